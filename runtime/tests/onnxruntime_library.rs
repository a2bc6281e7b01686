//! The real onnxruntime library, installed by `scripts/setup.sh`, is found and loads; a failed
//! load is not remembered, and a second library is refused. (One test: onnxruntime is loaded
//! once per process, so the order of these steps matters.)

#[test]
fn onnxruntime_from_the_project_venv_loads() {
    // A host naming a library that is not there gets an error naming it ...
    let e = sinmdm::load_onnxruntime("/nonexistent/libonnxruntime.so").unwrap_err();
    assert!(
        e.to_string().contains("/nonexistent/libonnxruntime.so"),
        "{e}"
    );
    // ... and the failure is not kept: the search still finds the project's library.
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
    // Naming the loaded file again is fine; naming another one is refused.
    assert!(std::ptr::eq(
        sinmdm::load_onnxruntime(&runtime.path).unwrap(),
        runtime
    ));
    let copy = std::env::temp_dir().join(format!("libonnxruntime-copy-{}.so", std::process::id()));
    std::fs::copy(&runtime.path, &copy).unwrap();
    let e = sinmdm::load_onnxruntime(&copy).unwrap_err();
    std::fs::remove_file(&copy).unwrap();
    assert!(
        matches!(e, sinmdm::RuntimeLibraryError::AlreadyLoaded { .. }),
        "{e:?}"
    );
    // The library answers: a session builder needs the live onnxruntime API.
    ort::session::Session::builder(runtime.environment()).expect("onnxruntime did not answer");
}
