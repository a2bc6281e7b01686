//! Foot-contact labels: a joint is in contact while its contact point (its End Site when it has
//! one, else the joint) moves slower than a threshold.
//!
//! Thresholds are relative to the skeleton's height, so the same settings work for a clip in
//! metres, centimetres or CMU units. Poses are in the canonical frame ([`super::up`]).
//!
//! An **in-place cycle** (a game walk whose root does not travel: during stance the feet slide
//! backwards under the body, as on a treadmill) has no still foot, so speed alone would label
//! almost nothing. [`label_contacts`] recognises such clips ([`is_in_place`]) and measures each
//! foot's speed relative to the belt: the ground-plane velocity of the lowest contact point,
//! median-filtered over a third of a second.

use serde::{Deserialize, Serialize};

use super::fk::GlobalPose;
use super::ground::Body;
/// Kept here for callers from before it moved to [`super::ground`], beside the body it carries.
pub use super::ground::travelling_root;
use super::math::Vec3;
use super::skeleton::Skeleton;
use super::up::{height_of, horizontal};

/// How contact joints are chosen and labelled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactConfig {
    /// Joint names to label. `None` chooses automatically ([`choose_contact_joints`]): the
    /// chain ends (joints without child joints) whose contact point comes within
    /// `ground_fraction` of the skeleton height of the frame's lowest point in at least
    /// [`GROUND_SHARE`] of the frames in which the figure stands ([`standing_frames`]).
    pub joints: Option<Vec<String>>,
    /// A joint is in contact while its speed is below this many skeleton heights per second.
    pub speed_threshold: f64,
    /// See `joints`.
    pub ground_fraction: f64,
}

impl Default for ContactConfig {
    fn default() -> Self {
        ContactConfig {
            joints: None,
            speed_threshold: 0.2,
            ground_fraction: 0.05,
        }
    }
}

/// The share of the frames a figure stands in ([`standing_frames`]) in which a chain end must be
/// at the ground to be a contact joint. A foot carries the body in a third of the frames or more (a dog's paw at a run 0.33,
/// a human's toe at a walk 0.5-0.97, an idle fox's paws all of them); a chain end that only
/// touches the ground now and then does not (a running dog's nose 0.02, the tail of a dog that
/// lies down for a second and then walks 0.13).
pub const GROUND_SHARE: f64 = 0.25;

/// A frame counts toward [`GROUND_SHARE`] only while the figure stands: its travelling root
/// ([`travelling_root`]) at least this share as high above the frame's lowest point as in the
/// frame where it stands highest. Feet are what a figure stands on; while it lies, its belly
/// and tail carry it. Measured (root over the frame's lowest point, against the clip's highest):
/// MANN dogs lying 0.21 and 0.27; every standing frame of the project's clips 0.43 or more (a
/// dog crouching to jump 0.43, the CMU walk 0.51, the dog run 0.54, the rest 0.64-0.97).
pub const STANDING_ROOT_SHARE: f64 = 0.35;

/// The chain-end joints whose contact point comes within `ground_fraction * height` of the
/// frame's lowest point of the body ([`Body`]: every joint and End Site but a static container's) in at least [`GROUND_SHARE`] of the frames in
/// which the figure stands ([`standing_frames`]). Each frame is measured against its own lowest
/// point, so a clip on uneven ground still finds its feet, and one that lies down for most of
/// the clip finds the feet it gets up on, not the tail it lies on.
pub fn choose_contact_joints(
    skeleton: &Skeleton,
    poses: &[GlobalPose],
    height: f64,
    ground_fraction: f64,
) -> Vec<usize> {
    let leaves = skeleton.leaves();
    let standing = standing_frames(skeleton, poses, height, ground_fraction);
    let body = Body::travelling(skeleton, poses);
    let mut grounded = vec![0usize; leaves.len()];
    for (pose, _) in poses.iter().zip(&standing).filter(|(_, up)| **up) {
        let ground = body.lowest_point(pose);
        for (count, &leaf) in grounded.iter_mut().zip(&leaves) {
            if height_of(pose.contact_point(leaf)) - ground <= ground_fraction * height {
                *count += 1;
            }
        }
    }
    let needed = GROUND_SHARE * standing.iter().filter(|up| **up).count() as f64;
    leaves
        .into_iter()
        .zip(grounded)
        .filter(|&(_, count)| count > 0 && count as f64 >= needed)
        .map(|(leaf, _)| leaf)
        .collect()
}

