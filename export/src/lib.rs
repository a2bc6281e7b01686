//! # sinmdm-export
//!
//! Writes a trained single-motion denoiser as one self-contained ONNX file: the QnA-UNet graph
//! built from plain named weights ([`Weights`]), plus every fact the runtime needs in
//! `metadata_props` ([`sinmdm::model_file::ModelMetadata`]). It never depends on burn; the
//! training crate adapts its checkpoints to named weights.

pub mod graph;
pub mod unet;
pub mod weights;

use std::path::Path;

use onnx_protobuf::{Message, ModelProto, OperatorSetIdProto, StringStringEntryProto};
use sinmdm::model_file::{METADATA_KEY, ModelMetadata, SCHEMA_KEY};

pub use sinmdm::network::NetworkShape;
pub use sinmdm::network::{WeightTensor, Weights};

/// ONNX IR version written (onnxruntime 1.31 reads up to 10).
pub const IR_VERSION: i64 = 8;
/// Operator set written.
pub const OPSET: i64 = 17;
/// The operators the graph may use: what onnxruntime, Unity's inference engine and Unreal NNE
/// all run. A test checks every exported file against this list.
pub const ALLOWED_OPS: &str = include_str!("../allowed_ops.txt");

/// Why a model could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// A weight the graph needs is absent.
    #[error("the weights have no tensor named '{0}'")]
    MissingWeight(String),
    /// A weight has the wrong shape for the network.
    #[error("weight '{name}' has shape {found:?}, the network needs {expected:?}")]
    WeightShape {
        /// The weight.
        name: String,
        /// The shape the network needs.
        expected: Vec<usize>,
        /// The shape found.
        found: Vec<usize>,
    },
    /// The sizes do not describe a valid network.
    #[error("not a valid network shape: {0}")]
    BadShape(String),
    /// The metadata disagrees with the network.
    #[error("metadata disagrees with the weights: {0}")]
    Metadata(String),
    /// The file could not be written.
    #[error("could not write '{}': {reason}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The reason.
        reason: std::io::Error,
    },
}

/// The complete ONNX model as bytes.
pub fn to_onnx_bytes(
    weights: &Weights,
    shape: NetworkShape,
    metadata: &ModelMetadata,
) -> Result<Vec<u8>, ExportError> {
    if metadata.network.shape() != shape {
        return Err(ExportError::Metadata(format!(
            "the network is {shape:?}; the metadata says {:?}",
            metadata.network.shape()
        )));
    }
    if metadata.normalizer.mean.len() != shape.features || metadata.layout.width() != shape.features
    {
        return Err(ExportError::Metadata(format!(
            "the network has {} feature rows; the metadata describes {} (layout) and {} (normaliser)",
            shape.features,
            metadata.layout.width(),
            metadata.normalizer.mean.len()
        )));
    }
    let graph = unet::build(weights, shape)?;
    let mut model = ModelProto::new();
    model.ir_version = IR_VERSION;
    let mut opset = OperatorSetIdProto::new();
    opset.domain = String::new();
    opset.version = OPSET;
    model.opset_import = vec![opset];
    model.producer_name = "sinmdm-export".into();
    model.producer_version = env!("CARGO_PKG_VERSION").into();
    model.doc_string = "Single-motion diffusion denoiser (QnA-UNet): x_t [B, F, N] (normalised features) and t [B] -> x0 [B, F, N]".into();
    model.graph = Some(graph).into();
    for (key, value) in [
        (SCHEMA_KEY, metadata.schema_version().to_string()),
        (
            METADATA_KEY,
            serde_json::to_string(metadata).expect("metadata serialises"),
        ),
    ] {
        let mut entry = StringStringEntryProto::new();
        entry.key = key.into();
        entry.value = value;
        model.metadata_props.push(entry);
    }
    Ok(model
        .write_to_bytes()
        .expect("an in-memory protobuf always serialises"))
}

/// Writes the model to `path` atomically (temporary file, then rename).
pub fn write_onnx(
    path: &Path,
    weights: &Weights,
    shape: NetworkShape,
    metadata: &ModelMetadata,
) -> Result<(), ExportError> {
    let bytes = to_onnx_bytes(weights, shape, metadata)?;
    sinmdm::files::write_atomically(path, &bytes).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        reason: source,
    })
}
