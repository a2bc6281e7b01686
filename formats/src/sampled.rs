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
}

impl SampledJoints {
    /// The clip's motion: joints built from the samples, static leaves as End Sites.
    pub(crate) fn into_motion(self) -> LocalMotion {
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

/// A joint's translation holds still when it changes by less than this share of its length
/// over the clip (f32 values round at about 1e-7 of it; exporters that sample every bone every
/// frame write that rounding as motion).
const STILL_SHARE: f64 = 1e-5;
/// A joint's rotation holds still when no matrix entry changes by more than this.
const STILL_TURN: f64 = 1e-5;

/// Whether joint `j` turns and whether it moves, over the frames.
fn turns_and_moves(
    rotations: &[Mat3],
    translations: &[Vec3],
    joints: usize,
    frames: usize,
    j: usize,
) -> (bool, bool) {
    let (r0, t0) = (rotations[j], translations[j]);
    let (mut turns, mut moves) = (0.0f64, 0.0f64);
    for f in 1..frames {
        let k = f * joints + j;
        turns = turns.max(math::mat_max_abs_diff(&rotations[k], &r0));
        moves = moves.max(math::norm(math::sub(translations[k], t0)));
    }
    let length = math::norm(t0).max(1e-12);
    (turns > STILL_TURN, moves > STILL_SHARE * length)
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
    (0..joints)
        .map(|j| {
            let (turns, moves) = turns_and_moves(rotations, translations, joints, *frames, j);
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
    let mut keep = vec![true; count];
    for j in 1..count {
        let Some(p) = joints[j].parent else { continue };
        let leaf = !joints.iter().any(|o| o.parent == Some(j));
        let only_child = joints.iter().filter(|o| o.parent == Some(p)).count() == 1;
        let (turns, moves) = turns_and_moves(&rotations, &translations, count, frames, j);
        if !recorded[j].ours
            && leaf
            && only_child
            && !turns
            && !moves
            && joints[p].end_site.is_none()
        {
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

    #[test]
    fn a_still_only_child_leaf_becomes_its_parents_end_site() {
        // Root, a turning child, and a leaf under it that never moves.
        let frames = 3;
        let turn = |a: f64| math::mat_from_quat_wxyz([(a / 2.0).cos(), 0.0, 0.0, (a / 2.0).sin()]);
        let mut rotations = Vec::new();
        let mut translations = Vec::new();
        for f in 0..frames {
            rotations.extend([math::IDENTITY, turn(0.1 * f as f64), math::IDENTITY]);
            translations.extend([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.25, 0.0]]);
        }
        let motion = SampledJoints {
            names: unique_names(["root", "knee", "toe_end"].map(|s| Some(s.to_string()))),
            parents: vec![None, Some(0), Some(1)],
            recorded: vec![Recorded::default(); 3],
            fps: 30.0,
            frames,
            rotations,
            translations,
        }
        .into_motion();
        assert_eq!(motion.skeleton.len(), 2);
        assert_eq!(motion.skeleton.joints[1].end_site, Some([0.0, 0.25, 0.0]));
        assert_eq!(motion.rotations.len(), 2 * frames);
    }
}
