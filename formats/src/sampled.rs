//! Joints sampled frame by frame, as the keyframe formats (glTF, FBX) give them, turned into a
//! clip: BVH-style joints (channels, offsets, End Sites) built from their motion, with leaf
//! joints that never move folded into their parent's End Site.

use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{Channel, Joint, LocalMotion, Skeleton};

/// What a file recorded about a joint beyond its motion (files this crate wrote keep each
/// joint's BVH channels and End Site).
#[derive(Debug, Clone, Default)]
pub(crate) struct Recorded {
    /// The joint's BVH channels, when the file kept them and they are well formed.
    pub(crate) channels: Option<Vec<Channel>>,
    /// The joint's End Site offset, when the file kept one.
    pub(crate) end_site: Option<Vec3>,
    /// Whether this crate wrote the joint (its static leaves are real joints, not end bones).
    pub(crate) ours: bool,
}

/// A skeleton's joints in parent-first order with their local transforms, frame by frame.
pub(crate) struct SampledJoints {
    /// Each joint's unique name.
    pub(crate) names: Vec<String>,
    /// Each joint's parent (an index into the joints, always smaller than the joint's own).
    pub(crate) parents: Vec<Option<usize>>,
    /// What the file recorded about each joint.
    pub(crate) recorded: Vec<Recorded>,
    /// Frames a second.
    pub(crate) fps: f64,
    /// Number of frames.
    pub(crate) frames: usize,
    /// Local rotations, `[frames][joints]`.
    pub(crate) rotations: Vec<Mat3>,
    /// Local translations, `[frames][joints]`.
    pub(crate) translations: Vec<Vec3>,
    /// Each joint's local rotation in the file's rest pose (its nodes' own transforms, the
    /// pose a skin is bound in). Joint frames are turned to line up with the world in this
    /// pose, as BVH's are in its zero pose.
    pub(crate) rest_rotations: Vec<Mat3>,
}

impl SampledJoints {
    /// The clip's motion: joint frames lined up with the world at rest, joints built from the
    /// samples, static leaves as End Sites.
    pub(crate) fn into_motion(mut self) -> LocalMotion {
        self.line_up_frames_at_rest();
        let joints = build_joints(&self);
        let SampledJoints {
            recorded,
            fps,
            frames,
            rotations,
            translations,
            ..
        } = self;
        let (skeleton, rotations, translations) =
            drop_static_leaves(joints, rotations, translations, frames, &recorded);
        LocalMotion {
            skeleton,
            fps,
            rotations,
            translations,
        }
    }
}

impl SampledJoints {
    /// Re-expresses every joint in a frame that is the world's in the rest pose, as BVH joints
    /// are in their zero pose: a joint of rest world rotation `A` under a parent of `P` gets the
    /// local rotation `P R A^T` and translation `P t`. World positions do not change; a file
    /// made from a BVH by a tool that re-bases joints onto bones (Blender) gives back the BVH's
    /// rotations, so the model learns the same features from either.
    fn line_up_frames_at_rest(&mut self) {
        let joints = self.names.len();
        let mut rest_world: Vec<Mat3> = Vec::with_capacity(joints);
        for j in 0..joints {
            let world = match self.parents[j] {
                Some(p) => rest_world[p] * self.rest_rotations[j],
                None => self.rest_rotations[j],
            };
            rest_world.push(world);
        }
        // An End Site hangs in its joint's frame.
        for (recorded, turn) in self.recorded.iter_mut().zip(&rest_world) {
            if let Some(end) = &mut recorded.end_site {
                *end = turn * *end;
            }
        }
        for f in 0..self.frames {
            for j in 0..joints {
                let k = f * joints + j;
                let parent = self.parents[j].map_or(math::IDENTITY, |p| rest_world[p]);
                let turned = parent * self.rotations[k];
                self.rotations[k] = turned * rest_world[j].transpose();
                if self.parents[j].is_some() {
                    self.translations[k] = parent * self.translations[k];
                }
            }
        }
    }
}

/// A node's name without its namespace (`mixamorig:Hips` -> `Hips`).
pub(crate) fn without_namespace(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or(name)
}

/// Names made unique: whitespace runs as `_`, `joint_N` (N the joint's index) for missing or
/// blank names, and `_2`, `_3`, ... after repeats.
pub(crate) fn unique_names(raw: impl IntoIterator<Item = Option<String>>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for (index, name) in raw.into_iter().enumerate() {
        let base = name
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.split_whitespace().collect::<Vec<_>>().join("_"))
            .unwrap_or_else(|| format!("joint_{index}"));
        let mut name = base.clone();
        let mut k = 2;
        while names.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        names.push(name);
    }

    names
}

/// Whether `channels` is a list a BVH joint can have: each rotation axis and each position
/// axis at most once.
pub(crate) fn well_formed(channels: &[Channel]) -> bool {
    let mut seen = Vec::with_capacity(channels.len());
    channels.iter().all(|c| {
        let new = !seen.contains(c);
        seen.push(*c);
        new
    })
}