/// Whether the figure stands in each frame ([`STANDING_ROOT_SHARE`]). A root that never rises
/// `ground_fraction * height` above the lowest point (a rig whose root bone lies on the floor)
/// says nothing of standing: every frame then counts.
pub fn standing_frames(
    skeleton: &Skeleton,
    poses: &[GlobalPose],
    height: f64,
    ground_fraction: f64,
) -> Vec<bool> {
    let body = Body::travelling(skeleton, poses);
    let root = body.carrier();
    let lift: Vec<f64> = poses
        .iter()
        .map(|pose| height_of(pose.joints[root]) - body.lowest_point(pose))
        .collect();
    // `f64::max` passes over a NaN lift, so no lift at all leaves the fold at minus infinity.
    let highest = lift.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if highest <= ground_fraction * height {
        return vec![true; poses.len()];
    }
    lift.iter()
        .map(|&l| l >= STANDING_ROOT_SHARE * highest)
        .collect()
}

/// Speed of one joint at every frame (units per second), by central differences (one-sided at
/// the ends).
pub fn joint_speeds(positions: &[Vec3], fps: f64) -> Vec<f64> {
    let n = positions.len();
    if n < 2 {
        return vec![0.0; n];
    }
    (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            (positions[b] - positions[a]).norm() * fps / (b - a) as f64
        })
        .collect()
}

/// Contact labels (1 = in contact) of `joint` over the clip, from its speed over the ground.
pub fn contact_labels(
    poses: &[GlobalPose],
    joint: usize,
    fps: f64,
    height: f64,
    speed_threshold: f64,
) -> Vec<f32> {
    let positions: Vec<Vec3> = poses.iter().map(|p| p.contact_point(joint)).collect();
    threshold(joint_speeds(&positions, fps), speed_threshold * height)
}

fn threshold(speeds: Vec<f64>, limit: f64) -> Vec<f32> {
    speeds
        .into_iter()
        .map(|s| if s < limit { 1.0 } else { 0.0 })
        .collect()
}

/// An in-place cycle's feet must move at least this fast relative to the root, on average (in
/// skeleton heights per second): a clip that stands still is not a cycle.
pub const IN_PLACE_MIN_FOOT_SPEED: f64 = 0.3;
/// A clip is in place when its root travels slower than this share of its feet's mean speed
/// relative to the root (a walk that travels scores about 1, a treadmill cycle about 0).
pub const IN_PLACE_MAX_TRAVEL_RATIO: f64 = 0.2;
/// ... and when its treadmill runs: the lowest foot drifts steadily over the ground (median over
/// a second) at least this share of the feet's mean speed relative to the root (a dance on the
/// spot plants its feet: about 0).
pub const IN_PLACE_MIN_BELT_RATIO: f64 = 0.3;

/// Frames in one second at `fps`, at least 1.
fn one_second(fps: f64) -> usize {
    (fps.round() as usize).max(1)
}

/// Whether the clip is an in-place cycle: its feet (the contact joints) move relative to the
/// root at a gait's pace, the root's ground position, measured over one-second spans (so a sway
/// does not count as travel), barely moves, and the lowest foot drifts steadily over the ground
/// (the treadmill, [`belt_displacement`]).
pub fn is_in_place(
    poses: &[GlobalPose],
    root: usize,
    contact_joints: &[usize],
    fps: f64,
    height: f64,
) -> bool {
    let frames = poses.len();
    if frames < 3 || contact_joints.is_empty() || height.is_nan() || height <= 0.0 {
        return false;
    }
    let span = one_second(fps).min(frames - 1);
    let travel: f64 = (0..frames - span)
        .map(|f| horizontal(poses[f + span].joints[root] - poses[f].joints[root]).norm())
        .sum::<f64>()
        / (frames - span) as f64
        * fps
        / span as f64;
    let mut feet = 0.0;
    for &joint in contact_joints {
        let relative: Vec<Vec3> = poses
            .iter()
            .map(|p| horizontal(p.contact_point(joint) - p.joints[root]))
            .collect();
        feet += joint_speeds(&relative, fps).iter().sum::<f64>() / frames as f64;
    }
    let feet = feet / contact_joints.len() as f64;
    if !(feet > IN_PLACE_MIN_FOOT_SPEED * height && travel < IN_PLACE_MAX_TRAVEL_RATIO * feet) {
        return false;
    }
    // Over a second: a treadmill drifts steadily, a dancer's lowest foot does not.
    let belt = belt_displacement(poses, contact_joints, fps, 1.0);
    let belt_speed = belt.iter().map(|&v| v.norm()).sum::<f64>() / frames as f64 * fps;
    belt_speed > IN_PLACE_MIN_BELT_RATIO * feet
}

/// Length of the median filter over the lowest foot's drift, in seconds. Measured on in-place
/// copies of the walks and dog clips (contact share within 10 points of the travelling clip's):
/// one frame follows the swing foot when the lowest foot switches (up to +19 points; five frames
/// +12), a second
/// smooths over the gait's own speed changes (up to -29 points), a third of a second keeps every
/// foot within 8.2 points.
pub const BELT_WINDOW_SECONDS: f64 = 1.0 / 3.0;

