//! What one frame of a steered run asks for ([`SteerFrame`]), and the checks a list of
//! commands passes before it is used.

use crate::model_file::ModelMetadata;
use crate::motion::math::Vec3;
use crate::motion::up::UP;

/// What one frame of a steered run asks for (file frame: the model's up axis and units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SteerFrame {
    /// Nothing: the model goes where it likes.
    Free,
    /// Forward speed (file units per second, along the facing) and turn rate (radians per
    /// second about up; positive turns left, counter-clockwise seen from above).
    Velocity {
        /// File units per second.
        forward: f64,
        /// Radians per second.
        turn: f64,
    },
    /// The root's position on the ground at this frame (file frame; the up component is
    /// ignored). The character faces the way the path goes.
    Position(Vec3),
    /// The direction the character faces at this frame (file frame; the up component is
    /// ignored, the rest must not be zero); where it goes is the model's.
    Facing(Vec3),
    /// The root's position on the ground and the direction the character faces, apart (file
    /// frame, up components ignored): a path walked sideways or backwards.
    PositionFacing {
        /// As [`SteerFrame::Position`].
        position: Vec3,
        /// As [`SteerFrame::Facing`].
        facing: Vec3,
    },
}

impl SteerFrame {
    /// Whether every number of the command is finite (a position's up component too).
    pub fn is_finite(&self) -> bool {
        match *self {
            SteerFrame::Free => true,
            SteerFrame::Velocity { forward, turn } => forward.is_finite() && turn.is_finite(),
            SteerFrame::Position(p) | SteerFrame::Facing(p) => p.is_finite(),
            SteerFrame::PositionFacing { position, facing } => {
                position.is_finite() && facing.is_finite()
            }
        }
    }

    /// The ground position the command asks for, if any (file frame).
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            SteerFrame::Position(p) | SteerFrame::PositionFacing { position: p, .. } => Some(p),
            _ => None,
        }
    }

    /// The facing direction the command asks for, if any (file frame).
    pub fn facing(&self) -> Option<Vec3> {
        match *self {
            SteerFrame::Facing(d) | SteerFrame::PositionFacing { facing: d, .. } => Some(d),
            _ => None,
        }
    }
}

/// The facing of a ground direction `direction` given in the file frame of `metadata`'s model:
/// the heading about up that faces it (canonical frame, as the root's turn rows integrate);
/// `None` when its horizontal part is (nearly) zero.
pub fn facing_of_direction(metadata: &ModelMetadata, direction: Vec3) -> Option<f64> {
    // Scaled by its largest component first, so a direction of any finite size is read alike.
    let largest = direction.0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    let mut d = metadata.layout.up.canonical_from_file() * (direction * (1.0 / largest));
    d[UP] = 0.0;
    (d.norm() > 1e-9).then(|| d[0].atan2(d[2]))
}

/// Checks commands before they are used: every number finite, every facing with a horizontal
/// part. The error names the first bad command by its index.
pub fn check_commands(metadata: &ModelMetadata, commands: &[SteerFrame]) -> Result<(), String> {
    for (i, c) in commands.iter().enumerate() {
        if !c.is_finite() {
            return Err(format!(
                "command {i} holds a value that is not finite: {c:?}"
            ));
        }
        if let Some(d) = c.facing()
            && facing_of_direction(metadata, d).is_none()
        {
            return Err(format!(
                "command {i} asks to face {:?}, which has no direction on the ground (it is zero or points along up, {})",
                d.0, metadata.layout.up
            ));
        }
    }
    Ok(())
}