/// A joint's translation holds still when it changes by less than this share of the skeleton's
/// longest bone over the clip. Exporters that sample every bone every frame write their f32
/// rounding as motion, and that rounding scales with the world coordinates the exporter worked
/// in, not with the bone: a short finger bone's translation wobbles by far more than 1e-7 of
/// its own length.
const STILL_SHARE: f64 = 1e-5;
/// A joint's rotation holds still when no matrix entry changes by more than this.
const STILL_TURN: f64 = 1e-5;

/// Whether joint `j` turns and whether it moves, over the frames.
fn turns_and_moves(
    rotations: &[Mat3],
    translations: &[Vec3],
    (joints, frames, reach): (usize, usize, f64),
    j: usize,
) -> (bool, bool) {
    let (r0, t0) = (rotations[j], translations[j]);
    let (mut turns, mut moves) = (0.0f64, 0.0f64);
    for f in 1..frames {
        let k = f * joints + j;
        turns = turns.max(math::mat_max_abs_diff(&rotations[k], &r0));
        moves = moves.max((translations[k] - t0).norm());
    }
    (turns > STILL_TURN, moves > STILL_SHARE * reach)
}

/// The length of the skeleton's longest bone (its largest first-frame translation below the
/// root), the scale of what counts as a joint moving.
fn reach(translations: &[Vec3], parents: &[Option<usize>]) -> f64 {
    parents
        .iter()
        .zip(translations)
        .filter(|(parent, _)| parent.is_some())
        .map(|(_, t)| t.norm())
        .fold(1e-12, f64::max)
}

/// The skeleton's joints: offsets from the first frame's translations where no position
/// channel moves them, and channels as recorded, or rotations (and positions where they move).
fn build_joints(sampled: &SampledJoints) -> Vec<Joint> {
    let SampledJoints {
        names,
        parents,
        recorded,
        frames,
        rotations,
        translations,
        ..
    } = sampled;
    let joints = names.len();
    let shape = (joints, *frames, reach(translations, parents));
    (0..joints)
        .map(|j| {
            let (turns, moves) = turns_and_moves(rotations, translations, shape, j);
            let parent = parents[j];
            let default_channels = || {
                let mut channels = Vec::new();
                if parent.is_none() || moves {
                    channels.extend(
                        ["Xposition", "Yposition", "Zposition"]
                            .map(|c| Channel::parse(c).expect("channel")),
                    );
                }
                channels.extend(
                    ["Zrotation", "Xrotation", "Yrotation"]
                        .map(|c| Channel::parse(c).expect("channel")),
                );
                channels
            };
            // Recorded channels are kept only when they can carry the motion: no rotation
            // channel means the identity, no position channel a fixed offset.
            let channels = match &recorded[j].channels {
                Some(channels) => {
                    let rotates = channels.iter().any(|c| matches!(c, Channel::Rotation(_)));
                    let positions = channels.iter().any(|c| matches!(c, Channel::Position(_)));
                    let identity =
                        math::mat_max_abs_diff(&rotations[j], &math::IDENTITY) < STILL_TURN;
                    if (rotates || (!turns && identity)) && (positions || !moves) {
                        channels.clone()
                    } else {
                        default_channels()
                    }
                }
                None => default_channels(),
            };
            Joint {
                name: names[j].clone(),
                parent,
                offset: translations[j],
                channels,
                end_site: recorded[j].end_site,
            }
        })
        .collect()
}

/// Leaf joints that never move and are their parent's only child become the parent's End Site
/// (Blender's leaf bones, Mixamo's `_End` bones). Joints this crate wrote keep their End Sites
/// in the file and have no such joints.
fn drop_static_leaves(
    mut joints: Vec<Joint>,
    rotations: Vec<Mat3>,
    translations: Vec<Vec3>,
    frames: usize,
    recorded: &[Recorded],
) -> (Skeleton, Vec<Mat3>, Vec<Vec3>) {
    let count = joints.len();
    let parents: Vec<Option<usize>> = joints.iter().map(|j| j.parent).collect();
    let shape = (count, frames, reach(&translations, &parents));
    let mut keep = vec![true; count];
    for j in 1..count {
        let Some(p) = joints[j].parent else { continue };
        let leaf = !joints.iter().any(|o| o.parent == Some(j));
        let only_child = joints.iter().filter(|o| o.parent == Some(p)).count() == 1;
        // The frames are read only for a joint that could become an End Site.
        let candidate = !recorded[j].ours && leaf && only_child && joints[p].end_site.is_none();
        if candidate && turns_and_moves(&rotations, &translations, shape, j) == (false, false) {
            joints[p].end_site = Some(translations[j]);
            keep[j] = false;
        }
    }
    if keep.iter().all(|&k| k) {
        return (Skeleton { joints }, rotations, translations);
    }
    let new_index: Vec<Option<usize>> = keep
        .iter()
        .scan(0, |next, &k| {
            let index = k.then_some(*next);
            *next += usize::from(k);
            Some(index)
        })
        .collect();
    let kept: Vec<Joint> = joints
        .into_iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(mut joint, _)| {
            joint.parent = joint.parent.and_then(|p| new_index[p]);
            joint
        })
        .collect();
    (
        Skeleton { joints: kept },
        kept_joints(rotations, &keep),
        kept_joints(translations, &keep),
    )
}

