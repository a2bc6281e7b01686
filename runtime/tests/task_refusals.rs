//! Requests, clips and model files the tasks refuse, through real onnxruntime on the small
//! trained model (tests/data/models/walk_tiny.onnx): each error names what is wrong.

use sinmdm::bvh::read_bvh;
use sinmdm::motion::encode_for;
use sinmdm::tasks::{self, Request, Span, Task, TaskError};
use sinmdm::{Method, Model, ModelError, ModelOptions};

mod common;

use common::{tiny_model as model, walk_features as walk, workspace as root};

fn plan_error(task: Task, count: usize, steps: Option<usize>) -> TaskError {
    let m = model();
    tasks::plan(
        m.metadata(),
        &Request {
            task,
            count,
            seed: 0,
            steps,
            feet: sinmdm::Feet::default(),
            method: Default::default(),
        },
    )
    .unwrap_err()
}

#[test]
fn bad_requests_are_refused_with_what_is_wrong() {
    let m = model();
    let reference = walk(&m, 100);
    let message = |e: TaskError| e.to_string();
    let e = plan_error(
        Task::Inbetween {
            reference: reference.clone(),
            keep: vec![Span::new(0, 40), Span::new(90, 140)],
            ramp: 10,
        },
        1,
        Some(10),
    );
    assert!(message(e).contains("span 90:140 reaches past the reference's 100 frames"));
    let e = plan_error(
        Task::Inbetween {
            reference: reference.clone(),
            keep: vec![Span::new(0, 40), Span::new(30, 60)],
            ramp: 10,
        },
        1,
        Some(10),
    );
    assert!(message(e).contains("spans 0:40 and 30:60 overlap"));
    let e = plan_error(
        Task::Inbetween {
            reference: reference.clone(),
            keep: vec![Span::new(40, 40)],
            ramp: 10,
        },
        1,
        Some(10),
    );
    assert!(message(e).contains("span 40:40 is empty"));
    let e = plan_error(Task::Generate { frames: 0 }, 1, Some(10));
    assert!(message(e).contains("0 frames"));
    let e = plan_error(Task::Generate { frames: 10_000_000 }, 1, Some(10));
    assert!(message(e).contains("the limit is"));
    let e = plan_error(Task::Generate { frames: 50 }, 0, Some(10));
    assert!(message(e).contains("the number of samples must be between 1 and 1024, got 0"));
    let e = plan_error(Task::Generate { frames: 50 }, 1, Some(5000));
    assert!(e.to_string().contains("5000"), "{e}");
    let e = tasks::joints_by_name(&m.metadata().layout, &["Tail".to_string()]).unwrap_err();
    assert!(message(e).contains("joint 'Tail' is not in the model's skeleton (joints: Hips"));
    let e = plan_error(
        Task::Compose {
            reference: reference.clone(),
            joints: vec![1, 999],
            root: false,
            spans: vec![],
            ramp: 10,
        },
        1,
        Some(10),
    );
    assert!(
        matches!(e, TaskError::JointIndex { index: 999, .. }),
        "{e:?}"
    );
}

#[test]
fn sizes_at_the_edge_of_usize_and_wide_ramps_are_refused() {
    let m = model();
    let reference = walk(&m, 100);
    let message = |e: TaskError| e.to_string();
    // Sizes at the edge of usize are refused, never wrapped round or panicked on.
    for (prefix, suffix) in [
        (usize::MAX, 0),
        (usize::MAX - 29, 0),
        (0, usize::MAX),
        (1, usize::MAX - 100),
    ] {
        let e = plan_error(
            Task::Expand {
                reference: reference.clone(),
                prefix,
                suffix,
                ramp: 6,
            },
            1,
            Some(10),
        );
        assert!(
            matches!(e, TaskError::Length { .. }),
            "{prefix} {suffix}: {e:?}"
        );
        assert!(message(e).contains("the limit is"));
    }
    for task in [
        Task::Expand {
            reference: reference.clone(),
            prefix: 10,
            suffix: 0,
            ramp: usize::MAX,
        },
        Task::Inbetween {
            reference: reference.clone(),
            keep: vec![Span::new(0, 40)],
            ramp: usize::MAX,
        },
        Task::Compose {
            reference: reference.clone(),
            joints: vec![1],
            root: false,
            spans: vec![],
            ramp: sinmdm::limits::MAX_RAMP_FRAMES + 1,
        },
    ] {
        let e = plan_error(task, 1, Some(10));
        assert!(matches!(e, TaskError::Ramp(_)), "{e:?}");
        assert!(message(e).contains("soft border"));
    }
}

