//! A clip given to a model as a reference or content (in-betweening, expansion, composition,
//! harmonization, scoring): its features in the model's layout, in the model's up convention.

use super::FeatureMatrix;
use super::encode::encode_for;
use super::error::MotionError;
use super::layout::FeatureLayout;
use crate::motion::clip::ChannelClip;
use crate::motion::up::{UpAxis, reorient, reorient_problem};
use crate::motion::up_detect::{Confidence, detect_up};

/// A clip encoded for a model, and how its up axis was settled.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipForModel {
    /// Raw (unnormalised) features `[F, N]` in the model's layout.
    pub features: FeatureMatrix,
    /// The clip's up axis: the one given, else the detected one when the detection is sure,
    /// else the model's.
    pub clip_up: UpAxis,
    /// Whether the clip was turned into the model's convention (its up axis differs).
    pub turned: bool,
}

/// Encodes `clip` in a model's `layout`. A clip whose up axis (`up`, or read from the motion)
/// differs from the model's is turned into the model's convention first.
pub fn encode_for_model(
    clip: &ChannelClip,
    layout: &FeatureLayout,
    up: Option<UpAxis>,
) -> Result<ClipForModel, MotionError> {
    let model_up = layout.up;
    let clip_up = up.unwrap_or_else(|| {
        let found = detect_up(&clip.to_local());
        if found.confidence == Confidence::Sure {
            found.axis
        } else {
            model_up
        }
    });
    if clip_up == model_up {
        return Ok(ClipForModel {
            features: encode_for(clip, layout)?,
            clip_up,
            turned: false,
        });
    }
    if let Some(problem) = reorient_problem(&clip.skeleton) {
        return Err(MotionError::CannotReorient {
            clip_up,
            model_up,
            problem,
        });
    }
    let turn = model_up.file_from_canonical() * clip_up.canonical_from_file();
    let turned = reorient(&clip.to_local(), &turn).to_channels();
    Ok(ClipForModel {
        features: encode_for(&turned, layout)?,
        clip_up,
        turned: true,
    })
}
