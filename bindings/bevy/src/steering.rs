//! Steering a character from a component: the speed and turn rate a player or an AI asks for.

use bevy_ecs::prelude::*;
use sinmdm::steer::SteerFrame;

use crate::frame::EngineFrame;

/// Where a character should go, read whenever its stream is asked for more motion: the
/// commands cover the frames a new block may reach (the stream's lookahead past the frames
/// handed out), so a change shows within that many frames. Needs a model with a
/// heading-relative root; commands beyond the clip's range are clamped by the stream.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub enum Steering {
    /// The model goes where it likes.
    Free,
    /// Forward speed along the character's facing and turn rate about up.
    Velocity {
        /// Metres per second.
        forward: f32,
        /// Radians per second; positive turns left (counter-clockwise seen from above).
        turn: f32,
    },
}

impl Steering {
    /// The stream command in the model's frame and units.
    pub fn command(&self, frame: &EngineFrame) -> SteerFrame {
        match *self {
            Steering::Free => SteerFrame::Free,
            // The turn from the file's axes to Bevy's is a rotation, so a turn to the left
            // stays one; only lengths change units.
            Steering::Velocity { forward, turn } => SteerFrame::Velocity {
                forward: frame.to_file_units(forward),
                turn: f64::from(turn),
            },
        }
    }
}
