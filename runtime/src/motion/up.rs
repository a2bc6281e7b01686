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
use super::contacts::travelling_root;
use super::fk::global_poses;
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
        let mut v = [0.0; 3];
        let (index, sign) = self.index_and_sign();
        v[index] = sign;
        v
    }

    fn index_and_sign(self) -> (usize, f64) {
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
            UpAxis::NegY => [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
            UpAxis::PosZ => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
            UpAxis::NegZ => [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            UpAxis::PosX => [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            UpAxis::NegX => [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The rotation that takes the file's coordinates to canonical ones.
    pub fn canonical_from_file(self) -> Mat3 {
        math::transpose(&self.file_from_canonical())
    }

    /// The canonical coordinate axis (0, 1 or 2) that file axis `index` maps to.
    pub fn canonical_index(self, index: usize) -> usize {
        let mut v = [0.0; 3];
        v[index] = 1.0;
        let c = math::mat_vec(&self.canonical_from_file(), v);
        (0..3).find(|&i| c[i] != 0.0).unwrap_or(index)
    }
}

/// The file's name of canonical axis `index` (0, 1 or 2) under up axis `up`, such as `-Y`.
pub fn file_axis_name(up: UpAxis, index: usize) -> String {
    let mut v = [0.0; 3];
    v[index] = 1.0;
    let f = math::mat_vec(&up.file_from_canonical(), v);
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
            out.rotations[k] = math::mat_mul(rotation, &motion.rotations[k]);
            out.translations[k] = math::mat_vec(rotation, motion.translations[k]);
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
            joint.offset = math::mat_vec(rotation, joint.offset);
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

/// How sure [`detect_up`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Confidence {
    /// The evidence is clear.
    Sure,
    /// The evidence is weak; check the figure and pass the axis explicitly if it is wrong.
    Unsure,
}

/// What [`detect_up`] found, with its evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct UpDetection {
    /// The detected up axis.
    pub axis: UpAxis,
    /// How sure the detection is.
    pub confidence: Confidence,
    /// Cosine between the limbs' mean hanging direction and the detected down axis (1 = exactly
    /// along it).
    pub alignment: f64,
    /// Length of the mean hanging vector relative to the figure's size (its mean bounding-box
    /// diagonal).
    pub strength: f64,
    /// The mean hanging vector in file coordinates, relative to the figure's size.
    pub hang: Vec3,
    /// Frames the evidence comes from.
    pub frames: usize,
    /// Why the detection is unsure, in plain words (empty when sure).
    pub doubts: Vec<String>,
}

impl UpDetection {
    /// One line of evidence for a person: `+Z (sure: limbs hang along -Z, cosine 0.97, ...)`.
    pub fn describe(&self) -> String {
        let h = self.hang;
        let sure = match self.confidence {
            Confidence::Sure => "sure".to_string(),
            Confidence::Unsure => format!("UNSURE: {}", self.doubts.join("; ")),
        };
        format!(
            "{} ({sure}; limbs hang along ({:.2}, {:.2}, {:.2}), cosine {:.2} with {}, strength {:.2} of the figure's size, {} frames)",
            self.axis,
            h[0],
            h[1],
            h[2],
            self.alignment,
            opposite(self.axis),
            self.strength,
            self.frames,
        )
    }
}

fn opposite(axis: UpAxis) -> UpAxis {
    match axis {
        UpAxis::PosX => UpAxis::NegX,
        UpAxis::NegX => UpAxis::PosX,
        UpAxis::PosY => UpAxis::NegY,
        UpAxis::NegY => UpAxis::PosY,
        UpAxis::PosZ => UpAxis::NegZ,
        UpAxis::NegZ => UpAxis::PosZ,
    }
}

/// Below this cosine between the hanging direction and the chosen axis the detection is unsure
/// (the figure is tilted, or lies down with its limbs spread).
pub const MIN_ALIGNMENT: f64 = 0.85;
/// Below this hanging length (share of the figure's size) the detection is unsure.
pub const MIN_STRENGTH: f64 = 0.05;
/// Fewer frames than this (a third of a second at 30 fps) make the detection unsure: a pose or
/// two can be anything.
pub const MIN_FRAMES: usize = 10;

/// Each chain end's weight: the length of the limb that carries it, from the nearest joint where
/// the skeleton branches (or `top`) to the end (its End Site included). Fingers and toes weigh
/// little, legs and tails a lot. Only chain ends below `top` count.
fn limb_weights(skeleton: &Skeleton, top: usize) -> Vec<(usize, f64)> {
    let children: Vec<usize> = (0..skeleton.len())
        .map(|j| skeleton.children(j).len())
        .collect();
    skeleton
        .leaves()
        .into_iter()
        .map(|leaf| {
            let joint = &skeleton.joints[leaf];
            let mut length = joint.end_site.map_or(0.0, math::norm);
            let mut j = leaf;
            while let Some(p) = skeleton.joints[j].parent {
                if j == top {
                    break;
                }
                length += math::norm(skeleton.joints[j].offset);
                if children[p] > 1 || p == top {
                    break;
                }
                j = p;
            }
            (leaf, length)
        })
        .filter(|&(leaf, _)| is_below(skeleton, leaf, top))
        .collect()
}

/// Whether `joint` is `top` or below it.
fn is_below(skeleton: &Skeleton, joint: usize, top: usize) -> bool {
    let mut j = joint;
    loop {
        if j == top {
            return true;
        }
        match skeleton.joints[j].parent {
            Some(p) => j = p,
            None => return false,
        }
    }
}

/// Detects the up axis of a clip (in its file's frame) from where its limbs hang; see the module
/// documentation for the rule.
pub fn detect_up(motion: &LocalMotion) -> UpDetection {
    let skeleton = &motion.skeleton;
    let poses = global_poses(motion);
    // A static container above the hips (some rigs) is no part of the body.
    let top = travelling_root(skeleton, &poses);
    let weights = limb_weights(skeleton, top);
    let in_body: Vec<bool> = (0..skeleton.len())
        .map(|j| is_below(skeleton, j, top))
        .collect();
    let total_weight: f64 = weights.iter().map(|(_, w)| w).sum();
    let mut hang = [0.0; 3];
    let mut size = 0.0;
    for pose in &poses {
        // The body's centre: bone midpoints weighted by bone length.
        let mut centre = [0.0; 3];
        let mut mass = 0.0;
        for (j, joint) in skeleton.joints.iter().enumerate() {
            if let Some(p) = joint
                .parent
                .filter(|_| j != top && is_below(skeleton, j, top))
            {
                let length = math::norm(math::sub(pose.joints[j], pose.joints[p]));
                let mid = math::scale(math::add(pose.joints[j], pose.joints[p]), 0.5);
                centre = math::add(centre, math::scale(mid, length));
                mass += length;
            }
        }
        let centre = if mass > 0.0 {
            math::scale(centre, 1.0 / mass)
        } else {
            pose.joints.first().copied().unwrap_or([0.0; 3])
        };
        if total_weight > 0.0 {
            for &(leaf, weight) in &weights {
                let d = math::sub(pose.contact_point(leaf), centre);
                hang = math::add(hang, math::scale(d, weight / total_weight));
            }
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let body = pose
            .joints
            .iter()
            .enumerate()
            .filter(|&(j, _)| in_body[j])
            .map(|(_, p)| *p)
            .chain(
                pose.end_sites
                    .iter()
                    .filter(|(j, _)| in_body[*j])
                    .map(|(_, p)| *p),
            );
        for p in body {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        size += math::norm(math::sub(hi, lo));
    }
    let frames = poses.len();
    let (hang, size) = if frames > 0 {
        (math::scale(hang, 1.0 / frames as f64), size / frames as f64)
    } else {
        ([0.0; 3], 0.0)
    };
    let hang = if size > 0.0 && size.is_finite() {
        math::scale(hang, 1.0 / size)
    } else {
        [0.0; 3]
    };
    let length = math::norm(hang);
    // Up is the signed axis most opposed to the hanging direction; ties and a zero vector give +Y.
    let axis = UpAxis::ALL
        .into_iter()
        .map(|a| (a, -math::dot(a.direction(), hang)))
        .fold((UpAxis::PosY, f64::NEG_INFINITY), |best, (a, s)| {
            if s > best.1 + 1e-12 || (a == UpAxis::PosY && s >= best.1 - 1e-12) {
                (a, s)
            } else {
                best
            }
        })
        .0;
    let alignment = if length > 0.0 && length.is_finite() {
        -math::dot(axis.direction(), hang) / length
    } else {
        0.0
    };
    let mut doubts = Vec::new();
    if frames < MIN_FRAMES {
        doubts.push(format!(
            "only {frames} frame(s), fewer than {MIN_FRAMES}: a pose alone can be anything"
        ));
    }
    if alignment < MIN_ALIGNMENT {
        doubts.push(format!(
            "the limbs hang at an angle to every axis (cosine {alignment:.2} < {MIN_ALIGNMENT}): tilted or lying down?"
        ));
    }
    if length < MIN_STRENGTH {
        doubts.push(format!(
            "the limbs barely hang below the body ({length:.3} < {MIN_STRENGTH} of its size)"
        ));
    }
    UpDetection {
        axis,
        confidence: if doubts.is_empty() {
            Confidence::Sure
        } else {
            Confidence::Unsure
        },
        alignment,
        strength: length,
        hang,
        frames,
        doubts,
    }
}

/// The up axis to use for a clip: `explicit` when given, else the detected one.
pub fn choose_up(motion: &LocalMotion, explicit: Option<UpAxis>) -> (UpAxis, Option<UpDetection>) {
    match explicit {
        Some(axis) => (axis, None),
        None => {
            let found = detect_up(motion);
            (found.axis, Some(found))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_axis_maps_canonical_up_to_itself_and_is_a_rotation() {
        for axis in UpAxis::ALL {
            let a = axis.file_from_canonical();
            assert_eq!(
                math::mat_vec(&a, [0.0, 1.0, 0.0]),
                axis.direction(),
                "{axis}"
            );
            let det = math::dot(a[0], math::cross(a[1], a[2]));
            assert_eq!(det, 1.0, "{axis}");
            assert_eq!(
                math::mat_mul(&a, &axis.canonical_from_file()),
                math::IDENTITY
            );
            assert_eq!(axis.canonical_index(axis.index_and_sign().0), UP);
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
