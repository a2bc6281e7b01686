//! A motion as a new animation of a character's nodes, for splicing into its file: the keys of
//! each driven (or retargeted) node appended to the character's binary buffer.

use serde_json::{Value, json};
use sinmdm::motion::ground::{GROUND_PERCENTILE, percentile};
use sinmdm::motion::math::{self, Vec3};
use sinmdm::motion::{GlobalPose, LocalMotion, UpAxis, global_poses, up};

use super::drive::{Drive, Driven};
use super::nodes::Similarity;
use super::replant::{CharacterMotion, character_motion};
use super::write::{Binary, quaternion_xyzw, unit_f32};

/// The motion's canonical global poses with its travel scaled to the character's units, and
/// the lift from its ground to the character's (none unless retargeted onto a standing rig).
fn scaled_poses(motion: &LocalMotion, up_axis: UpAxis, drive: &Drive) -> (Vec<GlobalPose>, Vec3) {
    let mut canonical = up::to_canonical(motion, up_axis);
    for t in &mut canonical.translations {
        *t = *t * drive.scale;
    }
    let poses = global_poses(&canonical);
    // From the motions' ground to the character's, for a retargeted character.
    let lift = drive.grounds.as_ref().map_or(0.0, |(ground, joints)| {
        let mut lowest: Vec<f64> = poses
            .iter()
            .map(|p| {
                joints
                    .iter()
                    .map(|&j| p.joints[j][1])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        lowest.sort_by(f64::total_cmp);
        ground - percentile(&lowest, GROUND_PERCENTILE)
    });
    (poses, Vec3::new(0.0, lift, 0.0))
}

/// One motion as an animation of a retargeted character: its bones' rotations (the legs'
/// turned so the feet stand still again) and the carrying bone's translation, every frame.
pub(super) fn retargeted_animation(
    binary: &mut Binary,
    (name, motion): (&str, &LocalMotion),
    up_axis: UpAxis,
    drive: &Drive,
    (parent, rest, names): (&[Option<usize>], &[Similarity], &[String]),
) -> Option<(Value, Vec<String>)> {
    let (poses, lift) = scaled_poses(motion, up_axis, drive);
    let character = character_motion(
        &motion.skeleton,
        &poses,
        lift,
        motion.fps,
        drive,
        (parent, rest, names),
    )?;
    let CharacterMotion {
        nodes,
        above,
        motion: played,
        planted,
    } = character;
    let frames = played.frame_count();
    let count = nodes.len();
    let input = binary.key_times(frames, played.fps);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    let inverse_above = above.rotation.transpose();
    for (k, &node) in nodes.iter().enumerate() {
        let rest_local = match parent[node] {
            Some(p) => rest[p].rotation.transpose() * rest[node].rotation,
            None => rest[node].rotation,
        };
        let local = |f: usize| {
            let r = played.rotations[f * count + k];
            if k == 0 { inverse_above * r } else { r }
        };
        let driven = drive.driven.iter().any(|d| d.node == node);
        let turned = (0..frames).any(|f| math::mat_max_abs_diff(&local(f), &rest_local) > 1e-9);
        if !(driven || turned) {
            continue;
        }
        let mut rotations = Vec::with_capacity(frames * 4);
        let mut previous = None;
        for f in 0..frames {
            let q = quaternion_xyzw(&local(f), previous);
            previous = Some(q);
            rotations.extend(unit_f32(q));
        }
        let output = binary.accessor(&rotations, "VEC4", 4, false);
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "rotation"}}),
        );
        if k == 0 {
            let mut translations = Vec::with_capacity(frames * 3);
            for f in 0..frames {
                let world = played.translations[f * count];
                let local = (inverse_above * (world - above.translation)) * (1.0 / above.scale);
                translations.extend(local.map(|v| v as f32));
            }
            let output = binary.accessor(&translations, "VEC3", 3, false);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "translation"}}));
        }
    }
    let feet = planted.iter().map(|&k| names[nodes[k]].clone()).collect();
    Some((
        json!({"name": name, "samplers": samplers, "channels": channels}),
        feet,
    ))
}

/// One motion as an animation of the character's nodes: each driven node's rotation (and the
/// translation of those that move) every frame.
pub(super) fn spliced_animation(
    binary: &mut Binary,
    name: &str,
    motion: &LocalMotion,
    up_axis: UpAxis,
    drive: &Drive,
    (parent, rest): (&[Option<usize>], &[Similarity]),
) -> Value {
    let (poses, lift) = scaled_poses(motion, up_axis, drive);
    let frames = motion.frame_count();
    let input = binary.key_times(frames, motion.fps);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for driven in &drive.driven {
        let node = driven.node;
        let mut rotations = Vec::with_capacity(frames * 4);
        let mut translations = Vec::with_capacity(frames * 3);
        let (anchor, fixed) = parent_frame(node, parent, rest, &drive.driven);
        let mut previous = None;
        for pose in &poses {
            let parent_global = match anchor {
                Some((above, p)) => Similarity {
                    rotation: (pose.rotations[above.joint] * above.turn),
                    translation: pose.joints[above.joint] + lift,
                    scale: rest[p].scale,
                }
                .then(&fixed),
                None => fixed,
            };
            let inverse_parent = parent_global.rotation.transpose();
            let global_rotation = pose.rotations[driven.joint] * driven.turn;
            let local_rotation = inverse_parent * global_rotation;
            let q = quaternion_xyzw(&local_rotation, previous);
            previous = Some(q);
            rotations.extend(unit_f32(q));
            if driven.moves {
                let world = pose.joints[driven.joint] + lift;
                let local = (inverse_parent * (world - parent_global.translation))
                    * (1.0 / parent_global.scale);
                translations.extend(local.map(|v| v as f32));
            }
        }
        let output = binary.accessor(&rotations, "VEC4", 4, false);
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "rotation"}}),
        );
        if driven.moves {
            let output = binary.accessor(&translations, "VEC3", 3, false);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "translation"}}));
        }
    }
    json!({"name": name, "samplers": samplers, "channels": channels})
}

/// How the global transform of node `n`'s parent is had at any frame: the nearest driven node
/// above it (how it is driven, and the node) followed by the fixed rest transforms of the
/// nodes between; or, with no driven node above, that parent's fixed global rest transform.
fn parent_frame(
    n: usize,
    parent: &[Option<usize>],
    rest: &[Similarity],
    driven: &[Driven],
) -> (Option<(Driven, usize)>, Similarity) {
    let mut chain: Vec<usize> = Vec::new();
    let mut at = parent[n];
    while let Some(p) = at {
        if let Some(above) = driven.iter().find(|d| d.node == p) {
            let fixed = chain.iter().rev().fold(Similarity::IDENTITY, |g, &c| {
                let above = rest[parent[c].expect("a node below a joint has a parent")];
                g.then(&relative(&above, &rest[c]))
            });
            return (Some((*above, p)), fixed);
        }
        chain.push(p);
        at = parent[p];
    }
    let fixed = chain.first().map_or(Similarity::IDENTITY, |&c| rest[c]);
    (None, fixed)
}

/// `local` as a transform relative to `above` (both global): `above^-1 local`.
fn relative(above: &Similarity, local: &Similarity) -> Similarity {
    let inverse_rotation = above.rotation.transpose();
    Similarity {
        rotation: (inverse_rotation * local.rotation),
        translation: ((inverse_rotation * (local.translation - above.translation))
            * (1.0 / above.scale)),
        scale: local.scale / above.scale,
    }
}
