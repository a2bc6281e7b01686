//! The model reader on any bytes, through the real onnxruntime: an error or a model, never a
//! panic, a hang or a runaway allocation. onnxruntime is found as the command line finds it
//! (`ORT_DYLIB_PATH`, beside the binary, the system's loader).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let options = sinmdm::ModelOptions {
        threads: Some(1),
    };
    let _ = sinmdm::Model::from_bytes(data, "fuzz.onnx", &options);
});