/// The treadmill's ground-plane displacement per frame, at every frame: the displacement of the
/// lowest contact point (central differences, per frame), median-filtered over
/// `window_seconds` ([`BELT_WINDOW_SECONDS`] for labels, a second for [`is_in_place`]).
pub fn belt_displacement(
    poses: &[GlobalPose],
    contact_joints: &[usize],
    fps: f64,
    window_seconds: f64,
) -> Vec<Vec3> {
    let n = poses.len();
    if n < 2 || contact_joints.is_empty() {
        return vec![Vec3::ZERO; n];
    }
    let lowest: Vec<Vec3> = (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            let joint = contact_joints
                .iter()
                .copied()
                .min_by(|&x, &y| {
                    height_of(poses[f].contact_point(x))
                        .total_cmp(&height_of(poses[f].contact_point(y)))
                })
                .unwrap_or(contact_joints[0]);
            let step = poses[b].contact_point(joint) - poses[a].contact_point(joint);
            horizontal(step * (1.0 / (b - a) as f64))
        })
        .collect();
    let half = ((fps * window_seconds / 2.0).round() as usize).clamp(1, n);
    let mut window = Vec::with_capacity(2 * half + 1);
    (0..n)
        .map(|f| {
            let (lo, hi) = (f.saturating_sub(half), f.saturating_add(half + 1).min(n));
            let mut out = Vec3::ZERO;
            for (c, value) in out.0.iter_mut().enumerate() {
                window.clear();
                window.extend(lowest[lo..hi].iter().map(|v| v[c]));
                window.sort_by(f64::total_cmp);
                *value = window[window.len() / 2];
            }
            out
        })
        .collect()
}

/// Contact labels for one clip, with whether it was treated as an in-place cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactLabels {
    /// One label per frame (1 = in contact) for each contact joint, in the order given.
    pub labels: Vec<Vec<f32>>,
    /// The clip is an in-place cycle and the labels are relative to its treadmill.
    pub in_place: bool,
}

