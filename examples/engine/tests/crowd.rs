//! The engine path on a shipped model: real onnxruntime, real poses.

use std::path::PathBuf;

use sinmdm_engine_example::generate_crowd;

#[test]
fn a_crowd_from_the_shipped_fox_model_has_a_pose_per_frame_and_joint() {
    let model =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../onnx-models/fox_survey_khronos.onnx");
    let mut ticks = Vec::new();
    let crowd = generate_crowd(&model, 3, 2.0, 5, 4, |done, steps| {
        ticks.push((done, steps))
    })
    .expect("run scripts/setup.sh first");
    assert_eq!(ticks, vec![(4, 20), (8, 20), (12, 20), (16, 20), (20, 20)]);
    assert_eq!(crowd.len(), 3);
    for character in &crowd {
        assert_eq!(
            character.poses.len(),
            (2.0 * character.fps).round() as usize
        );
        for pose in &character.poses {
            assert_eq!(pose.rotations.len(), character.joints.len());
            assert_eq!(pose.translations.len(), character.joints.len());
            for q in &pose.rotations {
                let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
                assert!((norm - 1.0).abs() < 1e-4, "a rotation of norm {norm}");
            }
            assert!(pose.root_position().iter().all(|v| v.is_finite()));
        }
    }
    // Different seeds within the crowd: the characters move differently.
    assert_ne!(crowd[0].poses, crowd[1].poses);
}
