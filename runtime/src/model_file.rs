//! The facts a `.onnx` model file carries in its `metadata_props` (schema version 1): written by
//! the exporter, read by the runtime.

use serde::{Deserialize, Serialize};

use crate::motion::{FeatureLayout, Normalizer};

/// Key of the schema version.
pub const SCHEMA_KEY: &str = "sinmdm.schema";
/// The schema version this crate writes and reads.
pub const SCHEMA_VERSION: u32 = 1;
/// Key of the JSON-encoded [`ModelMetadata`].
pub const METADATA_KEY: &str = "sinmdm.metadata";

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
}
