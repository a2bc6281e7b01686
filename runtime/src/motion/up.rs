//! The up axis of a clip and the canonical frame the representation works in.
//!
//! BVH files are Y-up, Z-up or (rarely) X-up, and either sign. Everything in this crate that
//! means "vertical", "height" or "ground" works in one **canonical frame** whose up is component
//! [`UP`] (Y) and whose ground plane is spanned by [`GROUND_PLANE`] (X and Z): a clip is turned
//! into that frame by [`to_canonical`] as it is read and back by [`to_file`] as it is written, so
//! a Z-up file and its Y-up twin give the same features, and the files written for a Z-up clip
//! are Z-up again. Only the skeleton's top joint moves between the two frames: every other joint
//! is relative to its parent.
//!
//! [`detect_up`] reads the up axis from the motion itself: gravity makes limbs hang, so averaged
//! over the clip the chain ends (feet, paws, hands, head, tail) sit below the body's centre,
//! each weighted by the length of the limb that carries it; the signed axis closest to the
//! opposite of that average is up. How well the average lines up with that axis, and how long it
//! is next to the figure's size, say how sure the guess is.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::clip::LocalMotion;
use super::math::{self, Mat3, Vec3};
use super::skeleton::Skeleton;

/// The component of a canonical-frame vector that points up.
pub const UP: usize = 1;
/// The components of a canonical-frame vector that span the ground plane.
pub const GROUND_PLANE: [usize; 2] = [0, 2];

/// The height of a canonical-frame point.
pub fn height_of(point: Vec3) -> f64 {
    point[UP]
}

/// A canonical-frame point projected onto the ground plane (its height set to `level`).
pub fn on_ground(point: Vec3, level: f64) -> Vec3 {
    let mut p = point;
    p[UP] = level;
    p
}

/// The ground-plane part of a canonical-frame vector (its vertical component zeroed).
pub fn horizontal(v: Vec3) -> Vec3 {
    on_ground(v, 0.0)
}

/// Which signed coordinate axis of a file points up. Written as `+X`, `-Y`, `+Z`, ...; read
/// from any of `x`, `+x`, `-x`, ... in either case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum UpAxis {
    /// +X up.
    PosX,
    /// -X up.
    NegX,
    /// +Y up (the BVH convention, and what a model file without the field means).
    #[default]
    PosY,
    /// -Y up.
    NegY,
    /// +Z up (many motion-capture and DCC exports).
    PosZ,
    /// -Z up.
    NegZ,
}

impl UpAxis {
    /// All six, in a fixed order.
    pub const ALL: [UpAxis; 6] = [
        UpAxis::PosX,
        UpAxis::NegX,
        UpAxis::PosY,
        UpAxis::NegY,
        UpAxis::PosZ,
        UpAxis::NegZ,
    ];

    /// The unit vector of the axis, in file coordinates.
    pub fn direction(self) -> Vec3 {
        let (index, sign) = self.index_and_sign();
        Vec3::along(index, sign)
    }

    pub(crate) fn index_and_sign(self) -> (usize, f64) {
        match self {
            UpAxis::PosX => (0, 1.0),
            UpAxis::NegX => (0, -1.0),
            UpAxis::PosY => (1, 1.0),
            UpAxis::NegY => (1, -1.0),
            UpAxis::PosZ => (2, 1.0),
            UpAxis::NegZ => (2, -1.0),
        }
    }

