//! Baking generated motion into an `AnimationClip` (the `animation-clip` feature).
#![cfg(feature = "animation-clip")]

use std::collections::HashSet;
use std::path::PathBuf;

use bevy_animation::AnimationTargetId;
use sinmdm::{Stream, StreamOptions};
use sinmdm_bevy::EngineFrame;
use sinmdm_bevy::bake::{bake_clip, joint_targets};

#[test]
fn a_baked_clip_animates_every_joint_for_the_motions_length() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../onnx-models/human_walk_cmu.onnx");
    let model = sinmdm_bevy::MotionModel::open(path, Some(1)).unwrap();
    let metadata = model.with(|m| m.metadata().clone());
    let frames = 90;
    let poses = model.with(|m| {
        let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
        stream.next(m, frames).unwrap().poses()
    });
    let skeleton = &metadata.layout.skeleton;
    let frame = EngineFrame::of(&metadata, None);
    let clip = bake_clip(skeleton, &frame, &poses, metadata.layout.fps);
    let expected = (frames - 1) as f32 / metadata.layout.fps as f32;
    assert!(
        (clip.duration() - expected).abs() < 1e-5,
        "{}",
        clip.duration()
    );

    // Targets named by the path of joint names from the top joint, as Bevy's glTF loader does.
    let targets = joint_targets(skeleton);
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
