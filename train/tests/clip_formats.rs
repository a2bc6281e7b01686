//! Training from a glTF clip: the same training features as from the BVH it was made from, and
//! a run that keeps its glTF clip, resumes from it and records it in the model file.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use burn::tensor::Device;
use sinmdm::bvh::read_bvh;
use sinmdm::motion::{ColumnKind, UpAxis};
use sinmdm_formats::gltf::{GltfWriteOptions, write_gltf};
use sinmdm_train::clip_data::ClipData;
use sinmdm_train::{TrainConfig, Trainer};

mod common;
use common::root;

fn tiny() -> TrainConfig {
    TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap()
}

/// `clip` written as glTF (`extension`) in metres at `metres` per unit, beside the scratch files.
fn as_gltf(clip: &str, metres: f64, extension: &str) -> PathBuf {
    let motion = read_bvh(root().join("tests/data/bvh").join(clip))
        .unwrap()
        .to_local();
    let path = common::scratch("formats", clip).with_extension(extension);
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: metres,
        proxy_mesh: false,
    };
    write_gltf(&path, &[("Take 1".into(), &motion)], &options).unwrap();
    path
}

#[test]
fn a_gltf_clip_gives_the_training_features_of_its_bvh() {
    let config = tiny();
    for (clip, metres) in [
        ("human_walk_cmu_131_01.bvh", 0.0564),
        ("fox_survey_khronos.bvh", 0.01),
    ] {
        let bvh = ClipData::load(
            &root().join("tests/data/bvh").join(clip),
            &config.data,
            &config.model,
        )
        .unwrap();
        for extension in ["glb", "gltf"] {
            let file = as_gltf(clip, metres, extension);
            let gltf = ClipData::load(&file, &config.data, &config.model).unwrap();
            assert_eq!(gltf.features.dim(), bvh.features.dim(), "{clip}");
            // The features before normalisation: 6D rotations within 1e-5, lengths (root travel
            // and height, position channels) within 1e-5 of the skeleton's height once in the
            // same unit, contact labels equal. (Normalised, a root that stands still turns
            // f32's rounding of its position, under 1e-7 m, into unit-variance noise.)
            let raw_gltf = gltf.facts.normalizer.denormalize(gltf.features.view());
            let raw_bvh = bvh.facts.normalizer.denormalize(bvh.features.view());
            let height = bvh.facts.layout.skeleton_height * metres;
            for (r, column) in bvh.facts.layout.columns().iter().enumerate() {
                let (scale, allowed) = match column.kind {
                    ColumnKind::Rotation6d(_) => (1.0, 1e-5),
                    ColumnKind::Contact => (1.0, 0.0),
                    _ => (metres, 1e-5 * height),
                };
                let worst = raw_gltf
                    .row(r)
                    .iter()
                    .zip(raw_bvh.row(r).iter())
                    .map(|(a, b)| (f64::from(*a) - f64::from(*b) * scale).abs())
                    .fold(0f64, f64::max);
                assert!(
                    worst <= allowed,
                    "{clip} as {extension}, row {r} ({:?}): max |diff| {worst} > {allowed}",
                    column.kind
                );
            }
            let source = gltf.facts.source.as_ref().expect("the source is recorded");
            assert_eq!(source.format, "gltf");
            assert_eq!(source.animation.as_deref(), Some("Take 1"));
            assert!(bvh.facts.source.is_none());
            std::fs::remove_file(file).unwrap();
        }
    }
}

#[test]
fn a_run_keeps_its_gltf_clip_resumes_from_it_and_records_it() {
    let file = as_gltf("fox_survey_khronos.bvh", 0.01, "glb");
    let mut config = tiny();
    config.training.steps = 4;
    config.training.checkpoint_every = 2;
    config.data.animation = Some("Take 1".into());
    let run = common::scratch("formats", "run");
    let device = || Device::flex().autodiff();
    let mut first = Trainer::start(&file, config.clone(), &run, device()).unwrap();
    first.step().unwrap();
    first.step().unwrap();
    first.save().unwrap();
    drop(first);
    assert!(run.join("clip.glb").is_file());
    std::fs::remove_file(&file).unwrap();
    // The original is gone: the run reads its own copy.
    let mut second = Trainer::resume(&run, None, None, device()).unwrap();
    let end = second.run(&AtomicBool::new(false), |_| {}).unwrap();
    let sinmdm_train::RunEnd::Finished(checkpoint) = end else {
        panic!("{end:?}");
    };
    let model = run.join("fox.onnx");
    sinmdm_train::export::export_checkpoint(&checkpoint, &model).unwrap();
    sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let opened = sinmdm::Model::open(&model, &sinmdm::ModelOptions::default()).unwrap();
    let source = opened
        .metadata()
        .training
        .clip_source
        .clone()
        .expect("recorded in the model");
    assert_eq!(
        (
            source.format.as_str(),
            source.animation.as_deref(),
            source.animations
        ),
        ("gltf", Some("Take 1"), 1)
    );
    // A BVH clip has one animation to learn.
    let mut wrong = tiny();
    wrong.data.animation = Some("Walk".into());
    let err = ClipData::load(
        &root().join("tests/data/bvh/fox_survey_khronos.bvh"),
        &wrong.data,
        &wrong.model,
    )
    .unwrap_err();
    assert!(err.to_string().contains("data.animation"), "{err}");
    std::fs::remove_dir_all(&run).unwrap();
}
