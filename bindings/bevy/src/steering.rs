//! Steering a character from a component: the speed and turn rate a player or an AI asks for.

use bevy_ecs::prelude::*;
use sinmdm::steer::{SteerFrame, SteerLimits};

use crate::frame::EngineFrame;

/// Where a character should go, read whenever its stream is asked for more motion: the
/// commands cover every frame the blocks started then may reach, so a change shows within
/// [`MotionCharacter::steering_reach`](crate::MotionCharacter::steering_reach) frames. Needs a
/// model with a heading-relative root; speeds and turns beyond the clip's range are clamped by
/// the stream.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub enum Steering {
    /// The model goes where it likes.
    Free,
    /// The clip's own mean forward speed, turning at `turn` radians per second (positive turns
    /// left, counter-clockwise seen from above).
    Turn {
        /// Radians per second.
        turn: f32,
    },
    /// Forward speed along the character's facing and turn rate about up.
    Velocity {
        /// Metres per second.
        forward: f32,
        /// Radians per second; positive turns left (counter-clockwise seen from above).
        turn: f32,
    },
}

impl Steering {
    /// The stream command in the model's frame and units (`limits`: the model's clip range),
    /// or why the value cannot be one (a number that is not finite).
    pub fn command(&self, frame: &EngineFrame, limits: &SteerLimits) -> Result<SteerFrame, String> {
        let (forward, turn) = match *self {
            Steering::Free => return Ok(SteerFrame::Free),
            Steering::Turn { turn } => ((limits.forward.0 + limits.forward.1) / 2.0, turn),
            Steering::Velocity { forward, turn } => (frame.to_file_units(forward), turn),
        };
        if !(forward.is_finite() && turn.is_finite()) {
            return Err(format!("{self:?} ignored: its numbers must be finite"));
        }
        // The turn from the file's axes to Bevy's is a rotation, so a turn to the left stays
        // one; only lengths change units.
        Ok(SteerFrame::Velocity {
            forward,
            turn: f64::from(turn),
        })
    }

    /// The clip's mean forward speed in metres per second (what [`Steering::Turn`] walks at).
    pub fn clip_speed(frame: &EngineFrame, limits: &SteerLimits) -> f32 {
        frame.to_metres((limits.forward.0 + limits.forward.1) / 2.0)
    }
}
