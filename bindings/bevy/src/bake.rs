//! Generated motion as a Bevy [`AnimationClip`], to blend in Bevy's animation graph with
//! authored clips (the `animation-clip` feature).
//!
//! Each joint is targeted by an [`AnimationTargetId`] made from the names of the joints from
//! the top joint down to it (as Bevy's glTF loader names a skeleton's bones), so a clip plays on
//! a skeleton from [`spawn_skeleton`](crate::character::spawn_skeleton) or on any rig whose
//! bones carry the same names.

use bevy_animation::prelude::*;
use bevy_animation::{AnimatedBy, AnimationTargetId, animated_field};
use bevy_ecs::prelude::*;
use bevy_math::curve::UnevenSampleAutoCurve;
use bevy_transform::components::Transform;
use sinmdm::{Pose, Skeleton};

use crate::frame::EngineFrame;

/// The animation target of every joint, in skeleton order.
pub fn joint_targets(skeleton: &Skeleton) -> Vec<AnimationTargetId> {
    (0..skeleton.len())
        .map(|j| {
            let mut path = vec![j];
            let mut at = j;
            while let Some(parent) = skeleton.joints[at].parent {
                path.push(parent);
                at = parent;
            }
            let names: Vec<Name> = path
                .iter()
                .rev()
                .map(|&i| Name::new(skeleton.joints[i].name.clone()))
                .collect();
            AnimationTargetId::from_names(names.iter())
        })
        .collect()
}

/// Bakes `poses` (one per frame at `fps`) into a clip that sets every joint's translation and
/// rotation, placed in Bevy's frame by `frame`.
pub fn bake_clip(
    skeleton: &Skeleton,
    frame: &EngineFrame,
    poses: &[Pose],
    fps: f64,
) -> AnimationClip {
    let mut clip = AnimationClip::default();
    let times: Vec<f32> = (0..poses.len()).map(|i| (i as f64 / fps) as f32).collect();
    for (j, target) in joint_targets(skeleton).into_iter().enumerate() {
        let top = skeleton.joints[j].parent.is_none();
        let transforms: Vec<Transform> = poses
            .iter()
            .map(|p| frame.joint_transform(p, j, top))
            .collect();
        // A clip of fewer than two frames has no curve to make.
        if let Ok(curve) = UnevenSampleAutoCurve::new(
            times
                .iter()
                .copied()
                .zip(transforms.iter().map(|t| t.translation)),
        ) {
            clip.add_curve_to_target(
                target,
                AnimatableCurve::new(animated_field!(Transform::translation), curve),
            );
        }
        if let Ok(curve) = UnevenSampleAutoCurve::new(
            times
                .iter()
                .copied()
                .zip(transforms.iter().map(|t| t.rotation)),
        ) {
            clip.add_curve_to_target(
                target,
                AnimatableCurve::new(animated_field!(Transform::rotation), curve),
            );
        }
    }
    clip.set_duration(times.last().copied().unwrap_or(0.0));
    clip
}

/// Makes the `joints` of a skeleton (in skeleton order) animatable by the [`AnimationPlayer`]
/// on `player`: each gets its [`AnimationTargetId`] and [`AnimatedBy`].
pub fn target_joints(
    commands: &mut Commands,
    skeleton: &Skeleton,
    joints: &[Entity],
    player: Entity,
) {
    for (&entity, target) in joints.iter().zip(joint_targets(skeleton)) {
        commands.entity(entity).insert((target, AnimatedBy(player)));
    }
}
