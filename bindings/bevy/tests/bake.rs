//! Baking generated motion into an `AnimationClip` (the `animation-clip` feature).
#![cfg(feature = "animation-clip")]

use std::collections::HashSet;
use std::path::PathBuf;

use bevy_animation::AnimationTargetId;
use sinmdm::{Stream, StreamOptions};
use sinmdm_bevy::EngineFrame;
use sinmdm_bevy::bake::{BakeError, bake_clip, joint_targets};

#[test]
fn a_baked_clip_animates_every_joint_for_the_motions_length() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../onnx-models/human_walk_cmu.onnx");
    let model = sinmdm_bevy::MotionModel::open(path, Some(1)).unwrap();
    let metadata = model.metadata().clone();
    let frames = 90;
    let poses = model.with(|m| {
        let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
        stream.next(m, frames).unwrap().poses()
    });
    let skeleton = &metadata.layout.skeleton;
    let frame = EngineFrame::of(&metadata, None).unwrap();
    let clip = bake_clip(skeleton, &frame, &poses, metadata.layout.fps, &[]).unwrap();
    let expected = (frames - 1) as f32 / metadata.layout.fps as f32;
    assert!(
        (clip.duration() - expected).abs() < 1e-5,
        "{}",
        clip.duration()
    );

    // Targets named by the path of joint names from the top joint, as Bevy's glTF loader does.
    let targets = joint_targets(skeleton, &[]);
    assert_eq!(targets.len(), skeleton.len());
    assert_eq!(targets.iter().collect::<HashSet<_>>().len(), skeleton.len());
    let first_child = skeleton
        .joints
        .iter()
        .position(|j| j.parent == Some(0))
        .unwrap();
    let by_hand = AnimationTargetId::from_iter([
        skeleton.joints[0].name.as_str(),
        skeleton.joints[first_child].name.as_str(),
    ]);
    assert_eq!(targets[first_child], by_hand);
    for target in &targets {
        let curves = clip
            .curves_for_target(*target)
            .expect("every joint has curves");
        assert_eq!(curves.len(), 2, "a translation and a rotation curve");
    }
}

#[test]
fn targets_sit_below_the_rig_s_own_nodes_and_bad_input_is_refused() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../onnx-models/human_walk_cmu.onnx");
    let model = sinmdm_bevy::MotionModel::open(path, Some(1)).unwrap();
    let metadata = model.metadata().clone();
    let skeleton = &metadata.layout.skeleton;
    // A glTF rig's bones sit below its scene's nodes (an "Armature"): the path starts there.
    let below = joint_targets(skeleton, &["Armature"]);
    let by_hand = AnimationTargetId::from_iter(["Armature", skeleton.joints[0].name.as_str()]);
    assert_eq!(below[0], by_hand);
    assert_ne!(below[0], joint_targets(skeleton, &[])[0]);

    let frame = EngineFrame::of(&metadata, None).unwrap();
    let poses = model.with(|m| {
        let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
        stream.next(m, 3).unwrap().poses()
    });
    let fps = metadata.layout.fps;
    assert!(matches!(
        bake_clip(skeleton, &frame, &poses[..1], fps, &[]),
        Err(BakeError::TooFewPoses(1))
    ));
    assert!(matches!(
        bake_clip(skeleton, &frame, &poses, 0.0, &[]),
        Err(BakeError::BadFrameRate(_))
    ));
    let mut short = poses.clone();
    short[2].rotations.pop();
    assert!(matches!(
        bake_clip(skeleton, &frame, &short, fps, &[]),
        Err(BakeError::PoseSize { index: 2, .. })
    ));
}
