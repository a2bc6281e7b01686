//! What the rule reads from a clip before training: its length, rate, own intra diversity
//! and feet, and whether that makes it calm or a clip on many feet.

use super::{CALM_INTRA_BELOW, MANY_FEET};
use crate::clip::ClipData;

/// What the rule reads from a clip before training.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipReading {
    /// Frames, at the rate the clip trains at.
    pub frames: usize,
    /// That rate.
    pub fps: f64,
    /// The clip's own intra diversity ([`sinmdm_eval::intra_diversity`] over
    /// [`sinmdm_eval::LOCAL_WINDOW`]-frame windows of its metric features).
    pub intra_diversity: f64,
    /// Its feet: the contact joints its layout found (or the configuration named).
    pub feet: usize,
}

impl ClipReading {
    /// Reads a loaded clip (its normalised features are returned to file units first).
    pub fn of(data: &ClipData) -> ClipReading {
        let layout = &data.facts.layout;
        let raw = data.facts.normalizer.denormalize(data.features.view());
        let rows = sinmdm_eval::metric_features(layout, raw.view());
        ClipReading {
            frames: data.facts.frames,
            fps: layout.fps,
            intra_diversity: sinmdm_eval::intra_diversity(rows.view(), sinmdm_eval::LOCAL_WINDOW),
            feet: layout.contact_joints.len(),
        }
    }

    /// Whether the clip stands on [`MANY_FEET`] feet or more.
    pub fn has_many_feet(&self) -> bool {
        self.feet >= MANY_FEET
    }

    /// Whether the clip is calm ([`CALM_INTRA_BELOW`]).
    pub fn is_calm(&self) -> bool {
        self.intra_diversity < CALM_INTRA_BELOW
    }
}
