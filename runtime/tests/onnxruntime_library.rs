//! The real onnxruntime library, installed by `scripts/setup.sh`, is found and loads.

#[test]
fn onnxruntime_from_the_project_venv_loads() {
    let runtime = sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let name = runtime
        .path
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_string();
    assert!(name.contains("onnxruntime"), "{}", runtime.path.display());
    // A second call reuses the loaded library.
    assert!(std::ptr::eq(sinmdm::init_onnxruntime().unwrap(), runtime));
    // The library answers: a session builder needs the live onnxruntime API.
    ort::session::Session::builder(&runtime.environment).expect("onnxruntime did not answer");
}
