//! Shared helpers for the integration tests: where the clips are, and the small trained model.

#![allow(dead_code)]

use std::path::PathBuf;

use sinmdm::motion::GlobalPose;

/// The workspace root.
pub fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The clips shipped with the project (it is an error if any of the four is missing, so a test
/// that loops over them cannot pass over none).
pub fn shipped_clips() -> Vec<PathBuf> {
    let dir = workspace().join("tests/data/bvh");
    let clips = bvh_files(dir.clone());
    for name in [
        "fox_survey_khronos.bvh",
        "human_dance_rokoko_jesse.bvh",
        "human_hop_cmu_131_03.bvh",
        "human_walk_cmu_131_01.bvh",
    ] {
        assert!(
            clips.iter().any(|p| p.ends_with(name)),
            "{} lacks {name}",
            dir.display()
        );
    }
    clips
}

/// The shipped clips plus, when the team's shared data folder sits beside the checkout, every
/// clip in it (including non-commercial ones that are never copied into the repository).
pub fn all_clips() -> Vec<PathBuf> {
    let mut clips = shipped_clips();
    let shared = bvh_files(workspace().join("../shared/data/bvh"));
    let shipped_names: Vec<_> = clips
        .iter()
        .map(|p| p.file_name().map(|n| n.to_owned()))
        .collect();
    clips.extend(
        shared
            .into_iter()
            .filter(|p| !shipped_names.contains(&p.file_name().map(|n| n.to_owned()))),
    );
    clips
}

fn bvh_files(dir: PathBuf) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "bvh"))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    files
}

/// Largest distance between corresponding points (joints and End Sites) of two pose sequences.
pub fn max_position_error(a: &[GlobalPose], b: &[GlobalPose]) -> f64 {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| {
            assert_eq!(p.joints.len(), q.joints.len());
            p.points().zip(q.points())
        })
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

/// The small trained model (tests/data/models/walk_tiny.onnx, or `SINMDM_TEST_MODEL`) on one
/// thread.
pub fn tiny_model() -> sinmdm::Model {
    sinmdm::Model::open(
        std::env::var("SINMDM_TEST_MODEL")
            .map(PathBuf::from)
            .unwrap_or(workspace().join("tests/data/models/walk_tiny.onnx")),
        &sinmdm::ModelOptions { threads: Some(1) },
    )
    .expect("the test model opens (run scripts/setup.sh first)")
}

/// The CMU walk in `model`'s layout, raw, cut to `frames`.
pub fn walk_features(model: &sinmdm::Model, frames: usize) -> ndarray::Array2<f32> {
    let clip = sinmdm::bvh::read_bvh(workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh"))
        .unwrap();
    let all = sinmdm::motion::encode_for(&clip, &model.metadata().layout).unwrap();
    all.slice(ndarray::s![.., ..frames]).to_owned()
}