#[test]
fn the_run_size_bound_is_count_frames_and_the_values_per_frame() {
    let m = model();
    let values = tasks::run_values_per_frame(m.metadata());
    let network = &m.metadata().network;
    let joints = m.skeleton().len();
    assert_eq!(
        values,
        (network.features + 8 * network.channels).max(12 * joints)
    );
    let count = tasks::MAX_SAMPLES;
    let longest = tasks::MAX_RUN_VALUES / (count * values);
    let request = |frames: usize| Request {
        task: Task::Generate { frames },
        count,
        seed: 0,
        steps: Some(2),
        feet: sinmdm::Feet::default(),
        method: Default::default(),
    };
    assert!(tasks::plan(m.metadata(), &request(longest)).is_ok());
    let e = tasks::plan(m.metadata(), &request(longest + 1)).unwrap_err();
    assert!(matches!(e, TaskError::TooLarge { .. }), "{e:?}");
}

#[test]
fn asking_a_batch_for_a_sample_it_lacks_is_an_error() {
    let mut m = model();
    let request = Request {
        task: Task::Generate { frames: 20 },
        count: 2,
        seed: 3,
        steps: Some(3),
        feet: sinmdm::Feet::default(),
        method: Method::Ancestral,
    };
    let out = tasks::run(&mut m, &request, &mut |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    assert!(out.poses(1).is_ok());
    let e = out.poses(2).unwrap_err();
    assert_eq!(e.to_string(), "there is no sample 2 in a batch of 2");
}

#[test]
fn a_clip_of_another_skeleton_is_refused() {
    let m = model();
    let fox = read_bvh(root().join("tests/data/bvh/fox_survey_khronos.bvh")).unwrap();
    let e = encode_for(&fox, &m.metadata().layout).unwrap_err();
    assert!(
        e.to_string()
            .contains("the clip's skeleton differs from the model's"),
        "{e}"
    );
}

#[test]
fn model_files_that_are_not_models_are_refused() {
    let dir = std::env::temp_dir().join(format!("sinmdm-model-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let options = ModelOptions { threads: Some(1) };
    let e = Model::open(dir.join("missing.onnx"), &options).unwrap_err();
    assert!(matches!(e, ModelError::Missing(_)), "{e}");
    assert!(e.to_string().contains("missing.onnx' does not exist"));

    let text = dir.join("notes.onnx");
    std::fs::write(&text, "this is not a model").unwrap();
    let e = Model::open(&text, &options).unwrap_err();
    assert!(matches!(e, ModelError::NotOnnx { .. }), "{e}");

    let bytes = std::fs::read(root().join("tests/data/models/walk_tiny.onnx")).unwrap();
    let truncated = dir.join("truncated.onnx");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let e = Model::open(&truncated, &options).unwrap_err();
    assert!(matches!(e, ModelError::NotOnnx { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("truncated.onnx' is not a loadable ONNX model")
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn metadata_problems_are_named() {
    let m = model();
    let good = serde_json::to_string(m.metadata()).unwrap();
    let path = std::path::Path::new("x.onnx");
    let lookup = |schema: Option<&'static str>, json: Option<String>| {
        move |key: &str| match key {
            "sinmdm.schema" => schema.map(str::to_string),
            "sinmdm.metadata" => json.clone(),
            _ => None,
        }
    };
    let e = sinmdm::model_file::parse_metadata(path, lookup(None, Some(good.clone()))).unwrap_err();
    assert!(e.to_string().contains("has no sinmdm metadata"), "{e}");
    let e = sinmdm::model_file::parse_metadata(path, lookup(Some("3"), Some(good.clone())))
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("schema '3'; this runtime reads schemas 1 and 2"),
        "{e}"
    );
    // A world-root model reads under schema 2 as well; a heading root under schema 1 does not.
    assert!(
        sinmdm::model_file::parse_metadata(path, lookup(Some("2"), Some(good.clone()))).is_ok()
    );
    let mut heading: serde_json::Value = serde_json::from_str(&good).unwrap();
    heading["layout"]["root"]["heading"] = serde_json::json!({
        "left": 1, "right": 2, "sides": "names", "smoothing": 0.2, "start": 0.5
    });
    let e = sinmdm::model_file::parse_metadata(path, lookup(Some("1"), Some(heading.to_string())))
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("layout.root.heading needs schema 2, the file says 1"),
        "{e}"
    );
    let mut value: serde_json::Value = serde_json::from_str(&good).unwrap();
    value.as_object_mut().unwrap().remove("normalizer");
    let e = sinmdm::model_file::parse_metadata(path, lookup(Some("1"), Some(value.to_string())))
        .unwrap_err();
    assert!(e.to_string().contains("missing field `normalizer`"), "{e}");
    assert!(sinmdm::model_file::parse_metadata(path, lookup(Some("1"), Some(good))).is_ok());
}
