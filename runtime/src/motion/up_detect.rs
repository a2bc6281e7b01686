//! Reading the up axis from the motion: limbs hang under gravity, so the chain ends sit below
//! the body's centre; up is the signed axis most opposed to them.

use serde::{Deserialize, Serialize};

use crate::motion::clip::LocalMotion;
use crate::motion::fk::{GlobalPose, global_poses};
use crate::motion::ground::travelling_root;
use crate::motion::math::Vec3;
use crate::motion::skeleton::Skeleton;
use crate::motion::up::UpAxis;

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
fn limb_weights(skeleton: &Skeleton, top: usize, below: &[bool]) -> Vec<(usize, f64)> {
    // Counted in one pass: `Skeleton::children` per joint would be quadratic in joints.
    let mut children = vec![0usize; skeleton.len()];
    for joint in &skeleton.joints {
        if let Some(p) = joint.parent {
            children[p] += 1;
        }
    }
    skeleton
        .leaves()
        .into_iter()
        .map(|leaf| {
            let joint = &skeleton.joints[leaf];
            let mut length = joint.end_site.map_or(0.0, Vec3::norm);
            let mut j = leaf;
            while let Some(p) = skeleton.joints[j].parent {
                if j == top {
                    break;
                }
                length += skeleton.joints[j].offset.norm();
                if children[p] > 1 || p == top {
                    break;
                }
                j = p;
            }
            (leaf, length)
        })
        .filter(|&(leaf, _)| below[leaf])
        .collect()
}

/// Whether each joint is `top` or below it, in one pass: parents precede their children, so
/// walking each joint up to the root (quadratic in a long chain) is not needed.
fn below_of(skeleton: &Skeleton, top: usize) -> Vec<bool> {
    let mut below = vec![false; skeleton.len()];
    for (j, joint) in skeleton.joints.iter().enumerate() {
        below[j] = j == top || joint.parent.is_some_and(|p| p < j && below[p]);
    }
    below
}

/// Detects the up axis of a clip (in its file's frame) from where its limbs hang; see the module
/// documentation for the rule.
pub fn detect_up(motion: &LocalMotion) -> UpDetection {
    let skeleton = &motion.skeleton;
    let poses = global_poses(motion);
    // A static container above the hips (some rigs) is no part of the body.
    let top = travelling_root(skeleton, &poses);
    let in_body = below_of(skeleton, top);
    let weights = limb_weights(skeleton, top, &in_body);
    let total_weight: f64 = weights.iter().map(|(_, w)| w).sum();
    let mut hang = Vec3::ZERO;
    let mut size = 0.0;
    for pose in &poses {
        let centre = body_centre(skeleton, pose, top, &in_body);
        if total_weight > 0.0 {
            for &(leaf, weight) in &weights {
                let d = pose.contact_point(leaf) - centre;
                hang += d * (weight / total_weight);
            }
        }
        size += body_size(pose, &in_body);
    }
    let frames = poses.len();
    let (hang, size) = if frames > 0 {
        ((hang * (1.0 / frames as f64)), size / frames as f64)
    } else {
        (Vec3::ZERO, 0.0)
    };
    let hang = if size > 0.0 && size.is_finite() {
        hang * (1.0 / size)
    } else {
        Vec3::ZERO
    };
    let length = hang.norm();
    // Up is the signed axis most opposed to the hanging direction; ties and a zero vector give +Y.
    let axis = UpAxis::ALL
        .into_iter()
        .map(|a| (a, -a.direction().dot(hang)))
        .fold((UpAxis::PosY, f64::NEG_INFINITY), |best, (a, s)| {
            if s > best.1 + 1e-12 || (a == UpAxis::PosY && s >= best.1 - 1e-12) {
                (a, s)
            } else {
                best
            }
        })
        .0;
    let alignment = if length > 0.0 && length.is_finite() {
        -axis.direction().dot(hang) / length
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

/// The body's centre in one pose: bone midpoints weighted by bone length (the bones below
/// `top`), or the first joint where no bone has a length.
fn body_centre(skeleton: &Skeleton, pose: &GlobalPose, top: usize, in_body: &[bool]) -> Vec3 {
    let mut centre = Vec3::ZERO;
    let mut mass = 0.0;
    for (j, joint) in skeleton.joints.iter().enumerate() {
        if let Some(p) = joint.parent.filter(|_| j != top && in_body[j]) {
            let length = (pose.joints[j] - pose.joints[p]).norm();
            let mid = (pose.joints[j] + pose.joints[p]) * 0.5;
            centre += mid * length;
            mass += length;
        }
    }
    if mass > 0.0 {
        centre * (1.0 / mass)
    } else {
        pose.joints.first().copied().unwrap_or(Vec3::ZERO)
    }
}

/// The diagonal of the box around the body's joints and End Sites in one pose.
fn body_size(pose: &GlobalPose, in_body: &[bool]) -> f64 {
    let (mut lo, mut hi) = (Vec3([f64::INFINITY; 3]), Vec3([f64::NEG_INFINITY; 3]));
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
    (hi - lo).norm()
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
