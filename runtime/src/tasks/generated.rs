//! The result of a run: a batch of samples in the model's layout, as features, motion or poses.

use ndarray::{Array3, Axis};

use crate::model_file::ModelMetadata;
use crate::motion::feet::{Feet, Kept, PlantOptions, PlantStats, plant_feet};
use crate::motion::{FeatureLayout, LocalMotion, MotionError, Pose, decode, poses};

/// A batch of generated samples in the model's layout.
#[derive(Debug, Clone)]
pub struct Generated {
    metadata: ModelMetadata,
    /// Normalised features `[B, F, N]`, as the network sees them.
    pub normalized: Array3<f32>,
    /// Features `[B, F, N]` in file units (denormalised).
    pub features: Array3<f32>,
    feet: Feet,
    kept: Kept,
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
            feet: Feet::default(),
            kept: Kept::default(),
        }
    }

    /// The same batch with `feet` for [`Generated::motion`] and [`Generated::poses`], and the
    /// joints and root positions a task kept from its reference (left untouched by planting).
    pub(crate) fn with_feet(mut self, feet: Feet, kept: Kept) -> Generated {
        self.feet = feet;
        self.kept = kept;
        self
    }

    /// What [`Generated::motion`] and [`Generated::poses`] do to the feet.
    pub fn feet(&self) -> Feet {
        self.feet
    }

    /// Chooses what [`Generated::motion`] and [`Generated::poses`] do to the feet (the
    /// request's choice until changed).
    pub fn set_feet(&mut self, feet: Feet) {
        self.feet = feet;
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

    /// Sample `index` as local joint transforms, its feet as [`Generated::feet`] says.
    pub fn motion(&self, index: usize) -> Result<LocalMotion, MotionError> {
        match self.feet {
            Feet::Planted => Ok(self.planted_motion(index)?.0),
            Feet::Raw => self.raw_motion(index),
        }
    }

    /// Sample `index` with its feet planted ([`plant_feet`] with default options), and what
    /// planting did.
    pub fn planted_motion(&self, index: usize) -> Result<(LocalMotion, PlantStats), MotionError> {
        let raw = self.raw_motion(index)?;
        let layout = &self.metadata.layout;
        let sample = self.features.index_axis(Axis(0), index);
        let labels = layout.contact_labels(sample);
        plant_feet(layout, &raw, &labels, &self.kept, &PlantOptions::default())
    }

    /// Sample `index` as the network made it, feet untouched.
    pub fn raw_motion(&self, index: usize) -> Result<LocalMotion, MotionError> {
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

    /// Sample `index` as per-frame root positions and joint quaternions, for engines, its feet
    /// as [`Generated::feet`] says.
    pub fn poses(&self, index: usize) -> Result<Vec<Pose>, MotionError> {
        Ok(poses(&self.motion(index)?))
    }
}
