//! The burn code that burn-onnx generates from `tests/data/models/walk_tiny.onnx`.

#[allow(clippy::all, missing_docs, unused)]
pub mod walk_tiny {
    include!(concat!(env!("OUT_DIR"), "/model/walk_tiny.rs"));
}
