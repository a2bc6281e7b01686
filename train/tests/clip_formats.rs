//! Training from a glTF or FBX clip: the same training features as from the BVH it was made
//! from, and a run that keeps its glTF clip, resumes from it and records it in the model file.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use burn::tensor::Device;
use sinmdm::bvh::read_bvh;
use sinmdm::motion::{ColumnKind, UpAxis};
use sinmdm_formats::gltf::{GltfWriteOptions, write_gltf};
use sinmdm_train::clip::ClipData;
use sinmdm_train::{TrainConfig, Trainer};

mod common;
use common::root;

fn tiny() -> TrainConfig {
    TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap()
}

/// `clip` written as glTF (`extension`) in metres at `metres` per unit, beside the scratch files
/// under `name` (tests running beside each other use names of their own).
fn as_gltf(clip: &str, metres: f64, extension: &str, name: &str) -> PathBuf {
    let motion = read_bvh(root().join("tests/data/bvh").join(clip))
        .unwrap()
        .to_local();
    let path = common::scratch("formats", name).with_extension(extension);
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: metres,
        proxy_mesh: false,
    };
    write_gltf(&path, &[("Take 1".into(), &motion)], &options).unwrap();
    path
}

/// Asserts that `clip` gives the training features of `bvh`, read in units of `metres` per BVH
/// unit: before normalisation, 6D rotations within `rotation_tolerance`, lengths (root travel and height,
/// position channels) within 1e-5 of the skeleton's height once in the same unit, contact
/// labels equal. (Normalised, a root that stands still turns f32's rounding of its position,
/// under 1e-7 m, into unit-variance noise.)
fn assert_same_features(
    clip: &ClipData,
    bvh: &ClipData,
    (metres, rotation_tolerance): (f64, f64),
    what: &str,
) {
    assert_eq!(clip.features.dim(), bvh.features.dim(), "{what}");
    let raw_clip = clip.facts.normalizer.denormalize(clip.features.view());
    let raw_bvh = bvh.facts.normalizer.denormalize(bvh.features.view());
    let height = bvh.facts.layout.skeleton_height * metres;
    for (r, column) in bvh.facts.layout.columns().iter().enumerate() {
        let (scale, allowed) = match column.kind {
            ColumnKind::Rotation6d(_) => (1.0, rotation_tolerance),
            ColumnKind::Contact => (1.0, 0.0),
            _ => (metres, 1e-5 * height),
        };
        let worst = raw_clip
            .row(r)
            .iter()
            .zip(raw_bvh.row(r).iter())
            .map(|(a, b)| (f64::from(*a) - f64::from(*b) * scale).abs())
            .fold(0f64, f64::max);
        assert!(
            worst <= allowed,
            "{what}, row {r} ({:?}): max |diff| {worst} > {allowed}",
            column.kind
        );
    }
}

#[test]
fn a_gltf_clip_gives_the_training_features_of_its_bvh() {
    let config = tiny();
    for (clip, metres) in [
        ("human_walk_cmu_131_01.bvh", 0.0564),
        ("fox_survey_khronos.bvh", 0.01),
    ] {
        let bvh = ClipData::load(&root().join("tests/data/bvh").join(clip), &config.data).unwrap();
        for extension in ["glb", "gltf"] {
            let file = as_gltf(clip, metres, extension, clip);
            let gltf = ClipData::load(&file, &config.data).unwrap();
            assert_same_features(
                &gltf,
                &bvh,
                (metres, 1e-5),
                &format!("{clip} as {extension}"),
            );
            let source = gltf.facts.source.as_ref().expect("the source is recorded");
            assert_eq!(source.format, "gltf");
            assert_eq!(source.animation.as_deref(), Some("Take 1"));
            assert!(bvh.facts.source.is_none());
            std::fs::remove_file(file).unwrap();
        }
    }
}

