//! The facts a `.onnx` model file carries in its `metadata_props` (schema version 1): written by
//! the exporter, read by the runtime.

use serde::{Deserialize, Serialize};

use std::path::{Path, PathBuf};

mod json_path;
mod validate;

pub use validate::problems;

use crate::motion::{FeatureLayout, Normalizer};
use crate::network::NetworkShape;

/// Key of the schema version.
pub const SCHEMA_KEY: &str = "sinmdm.schema";
/// The newest schema version this crate writes and reads: 2 adds the heading-relative root
/// (`layout.root.heading`). A model without it is written as schema 1, so runtimes that read
/// only schema 1 keep reading it, and refuse a heading model instead of misreading its root.
pub const SCHEMA_VERSION: u32 = 2;
/// The schema versions this crate reads.
pub const SCHEMA_VERSIONS_READ: [u32; 2] = [1, 2];
/// Key of the JSON-encoded [`ModelMetadata`].
pub const METADATA_KEY: &str = "sinmdm.metadata";

/// The noise schedule this runtime runs ([`DiffusionFacts::schedule`]).
pub const SCHEDULE: &str = "cosine";
/// What the network predicts ([`DiffusionFacts::prediction`]).
pub const PREDICTION: &str = "x0";

/// Everything the runtime needs besides the graph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelMetadata {
    /// The network's sizes.
    pub network: NetworkFacts,
    /// The diffusion process the network was trained for.
    pub diffusion: DiffusionFacts,
    /// Feature columns, skeleton (names, parents, offsets, channel lists, file units), frame
    /// rate, start position, contact joints and threshold.
    pub layout: FeatureLayout,
    /// Per-feature mean and std: the network works on `(x - mean) / std`.
    pub normalizer: Normalizer,
    /// How the model was trained.
    pub training: TrainingFacts,
}

impl ModelMetadata {
    /// The oldest schema version that holds this metadata (what a model file is written as):
    /// 2 for a heading-relative root, 1 otherwise.
    pub fn schema_version(&self) -> u32 {
        match self.layout.root.as_ref().and_then(|r| r.heading.as_ref()) {
            Some(_) => 2,
            None => 1,
        }
    }
}

/// The network's sizes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkFacts {
    /// Feature rows F of `x_t` and `x0`.
    pub features: usize,
    /// Channels C.
    pub channels: usize,
    /// QnA heads.
    pub heads: usize,
    /// QnA window in frames.
    pub window: usize,
    /// Frames that can influence one output frame.
    pub receptive_field: usize,
    /// Number of trained parameters.
    pub parameters: usize,
}

/// The diffusion process.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffusionFacts {
    /// Steps T the network was trained with (`t` runs over `0..T`).
    pub steps: usize,
    /// Noise schedule (`cosine`).
    pub schedule: String,
    /// What the network predicts (`x0`).
    pub prediction: String,
}

/// How the model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingFacts {
    /// File name of the clip.
    pub clip: String,
    /// SHA-256 of the clip file.
    pub clip_sha256: String,
    /// Frames of the clip after resampling.
    pub clip_frames: usize,
    /// The training configuration.
    pub config: serde_json::Value,
    /// Optimiser steps done.
    pub steps: u64,
    /// Loss of the last step.
    pub final_loss: f64,
    /// Mean loss of the last 100 steps.
    pub recent_loss: f64,
    /// Training time in seconds.
    pub seconds: f64,
    /// When training started (UTC, RFC 3339).
    pub started: String,
    /// When the file was written (UTC, RFC 3339).
    pub exported: String,
    /// What the clip file was, when it was not a BVH file (absent: BVH, or an older file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clip_source: Option<ClipSourceFacts>,
}

/// Where a clip read from a format other than BVH came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipSourceFacts {
    /// The file format (`gltf`, `fbx`).
    pub format: String,
    /// The animation read, by name (or `#index` when it has none).
    pub animation: Option<String>,
    /// How many animations the file held.
    pub animations: usize,
    /// The length of the file's own unit in metres (FBX: 0.01 for centimetres; glTF: 1). The
    /// reader converted the clip to metres, so positions in the model are metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file_unit_meters: Option<f64>,
}

impl NetworkFacts {
    /// The sizes the graph was built with.
    pub fn shape(&self) -> NetworkShape {
        NetworkShape {
            features: self.features,
            channels: self.channels,
            heads: self.heads,
            window: self.window,
        }
    }
}

/// Why a model file's metadata cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum MetadataError {
    /// A valid ONNX file without our metadata.
    #[error(
        "'{path}' has no sinmdm metadata (no '{SCHEMA_KEY}' entry in metadata_props): it was not written by sinmdm-export"
    )]
    NoMetadata {
        /// The model file.
        path: PathBuf,
    },
    /// Our metadata, but a schema version this runtime does not read.
    #[error(
        "'{path}' carries sinmdm metadata schema '{found}'; this runtime reads schemas 1 and {SCHEMA_VERSION}"
    )]
    SchemaVersion {
        /// The model file.
        path: PathBuf,
        /// The version in the file.
        found: String,
    },
    /// The metadata is present but incomplete or malformed.
    #[error("'{path}' has invalid sinmdm metadata: {message}")]
    BadMetadata {
        /// The model file.
        path: PathBuf,
        /// What is wrong, naming the field.
        message: String,
    },
    /// Metadata that breaks the rules of [`crate::model_file::problems`]: every problem, each
    /// naming its field, and the metadata as read (to show what is readable).
    #[error("'{path}' has invalid sinmdm metadata: {}", problems.join("; "))]
    Invalid {
        /// The model file.
        path: PathBuf,
        /// Every problem found, each naming the field and its value.
        problems: Vec<String>,
        /// The metadata as read.
        metadata: Box<ModelMetadata>,
    },
}

/// Reads and checks the metadata entries of a model, given a lookup of `metadata_props`.
pub fn parse_metadata(
    path: &Path,
    lookup: impl Fn(&str) -> Option<String>,
) -> Result<ModelMetadata, MetadataError> {
    let schema = lookup(SCHEMA_KEY).ok_or_else(|| MetadataError::NoMetadata {
        path: path.to_path_buf(),
    })?;
    let Some(version) = schema
        .trim()
        .parse::<u32>()
        .ok()
        .filter(|v| SCHEMA_VERSIONS_READ.contains(v))
    else {
        return Err(MetadataError::SchemaVersion {
            path: path.to_path_buf(),
            found: schema,
        });
    };
    let bad = |message: String| MetadataError::BadMetadata {
        path: path.to_path_buf(),
        message,
    };
    let json = lookup(METADATA_KEY).ok_or_else(|| bad(format!("no '{METADATA_KEY}' entry")))?;
    let metadata: ModelMetadata = serde_json::from_str(&json).map_err(|e| {
        let path = json_path::path_at(&json, json_path::offset_of(&json, e.line(), e.column()));
        let field = if path.is_empty() {
            String::new()
        } else {
            format!(" at field {path}")
        };
        bad(format!("'{METADATA_KEY}'{field}: {e}"))
    })?;
    let mut problems = validate::problems(&metadata);
    if metadata.schema_version() > version {
        problems.push(format!(
            "layout.root.heading needs schema {}, the file says {version}",
            metadata.schema_version()
        ));
    }
    if !problems.is_empty() {
        return Err(MetadataError::Invalid {
            path: path.to_path_buf(),
            problems,
            metadata: Box::new(metadata),
        });
    }
    Ok(metadata)
}