/// The `[frames][joints]` values of the joints marked in `keep`.
fn kept_joints<T>(values: Vec<T>, keep: &[bool]) -> Vec<T> {
    values
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep[i % keep.len()])
        .map(|(_, v)| v)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn namespaces_are_dropped_from_names() {
        assert_eq!(without_namespace("mixamorig:Hips"), "Hips");
        assert_eq!(without_namespace("mixamorig1:LeftUpLeg"), "LeftUpLeg");
        assert_eq!(without_namespace("a:b:Spine"), "Spine");
        assert_eq!(without_namespace("Hips"), "Hips");
    }

    #[test]
    fn names_are_made_unique_and_blank_ones_numbered() {
        let names = unique_names([
            Some("Hips".to_string()),
            Some("Left Leg".to_string()),
            None,
            Some("Hips".to_string()),
            Some("  ".to_string()),
            Some("Hips".to_string()),
        ]);
        assert_eq!(
            names,
            ["Hips", "Left_Leg", "joint_2", "Hips_2", "joint_4", "Hips_3"]
        );
    }

    /// A turn by `angle` about `axis` (unit).
    fn turn(axis: Vec3, angle: f64) -> Mat3 {
        let (s, c) = (angle / 2.0).sin_cos();
        math::mat_from_quat([axis[0] * s, axis[1] * s, axis[2] * s, c])
    }

    #[test]
    fn lining_up_frames_at_rest_keeps_every_position_and_makes_rest_the_identity() {
        // A chain of three joints whose rest frames are turned every which way, in two frames:
        // the rest pose itself and a bent pose.
        let rest = vec![
            turn(Vec3::new(0.0, 0.0, 1.0), 0.7),
            turn(Vec3::new(1.0, 0.0, 0.0), -1.1),
            turn(Vec3::new(0.0, 1.0, 0.0), 2.0),
        ];
        let bend = turn(Vec3::new(0.6, 0.0, 0.8), 0.5);
        let offsets = [[0.1, 0.9, 0.2], [0.0, 0.5, 0.1], [0.3, 0.4, 0.0]].map(Vec3);
        let mut rotations = rest.clone();
        rotations.extend([rest[0], rest[1] * bend, rest[2]]);
        let translations: Vec<Vec3> = offsets.iter().chain(&offsets).copied().collect();
        let world = |rotations: &[Mat3], translations: &[Vec3]| -> Vec<Vec3> {
            let mut out = Vec::new();
            for f in 0..2 {
                let (mut r, mut p) = (math::IDENTITY, Vec3::ZERO);
                for j in 0..3 {
                    p += r * translations[3 * f + j];
                    r = r * rotations[3 * f + j];
                    out.push(p);
                }
            }
            out
        };
        let before = world(&rotations, &translations);
        let mut sampled = SampledJoints {
            names: unique_names(["a", "b", "c"].map(|s| Some(s.to_string()))),
            parents: vec![None, Some(0), Some(1)],
            recorded: vec![Recorded::default(); 3],
            fps: 30.0,
            frames: 2,
            rotations,
            translations,
            rest_rotations: rest,
        };
        sampled.line_up_frames_at_rest();
        let after = world(&sampled.rotations, &sampled.translations);
        for (a, b) in before.iter().zip(&after) {
            assert!((*a - *b).norm() < 1e-12, "{a:?} {b:?}");
        }
        for j in 0..3 {
            assert!(math::mat_max_abs_diff(&sampled.rotations[j], &math::IDENTITY) < 1e-12);
        }
        assert!(math::mat_max_abs_diff(&sampled.rotations[4], &math::IDENTITY) > 0.1);
    }

    #[test]
    fn a_still_only_child_leaf_becomes_its_parents_end_site() {
        // Root, a turning child, and a leaf under it that never moves.
        let frames = 3;
        let turn = |a: f64| math::mat_from_quat([0.0, 0.0, (a / 2.0).sin(), (a / 2.0).cos()]);
        let mut rotations = Vec::new();
        let mut translations = Vec::new();
        for f in 0..frames {
            rotations.extend([math::IDENTITY, turn(0.1 * f as f64), math::IDENTITY]);
            translations.extend([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.25, 0.0]].map(Vec3));
        }
        let motion = SampledJoints {
            names: unique_names(["root", "knee", "toe_end"].map(|s| Some(s.to_string()))),
            parents: vec![None, Some(0), Some(1)],
            recorded: vec![Recorded::default(); 3],
            fps: 30.0,
            frames,
            rotations,
            translations,
            rest_rotations: vec![math::IDENTITY; 3],
        }
        .into_motion();
        assert_eq!(motion.skeleton.len(), 2);
        assert_eq!(
            motion.skeleton.joints[1].end_site,
            Some(Vec3::new(0.0, 0.25, 0.0))
        );
        assert_eq!(motion.rotations.len(), 2 * frames);
    }
}
