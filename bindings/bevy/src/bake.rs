//! Generated motion as a Bevy [`AnimationClip`], to blend in Bevy's animation graph with
//! authored clips (the `animation-clip` feature).
//!
//! Each joint is targeted by an [`AnimationTargetId`] made from a path of names, as Bevy's glTF
//! loader names a scene's nodes: `prefix` (the names of the nodes above the skeleton in the
//! rig, from the scene's root node down; empty for a skeleton from
//! [`spawn_skeleton`](crate::character::spawn_skeleton)), then the joints from the top joint
//! down to the joint. A clip plays on any rig whose nodes carry the same names.

use bevy_animation::prelude::*;
use bevy_animation::{AnimatedBy, AnimationTargetId, animated_field};
use bevy_ecs::prelude::*;
use bevy_math::curve::UnevenSampleAutoCurve;
use bevy_transform::components::Transform;
use sinmdm::{Pose, Skeleton};

use crate::frame::EngineFrame;

/// Why poses could not be baked.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// Fewer than two poses make no curve.
    #[error("a clip needs at least two poses, got {0}")]
    TooFewPoses(usize),
    /// The frame rate is not a positive number.
    #[error("the frame rate must be a positive number, got {0}")]
    BadFrameRate(f64),
    /// A pose does not have one rotation and one translation per joint.
    #[error(
        "pose {index} has {rotations} rotations and {translations} translations for {joints} joints"
    )]
    PoseSize {
        /// The pose.
        index: usize,
        /// Its rotations.
        rotations: usize,
        /// Its translations.
        translations: usize,
        /// The skeleton's joints.
        joints: usize,
    },
}

/// The animation target of every joint, in skeleton order, below the nodes named `prefix`.
pub fn joint_targets(skeleton: &Skeleton, prefix: &[&str]) -> Vec<AnimationTargetId> {
    (0..skeleton.len())
        .map(|j| {
            let mut path = vec![j];
            let mut at = j;
            while let Some(parent) = skeleton.joints[at].parent {
                path.push(parent);
                at = parent;
            }
            let names: Vec<Name> = prefix
                .iter()
                .map(|p| Name::new(p.to_string()))
                .chain(
                    path.iter()
                        .rev()
                        .map(|&i| Name::new(skeleton.joints[i].name.clone())),
                )
                .collect();
            AnimationTargetId::from_names(names.iter())
        })
        .collect()
}

/// Bakes `poses` (one per frame at `fps`, at least two) into a clip that sets every joint's
/// translation and rotation, placed in Bevy's frame by `frame`, each joint targeted below the
/// nodes named `prefix` ([`joint_targets`]).
pub fn bake_clip(
    skeleton: &Skeleton,
    frame: &EngineFrame,
    poses: &[Pose],
    fps: f64,
    prefix: &[&str],
) -> Result<AnimationClip, BakeError> {
    if poses.len() < 2 {
        return Err(BakeError::TooFewPoses(poses.len()));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(BakeError::BadFrameRate(fps));
    }
    let joints = skeleton.len();
    if let Some((index, p)) = poses
        .iter()
        .enumerate()
        .find(|(_, p)| p.rotations.len() != joints || p.translations.len() != joints)
    {
        return Err(BakeError::PoseSize {
            index,
            rotations: p.rotations.len(),
            translations: p.translations.len(),
            joints,
        });
    }
    let mut clip = AnimationClip::default();
    let times: Vec<f32> = (0..poses.len()).map(|i| (i as f64 / fps) as f32).collect();
    for (j, target) in joint_targets(skeleton, prefix).into_iter().enumerate() {
        let top = skeleton.joints[j].parent.is_none();
        let transforms: Vec<Transform> = poses
            .iter()
            .map(|p| frame.joint_transform(p, j, top))
            .collect();
        // Two or more finite, increasing times: the curves are always made.
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
    Ok(clip)
}

/// Makes the `joints` of a skeleton from [`spawn_skeleton`](crate::spawn_skeleton) (in
/// skeleton order) animatable by the [`AnimationPlayer`]
/// on `player`: each gets its [`AnimationTargetId`] and [`AnimatedBy`].
pub fn target_joints(
    commands: &mut Commands,
    skeleton: &Skeleton,
    joints: &[Entity],
    player: Entity,
) {
    for (&entity, target) in joints.iter().zip(joint_targets(skeleton, &[])) {
        commands.entity(entity).insert((target, AnimatedBy(player)));
    }
}