    /// The rotation that takes canonical coordinates to the file's: canonical up (+Y) goes to
    /// this axis. Its entries are 0 and +-1, so applying it and its transpose is exact.
    /// +Z: a quarter turn about X (canonical forward +Z becomes -Y, Blender's convention);
    /// +X and -X: a quarter turn about Z; -Y and -Z: half and three-quarter turns about X.
    pub fn file_from_canonical(self) -> Mat3 {
        match self {
            UpAxis::PosY => math::IDENTITY,
            UpAxis::NegY => Mat3([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]),
            UpAxis::PosZ => Mat3([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
            UpAxis::NegZ => Mat3([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
            UpAxis::PosX => Mat3([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            UpAxis::NegX => Mat3([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        }
    }

    /// The rotation that takes the file's coordinates to canonical ones.
    pub fn canonical_from_file(self) -> Mat3 {
        self.file_from_canonical().transpose()
    }
}

/// The file's name of canonical axis `index` (0, 1 or 2) under up axis `up`, such as `-Y`.
pub fn file_axis_name(up: UpAxis, index: usize) -> String {
    let f = up.file_from_canonical() * Vec3::along(index, 1.0);
    let i = (0..3).find(|&i| f[i] != 0.0).unwrap_or(index);
    let sign = if f[i] < 0.0 { "-" } else { "" };
    format!("{sign}{}", ["X", "Y", "Z"][i])
}

impl fmt::Display for UpAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            UpAxis::PosX => "+X",
            UpAxis::NegX => "-X",
            UpAxis::PosY => "+Y",
            UpAxis::NegY => "-Y",
            UpAxis::PosZ => "+Z",
            UpAxis::NegZ => "-Z",
        })
    }
}

impl TryFrom<String> for UpAxis {
    type Error = BadUpAxis;

    fn try_from(s: String) -> Result<Self, Self::Error> {
        s.parse()
    }
}

impl From<UpAxis> for String {
    fn from(axis: UpAxis) -> String {
        axis.to_string()
    }
}

/// An up axis that is not one of `x`, `y`, `z`, `-x`, `-y`, `-z` (a leading `+` is allowed).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("up axis must be one of x, y, z, -x, -y, -z, got '{0}'")]
pub struct BadUpAxis(pub String);

impl FromStr for UpAxis {
    type Err = BadUpAxis;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" | "+x" => Ok(UpAxis::PosX),
            "-x" => Ok(UpAxis::NegX),
            "y" | "+y" => Ok(UpAxis::PosY),
            "-y" => Ok(UpAxis::NegY),
            "z" | "+z" => Ok(UpAxis::PosZ),
            "-z" => Ok(UpAxis::NegZ),
            _ => Err(BadUpAxis(s.to_string())),
        }
    }
}

/// The motion with a global rotation applied: the top joints' (those without a parent) local
/// rotations and translations are premultiplied by `rotation`; the skeleton is left as it is.
pub fn rotate_motion(motion: &LocalMotion, rotation: &Mat3) -> LocalMotion {
    let mut out = motion.clone();
    let joints = motion.skeleton.len();
    for (j, joint) in motion.skeleton.joints.iter().enumerate() {
        if joint.parent.is_some() {
            continue;
        }
        for f in 0..motion.frame_count() {
            let k = f * joints + j;
            out.rotations[k] = rotation * motion.rotations[k];
            out.translations[k] = rotation * motion.translations[k];
        }
    }
    out
}

/// A motion in a file whose up is `up`, expressed in the canonical Y-up frame.
pub fn to_canonical(motion: &LocalMotion, up: UpAxis) -> LocalMotion {
    if up == UpAxis::PosY {
        return motion.clone();
    }
    rotate_motion(motion, &up.canonical_from_file())
}

/// A canonical-frame motion expressed in the frame of a file whose up is `up`.
pub fn to_file(motion: &LocalMotion, up: UpAxis) -> LocalMotion {
    if up == UpAxis::PosY {
        return motion.clone();
    }
    rotate_motion(motion, &up.file_from_canonical())
}

/// A re-oriented copy of a clip, as another tool would have written it: the whole motion turned
/// by `rotation` (the top joints' rotations, translations and OFFSETs), with the same joints and
/// channel lists. Used to make Z-up, X-up or turned twins of a clip.
pub fn reorient(motion: &LocalMotion, rotation: &Mat3) -> LocalMotion {
    let mut out = rotate_motion(motion, rotation);
    for joint in &mut out.skeleton.joints {
        if joint.parent.is_none() {
            joint.offset = rotation * joint.offset;
        }
    }
    out
}

/// Why [`reorient`] cannot write a clip faithfully: its top joint lacks the channels that would
/// carry the turn (all three rotations, and all three positions if it has any), naming the joint.
pub fn reorient_problem(skeleton: &Skeleton) -> Option<String> {
    skeleton.joints.iter().filter(|j| j.parent.is_none()).find_map(|joint| {
        let rotations = joint.rotation_order().len();
        let positions = joint.position_axes().len();
        (rotations != 3 || (positions != 0 && positions != 3)).then(|| {
            format!(
                "the top joint '{}' has {rotations} rotation and {positions} position channels; turning the clip needs 3 rotations (and 0 or 3 positions)",
                joint.name
            )
        })
    })
}

// Detecting the up axis from a motion lives beside this module (`super::up_detect`): it needs
// forward kinematics and contacts, which need this module's frame.

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_axis_maps_canonical_up_to_itself_and_is_a_rotation() {
        for axis in UpAxis::ALL {
            let a = axis.file_from_canonical();
            assert_eq!((a * Vec3::new(0.0, 1.0, 0.0)), axis.direction(), "{axis}");
            let det = a.determinant();
            assert_eq!(det, 1.0, "{axis}");
            assert_eq!((a * axis.canonical_from_file()), math::IDENTITY);
            // The file's up direction becomes canonical +Y.
            let (index, sign) = axis.index_and_sign();
            assert_eq!(
                axis.canonical_from_file() * Vec3::along(index, sign),
                Vec3::new(0.0, 1.0, 0.0)
            );
        }
    }

    #[test]
    fn parsing_accepts_signed_axes_in_either_case() {
        assert_eq!("z".parse::<UpAxis>(), Ok(UpAxis::PosZ));
        assert_eq!("+Y".parse::<UpAxis>(), Ok(UpAxis::PosY));
        assert_eq!("-x".parse::<UpAxis>(), Ok(UpAxis::NegX));
        assert!("up".parse::<UpAxis>().is_err());
        for axis in UpAxis::ALL {
            assert_eq!(axis.to_string().parse::<UpAxis>(), Ok(axis));
        }
    }

    #[test]
    fn serialised_names_are_short_and_old_files_mean_y() {
        assert_eq!(serde_json::to_string(&UpAxis::NegZ).unwrap(), "\"-Z\"");
        assert_eq!(
            serde_json::from_str::<UpAxis>("\"z\"").unwrap(),
            UpAxis::PosZ
        );
        assert_eq!(UpAxis::default(), UpAxis::PosY);
    }
}
