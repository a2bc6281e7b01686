//! The rules a model file's metadata must follow, one hand-broken copy of the small walk
//! model's metadata per rule: each is refused with a message that names the field and value.
//! And every shipped model follows them all.

mod common;

use std::path::PathBuf;

use sinmdm::model_file::{ModelMetadata, problems};
use sinmdm::motion::{Axis, Channel};
use sinmdm::{Model, ModelOptions};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn walk() -> ModelMetadata {
    common::tiny_model().metadata().clone()
}

/// The problems of the walk's metadata after `breaking` it; asserts one of them contains every
/// piece of `expected`.
fn refused(breaking: impl FnOnce(&mut ModelMetadata), expected: &[&str]) {
    let mut m = walk();
    breaking(&mut m);
    let found = problems(&m);
    assert!(
        found
            .iter()
            .any(|p| expected.iter().all(|piece| p.contains(piece))),
        "expected a problem with {expected:?}, got {found:?}"
    );
}

#[test]
fn every_shipped_model_follows_every_rule() {
    let mut models: Vec<PathBuf> = std::fs::read_dir(root().join("onnx-models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "onnx"))
        .collect();
    models.push(root().join("tests/data/models/walk_tiny.onnx"));
    assert!(models.len() >= 4, "{models:?}");
    for path in models {
        let model = Model::open(&path, &ModelOptions { threads: Some(1) }).unwrap();
        assert_eq!(
            problems(model.metadata()),
            Vec::<String>::new(),
            "{}",
            path.display()
        );
    }
}

#[test]
fn the_skeleton_is_a_tree_with_one_root_and_sound_joints() {
    refused(
        |m| m.layout.skeleton.joints.clear(),
        &["layout.skeleton.joints", "0 joints"],
    );
    refused(
        |m| m.layout.skeleton.joints[3].parent = Some(3),
        &[
            "layout.skeleton.joints[3].parent",
            "is 3",
            "before its child",
        ],
    );
    refused(
        |m| m.layout.skeleton.joints[2].parent = Some(500),
        &["layout.skeleton.joints[2].parent", "500"],
    );
    refused(
        |m| m.layout.skeleton.joints[4].parent = None,
        &[
            "layout.skeleton.joints[4].parent",
            "only the first joint is a root",
        ],
    );
    refused(
        |m| m.layout.skeleton.joints[0].parent = Some(1),
        &[
            "layout.skeleton.joints[0].parent",
            "the first joint is the root",
        ],
    );
    refused(
        |m| {
            let name = m.layout.skeleton.joints[1].name.clone();
            m.layout.skeleton.joints[5].name = name;
        },
        &["layout.skeleton.joints[5].name", "used twice"],
    );
    refused(
        |m| m.layout.skeleton.joints[2].name = " ".into(),
        &["layout.skeleton.joints[2].name"],
    );
    refused(
        |m| m.layout.skeleton.joints[1].offset[2] = f64::NAN,
        &["layout.skeleton.joints[1].offset", "NaN"],
    );
    // One or two rotation axes are a hinge and fine; the same axis twice is not.
    refused(
        |m| {
            let channels = &mut m.layout.skeleton.joints[1].channels;
            channels[1] = channels[0];
        },
        &["layout.skeleton.joints[1].channels", "rotations"],
    );
    refused(
        |m| {
            m.layout.skeleton.joints[0]
                .channels
                .push(Channel::Position(Axis::X))
        },
        &[
            "layout.skeleton.joints[0].channels",
            "repeats a position axis",
        ],
    );
}

#[test]
fn layout_indices_point_inside_the_skeleton_and_agree_with_its_channels() {
    refused(
        |m| m.layout.root.as_mut().unwrap().joint = 99,
        &["layout.root.joint", "99"],
    );
    refused(
        |m| m.layout.root.as_mut().unwrap().axes = vec![Axis::X, Axis::X],
        &["layout.root.axes"],
    );
    refused(
        |m| m.layout.root.as_mut().unwrap().frame[0][0] = 2.0,
        &["layout.root.frame", "rotation"],
    );
    refused(
        |m| m.layout.rotation_joints[0] = 1000,
        &["layout.rotation_joints[0]", "1000"],
    );
    refused(
        |m| {
            let j = m.layout.rotation_joints[1];
            m.layout.rotation_joints[2] = j;
        },
        &["layout.rotation_joints[2]", "listed twice"],
    );
    refused(
        |m| m.layout.contact_joints[0] = 77,
        &["layout.contact_joints[0]", "77"],
    );
    refused(
        |m| m.layout.position_channels.push((3, Axis::Y)),
        &["layout.position_channels", "no such channel"],
    );
    refused(
        |m| {
            m.layout.rest_translations.pop();
        },
        &["layout.rest_translations", "entries for"],
    );
    refused(|m| m.layout.fps = 0.0, &["layout.fps", "is 0"]);
    refused(|m| m.layout.fps = f64::INFINITY, &["layout.fps", "inf"]);
    refused(
        |m| m.layout.skeleton_height = -1.0,
        &["layout.skeleton_height", "-1"],
    );
    refused(
        |m| m.layout.contact_speed_threshold = f64::NAN,
        &["layout.contact_speed_threshold", "NaN"],
    );
}

#[test]
fn sizes_are_bounded_and_agree_with_each_other() {
    refused(
        |m| m.network.features += 1,
        &["network.features", "columns"],
    );
    refused(
        |m| m.network.features = usize::MAX,
        &["network.features", &usize::MAX.to_string()],
    );
    refused(|m| m.network.channels = 33, &["network", "channels (33)"]);
    refused(|m| m.network.window = 4, &["network", "window (4)"]);
    refused(
        |m| m.network.channels = 1 << 20,
        &["network.channels", "1048576"],
    );
    refused(
        |m| m.diffusion.steps = 8_000_000_000_000,
        &["diffusion.steps", "8000000000000"],
    );
    refused(|m| m.diffusion.steps = 1, &["diffusion.steps", "is 1"]);
    refused(
        |m| m.diffusion.schedule = "linear".into(),
        &["diffusion.schedule", "linear"],
    );
    refused(
        |m| m.training.clip_frames = usize::MAX / 2,
        &["training.clip_frames"],
    );
    refused(
        |m| {
            m.normalizer.mean.pop();
        },
        &["normalizer", "means"],
    );
    refused(|m| m.normalizer.std[4] = 0.0, &["normalizer.std[4]", "0"]);
    refused(
        |m| m.normalizer.mean[7] = f32::NAN,
        &["normalizer.mean[7]", "NaN"],
    );
}

/// A model path that is a folder, a FIFO or a file over [`sinmdm::limits::MAX_MODEL_BYTES`] is refused
/// before a byte is read, and the message says why once.
#[test]
fn a_model_path_that_is_no_regular_file_or_too_large_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("sinmdm-model-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let refused = |path: &std::path::Path, reason: &str| {
        let e = Model::open(path, &ModelOptions { threads: Some(1) }).unwrap_err();
        let message = e.to_string();
        assert!(
            message.contains(&path.display().to_string()) && message.matches(reason).count() == 1,
            "{message}"
        );
        assert!(std::error::Error::source(&e).is_none(), "{message}");
    };
    let folder = dir.join("walk.onnx");
    std::fs::create_dir_all(&folder).unwrap();
    refused(&folder, "is a directory, not a regular file");
    // A sparse file: its size is what is checked, and nothing of it is read.
    let huge = dir.join("huge.onnx");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(sinmdm::limits::MAX_MODEL_BYTES + 1)
        .unwrap();
    refused(&huge, "MAX_MODEL_BYTES");
    #[cfg(unix)]
    {
        let fifo = dir.join("pipe.onnx");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        refused(&fifo, "a device, FIFO or socket, not a regular file");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
