//! The result of a run: a batch of samples in the model's layout, as features, motion or poses.

use ndarray::{Array3, Axis};

use crate::model_file::ModelMetadata;
use crate::motion::{FeatureLayout, LocalMotion, MotionError, Pose, decode, poses};

/// A batch of generated samples in the model's layout.
#[derive(Debug, Clone)]
pub struct Generated {
    metadata: ModelMetadata,
    /// Normalised features `[B, F, N]`, as the network sees them.
    pub normalized: Array3<f32>,
    /// Features `[B, F, N]` in file units (denormalised).
    pub features: Array3<f32>,
}

impl Generated {
    /// Wraps normalised sampler output.
    pub fn from_normalized(metadata: ModelMetadata, normalized: Array3<f32>) -> Generated {
        let mut features = normalized.clone();
        for mut sample in features.outer_iter_mut() {
            let raw = metadata.normalizer.denormalize(sample.view());
            sample.assign(&raw);
        }
        Generated {
            metadata,
            normalized,
            features,
        }
    }

    /// Samples in the batch.
    pub fn count(&self) -> usize {
        self.features.len_of(Axis(0))
    }

    /// Frames per sample.
    pub fn frames(&self) -> usize {
        self.features.len_of(Axis(2))
    }

    /// The feature layout (skeleton, frame rate, columns).
    pub fn layout(&self) -> &FeatureLayout {
        &self.metadata.layout
    }

    /// Sample `index` as local joint transforms.
    pub fn motion(&self, index: usize) -> Result<LocalMotion, MotionError> {
        if index >= self.count() {
            return Err(MotionError::NoSuchSample {
                index,
                count: self.count(),
            });
        }
        decode(
            &self.metadata.layout,
            self.features.index_axis(Axis(0), index),
        )
    }

    /// Sample `index` as per-frame root positions and joint quaternions, for engines.
    pub fn poses(&self, index: usize) -> Result<Vec<Pose>, MotionError> {
        Ok(poses(&self.motion(index)?))
    }
}
