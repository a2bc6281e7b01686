//! The adapter from training checkpoints to the exporter's plain named weights and metadata.

use std::path::Path;

use burn::module::Module;
use burn::tensor::Device;
use sinmdm::model_file::{
    DiffusionFacts, ModelMetadata, NetworkFacts, PREDICTION, SCHEDULE, TrainingFacts,
};
use sinmdm_export::{NetworkShape, Weights};

use crate::error::TrainError;
use crate::model::QnaUnet;
use crate::model::weights::named_tensors;
use crate::run::checkpoint::{self, CheckpointState};

/// The network's weights by name, as the exporter reads them.
pub fn weights_of(model: &QnaUnet) -> Weights {
    named_tensors(model)
}

/// The network's sizes for a checkpoint state.
pub fn shape_of(state: &CheckpointState) -> NetworkShape {
    NetworkShape {
        features: state.features,
        channels: state.config.model.channels,
        heads: state.config.model.heads,
        window: state.config.model.window,
    }
}

/// The model-file metadata for a checkpoint state.
pub fn metadata_of(state: &CheckpointState) -> ModelMetadata {
    let config = &state.config;
    ModelMetadata {
        network: NetworkFacts {
            features: state.features,
            channels: config.model.channels,
            heads: config.model.heads,
            window: config.model.window,
            receptive_field: config.model.receptive_field(),
            parameters: state.parameters,
        },
        diffusion: DiffusionFacts {
            steps: config.diffusion.steps,
            schedule: SCHEDULE.into(),
            prediction: PREDICTION.into(),
        },
        layout: state.clip.layout.clone(),
        normalizer: state.clip.normalizer.clone(),
        training: TrainingFacts {
            clip: state.clip.name.clone(),
            clip_sha256: state.clip.sha256.clone(),
            clip_frames: state.clip.frames,
            config: serde_json::to_value(config).expect("config serialises"),
            steps: state.step,
            final_loss: state.loss,
            recent_loss: state.recent_loss,
            seconds: state.elapsed_seconds,
            started: state.started.clone(),
            exported: crate::clock::now(),
            clip_source: state.clip.source.clone(),
        },
    }
}

/// Writes the ONNX file of `model` trained as `state` to `out`.
pub fn export_model(
    model: &QnaUnet,
    state: &CheckpointState,
    out: &Path,
) -> Result<(), TrainError> {
    sinmdm_export::write_onnx(
        out,
        &weights_of(model),
        shape_of(state),
        &metadata_of(state),
    )
    .map_err(|e| TrainError::Export(e.to_string()))
}

/// Writes the ONNX file of the checkpoint at `path` (a checkpoint folder, or a run folder for its
/// newest checkpoint) to `out`, with the averaged weights when the run keeps an average; returns
/// the checkpoint's state.
pub fn export_checkpoint(path: &Path, out: &Path) -> Result<CheckpointState, TrainError> {
    let dir = checkpoint::resolve(path)?;
    let state = checkpoint::load_state(&dir)?;
    let device = Device::flex();
    let model = QnaUnet::new(state.features, &state.config.model, &device);
    let model = checkpoint::load_exported(&dir, model)?;
    export_model(&model.valid(), &state, out)?;
    Ok(state)
}