/// Labels every contact joint of a clip: by speed over the ground, or for an in-place cycle
/// ([`is_in_place`]) by speed relative to the treadmill ([`belt_displacement`]).
pub fn label_contacts(
    poses: &[GlobalPose],
    root: usize,
    contact_joints: &[usize],
    fps: f64,
    height: f64,
    speed_threshold: f64,
) -> ContactLabels {
    if !is_in_place(poses, root, contact_joints, fps, height) {
        return ContactLabels {
            labels: contact_joints
                .iter()
                .map(|&j| contact_labels(poses, j, fps, height, speed_threshold))
                .collect(),
            in_place: false,
        };
    }
    let belt = belt_displacement(poses, contact_joints, fps, BELT_WINDOW_SECONDS);
    let n = poses.len();
    let labels = contact_joints
        .iter()
        .map(|&joint| {
            let speeds = (0..n)
                .map(|f| {
                    let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
                    let step = poses[b].contact_point(joint) - poses[a].contact_point(joint);
                    let relative = step - (belt[f] * ((b - a) as f64));
                    relative.norm() * fps / (b - a) as f64
                })
                .collect();
            threshold(speeds, speed_threshold * height)
        })
        .collect();
    ContactLabels {
        labels,
        in_place: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math::IDENTITY;

    fn pose(points: &[Vec3]) -> GlobalPose {
        GlobalPose {
            joints: points.to_vec(),
            rotations: vec![IDENTITY; points.len()],
            end_sites: vec![],
        }
    }

    #[test]
    fn a_foot_that_stops_and_moves_is_labelled_by_its_speed() {
        // 30 fps. The foot steps forward between frames 9 and 19 (ten steps at 2 heights/s) and
        // rests before and after. With central differences frames 9 and 19 see one step over two
        // frames, 1 height/s: still above the 0.15 threshold; frames 8 and 20 see no step.
        let height = 1.8;
        let mut x = 0.0;
        let mut points = Vec::new();
        for f in 0..30 {
            if (10..20).contains(&f) {
                x += 2.0 * height / 30.0;
            }
            points.push(pose(&[Vec3([x, 0.0, 0.0])]));
        }
        let labels = contact_labels(&points, 0, 30.0, height, 0.15);
        let expected: Vec<f32> = (0..30)
            .map(|f| if (9..=19).contains(&f) { 0.0 } else { 1.0 })
            .collect();
        assert_eq!(labels, expected);
    }

    #[test]
    fn speeds_use_central_differences() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]].map(Vec3);
        assert_eq!(joint_speeds(&positions, 10.0), vec![10.0, 15.0, 20.0]);
    }

    /// A root with one chain end per name below it, joints at the origin.
    fn star(ends: &[&str]) -> Skeleton {
        use crate::motion::skeleton::Joint;
        let joint = |name: &str, parent| Joint {
            name: name.into(),
            parent,
            offset: Vec3([0.0; 3]),
            channels: vec![],
            end_site: None,
        };
        let mut joints = vec![joint("root", None)];
        joints.extend(ends.iter().map(|name| joint(name, Some(0))));
        Skeleton { joints }
    }

    #[test]
    fn automatic_choice_takes_chain_ends_near_the_ground() {
        // root -> foot (leaf, at the ground) and root -> hand (leaf, high up).
        let skeleton = star(&["foot", "hand"]);
        let poses = vec![pose(&[
            Vec3([0.0, 1.0, 0.0]),
            Vec3([0.0, 0.02, 0.0]),
            Vec3([0.0, 1.4, 0.0]),
        ])];
        assert_eq!(choose_contact_joints(&skeleton, &poses, 1.4, 0.05), vec![1]);
    }

    #[test]
    fn feet_are_the_chain_ends_at_the_ground_in_a_quarter_of_the_frames() {
        // A body with two paws, a nose and a tail. For 8 frames it stands on its paws; for 2
        // it sits back, its root half as high over its tail, 0.1 under the paws' floor (a lower
        // spot, or a tail end that sinks into it): still standing by STANDING_ROOT_SHARE. For 1
        // its nose touches the ground.
        let skeleton = star(&["paw_a", "paw_b", "nose", "tail"]);
        let at = |y: [f64; 5]| pose(&y.map(|y| Vec3([0.0, y, 0.0])));
        let mut poses = vec![at([0.5, 0.0, 0.02, 0.4, 0.4]); 7];
        poses.push(at([0.5, 0.0, 0.02, 0.0, 0.4]));
        poses.extend(vec![at([0.15, 0.05, 0.05, 0.2, -0.1]); 2]);
        // Against the clip's lowest point (the lying tail) no paw would count; against each
        // frame's own, both paws are at the ground in 8 of 10 frames, the nose in 1 and the
        // tail in 2: under a quarter.
        assert_eq!(
            choose_contact_joints(&skeleton, &poses, 1.0, 0.05),
            vec![1, 2]
        );
        // A tail on the ground in a quarter of the frames or more counts (3 of 11).
        let mut sitting = poses.clone();
        sitting.truncate(8);
        sitting.extend(vec![at([0.15, 0.05, 0.05, 0.2, -0.1]); 3]);
        assert_eq!(
            choose_contact_joints(&skeleton, &sitting, 1.0, 0.05),
            vec![1, 2, 4]
        );
    }

    #[test]
    fn a_figure_that_lies_most_of_the_clip_stands_on_the_feet_it_gets_up_on() {
        // Root, two paws and a tail. For 8 frames it lies: root 0.1 over the tail on the floor,
        // paws folded 0.06 up (over the 0.05 tolerance). For 2 it stands: root 0.5 up, paws on
        // the floor, tail 0.3 up. Over all frames the tail is at the ground in 8 of 10 and the
        // paws in 2 (under a quarter); over the 2 frames it stands, the paws in both, the tail
        // in neither.
        let skeleton = star(&["paw_a", "paw_b", "tail"]);
        let at = |y: [f64; 4]| pose(&y.map(|y| Vec3([0.0, y, 0.0])));
        let mut poses = vec![at([0.1, 0.06, 0.06, 0.0]); 8];
        poses.extend(vec![at([0.5, 0.0, 0.0, 0.3]); 2]);
        let standing = standing_frames(&skeleton, &poses, 1.0, 0.05);
        assert_eq!(standing, [vec![false; 8], vec![true; 2]].concat());
        assert_eq!(
            choose_contact_joints(&skeleton, &poses, 1.0, 0.05),
            vec![1, 2]
        );
        // The boundary: a root at STANDING_ROOT_SHARE of its highest lift stands, one just under
        // does not.
        let mut edge = poses.clone();
        edge[0] = at([0.5 * STANDING_ROOT_SHARE, 0.06, 0.06, 0.0]);
        edge[1] = at([0.5 * STANDING_ROOT_SHARE - 1e-9, 0.06, 0.06, 0.0]);
        let standing = standing_frames(&skeleton, &edge, 1.0, 0.05);
        assert_eq!(standing[..2], [true, false]);
        // A root bone on the floor (as in rigs that carry the travel in a floor-level root)
        // never rises: every frame counts, and the figure's chain ends are chosen as before.
        let floor_root: Vec<GlobalPose> = poses
            .iter()
            .map(|p| {
                let mut p = p.clone();
                p.joints[0] = Vec3([0.0, 0.0, 0.0]);
                p
            })
            .collect();
        assert!(
            standing_frames(&skeleton, &floor_root, 1.0, 0.05)
                .iter()
                .all(|&up| up)
        );
        assert_eq!(
            choose_contact_joints(&skeleton, &floor_root, 1.0, 0.05),
            vec![3]
        );
    }
}