/// `tests/data/fbx/NAME.gz` unpacked beside the scratch files.
fn fbx_fixture(name: &str) -> PathBuf {
    use std::io::Read;
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(
        std::fs::File::open(root().join("tests/data/fbx").join(format!("{name}.gz"))).unwrap(),
    )
    .read_to_end(&mut bytes)
    .unwrap();
    let path = common::scratch("formats", name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn blenders_glb_and_fbx_give_the_training_features_of_their_bvh() {
    let config = tiny();
    let fixtures = root().join("tests/data/gltf");
    for clip in ["human_walk_cmu_131_01", "fox_survey_khronos"] {
        // The GLB holds the cut BVH's 2 s; the FBX its first second.
        let bvh_clip = read_bvh(fixtures.join(format!("{clip}_2s.bvh"))).unwrap();
        let glb = fixtures.join(format!("{clip}_skinned.glb"));
        let fbx = fbx_fixture(&format!("{clip}_skinned.fbx"));
        // Blender's glTF exporter composes bone matrices in single precision: its keys of the
        // walk's deepest joints are off by up to 1.1e-5 (its FBX, in double, by 5e-6).
        for (file, seconds, rotation_tolerance) in [(glb, 2.0, 2e-5), (fbx.clone(), 1.0, 1e-5)] {
            let frames = (seconds * bvh_clip.fps).round() as usize + 1;
            let channels = bvh_clip.skeleton.channel_count();
            let cut = sinmdm::motion::ChannelClip {
                values: bvh_clip.values[..frames * channels].to_vec(),
                ..bvh_clip.clone()
            };
            let bvh_file = common::scratch("formats", clip).with_extension("bvh");
            std::fs::write(&bvh_file, sinmdm::bvh::to_bvh_string(&cut)).unwrap();
            let bvh = ClipData::load(&bvh_file, &config.data).unwrap();
            let read = ClipData::load(&file, &config.data).unwrap();
            // Blender reads BVH units as metres, so the files are in the BVH's units.
            assert_same_features(
                &read,
                &bvh,
                (1.0, rotation_tolerance),
                &file.display().to_string(),
            );
            std::fs::remove_file(bvh_file).unwrap();
        }
        let source = ClipData::load(&fbx, &config.data)
            .unwrap()
            .facts
            .source
            .expect("recorded");
        assert_eq!(source.format, "fbx");
        assert_eq!(source.animations, 1);
        assert!(source.file_unit_meters.is_some_and(|m| m > 0.0));
        std::fs::remove_file(fbx).unwrap();
    }
}

#[test]
fn a_run_keeps_its_gltf_clip_resumes_from_it_and_records_it() {
    let file = as_gltf("fox_survey_khronos.bvh", 0.01, "glb", "run_clip");
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
            source.animations,
            source.file_unit_meters
        ),
        ("gltf", Some("Take 1"), 1, Some(1.0))
    );
    // A BVH clip has one animation to learn.
    let mut wrong = tiny();
    wrong.data.animation = Some("Walk".into());
    let err = ClipData::load(
        &root().join("tests/data/bvh/fox_survey_khronos.bvh"),
        &wrong.data,
    )
    .unwrap_err();
    assert!(err.to_string().contains("data.animation"), "{err}");
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn a_run_keeps_its_fbx_clip_and_resumes_from_it() {
    let file = fbx_fixture("fox_survey_khronos_armature.fbx");
    let mut config = tiny();
    config.training.steps = 3;
    config.training.checkpoint_every = 2;
    let run = common::scratch("formats", "fbx_run");
    let device = || Device::flex().autodiff();
    let mut first = Trainer::start(&file, config, &run, device()).unwrap();
    first.step().unwrap();
    first.step().unwrap();
    first.save().unwrap();
    drop(first);
    assert!(run.join("clip.fbx").is_file());
    std::fs::remove_file(&file).unwrap();
    let mut second = Trainer::resume(&run, None, None, device()).unwrap();
    let end = second.run(&AtomicBool::new(false), |_| {}).unwrap();
    assert!(matches!(end, sinmdm_train::RunEnd::Finished(_)), "{end:?}");
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn a_clip_with_a_one_axis_hinge_trains_exports_and_opens() {
    // The walk with its left knee a hinge: one rotation channel (the knee's own bend, X), as
    // some rigs write their knees and elbows. The reader takes it, so the whole path must.
    let mut clip = read_bvh(root().join("tests/data/bvh/human_walk_cmu_131_01.bvh")).unwrap();
    let knee = clip
        .skeleton
        .joints
        .iter()
        .position(|j| j.name == "LeftKnee")
        .unwrap();
    let width = clip.skeleton.channel_count();
    let first: usize = clip.skeleton.joints[..knee]
        .iter()
        .map(|j| j.channels.len())
        .sum();
    let channels = clip.skeleton.joints[knee].channels.clone();
    let keep = channels
        .iter()
        .position(|c| *c == sinmdm::motion::Channel::parse("Xrotation").unwrap())
        .unwrap();
    let values: Vec<f64> = clip
        .values
        .chunks(width)
        .flat_map(|row| {
            let mut row = row.to_vec();
            let kept = row[first + keep];
            row.splice(first..first + channels.len(), [kept]);
            row
        })
        .collect();
    clip.skeleton.joints[knee].channels = vec![channels[keep]];
    clip.values = values;
    let file = common::scratch("formats", "hinge.bvh");
    std::fs::write(&file, sinmdm::bvh::to_bvh_string(&clip)).unwrap();

    let mut config = tiny();
    config.training.steps = 2;
    config.training.checkpoint_every = 2;
    let run = common::scratch("formats", "hinge_run");
    let mut trainer = Trainer::start(&file, config, &run, Device::flex().autodiff()).unwrap();
    let end = trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    let sinmdm_train::RunEnd::Finished(checkpoint) = end else {
        panic!("{end:?}");
    };
    let model_file = run.join("hinge.onnx");
    sinmdm_train::export::export_checkpoint(&checkpoint, &model_file).unwrap();
    sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let mut model = sinmdm::Model::open(&model_file, &sinmdm::ModelOptions::default()).unwrap();
    let request = sinmdm::Request {
        task: sinmdm::Task::Generate { frames: 40 },
        count: 1,
        seed: 1,
        steps: Some(3),
        feet: sinmdm::Feet::Planted,
        method: Default::default(),
    };
    let generated = sinmdm::run(&mut model, &request, &mut |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    let motion = generated.motion(0).unwrap();
    assert_eq!(motion.skeleton.joints[knee].channels.len(), 1);
    std::fs::remove_dir_all(&run).unwrap();
    std::fs::remove_file(&file).unwrap();
}

/// A `.gltf` clip whose buffer lies in the folder above is read only when the run allows it
/// (`data.allow_outside_folder`, what `sinmdm-train --allow-outside-folder` sets), and then
/// gives the features of the same clip as a GLB.
#[test]
fn a_gltf_clip_reads_a_buffer_outside_its_folder_only_when_allowed() {
    let mut config = tiny();
    let glb = as_gltf("fox_survey_khronos.bvh", 0.01, "glb", "outside_folder");
    let bytes = std::fs::read(&glb).unwrap();
    // The GLB's two chunks: its JSON, then its binary buffer.
    let chunk = |at: usize| {
        let length = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        (&bytes[at + 8..at + 8 + length], at + 8 + length)
    };
    let (json, next) = chunk(12);
    let (bin, _) = chunk(next);
    let mut json: serde_json::Value = serde_json::from_slice(json).unwrap();
    json["buffers"][0] =
        serde_json::json!({ "uri": "../buffers/clip.bin", "byteLength": bin.len() });
    let top = glb.with_extension("split");
    std::fs::create_dir_all(top.join("buffers")).unwrap();
    std::fs::create_dir_all(top.join("clips")).unwrap();
    std::fs::write(top.join("buffers/clip.bin"), bin).unwrap();
    let gltf = top.join("clips/clip.gltf");
    std::fs::write(&gltf, serde_json::to_vec(&json).unwrap()).unwrap();

    let refused = match ClipData::load(&gltf, &config.data) {
        Ok(_) => panic!("the buffer outside the clip's folder was read"),
        Err(e) => e.to_string(),
    };
    assert!(
        refused.contains("'../buffers/clip.bin'") && refused.contains("--allow-outside-folder"),
        "{refused}"
    );
    config.data.allow_outside_folder = true;
    let split = ClipData::load(&gltf, &config.data).unwrap();
    let whole = ClipData::load(&glb, &config.data).unwrap();
    assert_eq!(split.features, whole.features);
    std::fs::remove_dir_all(&top).unwrap();
    std::fs::remove_file(&glb).unwrap();
}

/// A model trained from a Mixamo-style FBX (`mixamorig:` names, centimetres) puts its samples
/// onto another character with the same names and other proportions, rest pose and bone rolls
/// in one call, retargeted (how well is `formats/tests/retarget.rs`'s to check).
#[test]
fn a_model_trained_from_a_mixamo_fbx_goes_onto_another_mixamo_character() {
    use sinmdm_formats::gltf::container::{glb_bytes, parse_glb};
    let fbx = root().join("tests/data/fbx/human_walk_cmu_131_01_mixamo_style.fbx");
    let mut config = tiny();
    config.training.steps = 2;
    config.training.checkpoint_every = 2;
    let run = common::scratch("formats", "mixamo_run");
    let mut trainer = Trainer::start(&fbx, config, &run, Device::flex().autodiff()).unwrap();
    let end = trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    let sinmdm_train::RunEnd::Finished(checkpoint) = end else {
        panic!("{end:?}");
    };
    let model_file = run.join("mixamo.onnx");
    sinmdm_train::export::export_checkpoint(&checkpoint, &model_file).unwrap();
    sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let mut model = sinmdm::Model::open(&model_file, &sinmdm::ModelOptions::default()).unwrap();
    let request = sinmdm::Request {
        task: sinmdm::Task::Generate { frames: 40 },
        count: 2,
        seed: 1,
        steps: Some(3),
        feet: sinmdm::Feet::Planted,
        method: Default::default(),
    };
    let generated = sinmdm::run(&mut model, &request, &mut |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    let motions = [generated.motion(0).unwrap(), generated.motion(1).unwrap()];

    // Another Mixamo character: Blender's reshaped walk rig under `mixamorig:` names.
    let rig = root().join("tests/data/gltf/human_walk_rig_other_proportions.glb");
    let asset = parse_glb(&rig, &std::fs::read(&rig).unwrap()).unwrap();
    let mut json = asset.json;
    for node in json["nodes"].as_array_mut().unwrap() {
        if let Some(name) = node["name"].as_str().filter(|n| !n.contains("Cube")) {
            node["name"] = serde_json::Value::String(format!("mixamorig:{name}"));
        }
    }
    let character = run.join("character.glb");
    std::fs::write(&character, glb_bytes(&json, &asset.buffers[0])).unwrap();
    let out = run.join("character_walks.glb");
    let named = [
        ("sample_000".to_string(), &motions[0]),
        ("sample_001".to_string(), &motions[1]),
    ];
    let report = sinmdm_formats::gltf::splice_into_character(
        &character,
        &out,
        &named,
        generated.layout().up,
    )
    .unwrap();
    let retargeted = report.retargeted.expect("another rig is retargeted");
    assert!(
        retargeted.reason.contains("another rig"),
        "{}",
        retargeted.reason
    );
    assert_eq!(retargeted.map.pairs.len(), motions[0].skeleton.len());
    assert!(retargeted.dropped_joints.is_empty());
    let options = sinmdm_formats::ReadOptions {
        animation: Some(sinmdm_formats::AnimationChoice::Name("sample_001".into())),
        fps: None,
    };
    let played = sinmdm_formats::gltf::read_gltf(&out, &options).unwrap();
    assert_eq!(played.clip.frame_count(), 40);
    std::fs::remove_dir_all(&run).unwrap();
}
