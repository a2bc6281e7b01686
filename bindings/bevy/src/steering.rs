//! Steering a character from a component: the speed and turn rate, or the facing, a player or
//! an AI asks for.

use bevy_ecs::prelude::*;
use bevy_math::Vec3;
use sinmdm::motion::math::Vec3 as FileVec3;
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
    /// Face this direction, in the frame of the character's entity (Bevy's axes, +Y up; the
    /// up part is ignored): the character turns to it at its clip's pace and walks where the
    /// model likes, which for a walk is mostly where it faces.
    Face {
        /// A direction with a part on the ground.
        direction: Vec3,
    },
}

impl Steering {
    /// The stream command in the model's frame and units (`limits`: the model's clip range),
    /// or why the value cannot be one (a number that is not finite).
    pub fn command(&self, frame: &EngineFrame, limits: &SteerLimits) -> Result<SteerFrame, String> {
        let (forward, turn) = match *self {
            Steering::Free => return Ok(SteerFrame::Free),
            Steering::Face { direction } => {
                let ground = Vec3::new(direction.x, 0.0, direction.z);
                if !ground.is_finite() || ground.length() <= 1e-6 * direction.length() {
                    return Err(format!(
                        "{self:?} ignored: the direction must be finite with a part on the ground"
                    ));
                }
                let file = frame.turn.inverse() * ground;
                return Ok(SteerFrame::Facing(FileVec3::new(
                    f64::from(file.x),
                    f64::from(file.y),
                    f64::from(file.z),
                )));
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_math::Quat;

    /// The frame of a +Z-up file (the zombie walk's): file x is Bevy's x, file y is Bevy's -z,
    /// file z is Bevy's y (up).
    fn z_up() -> EngineFrame {
        EngineFrame {
            turn: Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            metres_per_unit: 0.01,
        }
    }

    fn limits() -> SteerLimits {
        SteerLimits {
            forward: (0.0, 100.0),
            turn: 2.0,
            sideways: (-10.0, 10.0),
        }
    }

    #[test]
    fn a_facing_in_bevys_axes_becomes_one_in_the_files() {
        let frame = z_up();
        // The frame turns file +Z (up) to Bevy's +Y.
        let up = frame.turn * Vec3::Z;
        assert!((up - Vec3::Y).length() < 1e-6, "{up}");
        let face = |direction: Vec3| match (Steering::Face { direction }).command(&frame, &limits())
        {
            Ok(SteerFrame::Facing(d)) => d.0,
            other => panic!("{other:?}"),
        };
        let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
        assert!(close(face(Vec3::X), [1.0, 0.0, 0.0]));
        assert!(close(face(Vec3::Z), [0.0, -1.0, 0.0]));
        // The up part is dropped.
        assert!(close(face(Vec3::new(0.0, 5.0, 2.0)), [0.0, -2.0, 0.0]));
    }

    #[test]
    fn a_facing_straight_up_or_not_finite_is_refused() {
        let frame = z_up();
        for direction in [Vec3::Y, Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)] {
            let e = (Steering::Face { direction }).command(&frame, &limits());
            assert!(e.is_err(), "{direction}: {e:?}");
        }
    }
}
