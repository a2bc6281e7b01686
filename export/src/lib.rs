//! # sinmdm-export
//!
//! Writes a trained single-motion denoiser as one self-contained ONNX file: the QnA-UNet graph
//! from plain named weights plus every fact the runtime needs in `metadata_props`. It depends on
//! the runtime crate for the motion representation and never on burn. The graph writer is not
//! built yet; this crate reserves its place in the workspace.
