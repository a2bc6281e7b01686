//! The exported ONNX graph computes what the burn network computes, in real onnxruntime.

use sinmdm::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

use burn::tensor::{Device, Tensor, TensorData};
use ort::session::Session;
use ort::value::Tensor as OrtTensor;
use sinmdm_train::export::{export_model, weights_of};
use sinmdm_train::model::QnaUnet;
use sinmdm_train::model::weights::perturb;
use sinmdm_train::{TrainConfig, Trainer};

mod common;
use common::root;

static RNG: Mutex<()> = Mutex::new(());

fn scratch(name: &str) -> PathBuf {
    common::scratch("export", name)
}

fn input(b: usize, f: usize, n: usize) -> (Vec<f32>, Vec<i64>) {
    let x = (0..b * f * n)
        .map(|i| (i as f32 * 0.618).sin() * 1.3 + (i % 11) as f32 * 0.05)
        .collect();
    let t = (0..b).map(|i| (i as i64 * 397 + 11) % 1000).collect();
    (x, t)
}

fn burn_forward(model: &QnaUnet, x: &[f32], t: &[i64], b: usize, f: usize, n: usize) -> Vec<f32> {
    let device = Device::flex();
    let x = Tensor::<3>::from_data(TensorData::new(x.to_vec(), [b, f, n]), &device);
    let t: Vec<f32> = t.iter().map(|&v| v as f32).collect();
    let t = Tensor::<1>::from_data(TensorData::new(t, [b]), &device);
    model.forward(x, t).into_data().try_to_vec::<f32>().unwrap()
}

fn ort_forward(
    session: &mut Session,
    x: &[f32],
    t: &[i64],
    b: usize,
    f: usize,
    n: usize,
) -> Vec<f32> {
    let xs = OrtTensor::from_array(([b, f, n], x.to_vec().into_boxed_slice())).unwrap();
    let ts = OrtTensor::from_array(([b], t.to_vec().into_boxed_slice())).unwrap();
    let outputs = session
        .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
        .unwrap();
    let (shape, data) = outputs[OUTPUT_FEATURES]
        .try_extract_tensor::<f32>()
        .unwrap();
    assert_eq!(shape.to_vec(), vec![b as i64, f as i64, n as i64]);
    data.to_vec()
}

/// A tiny trained run whose weights (zero-initialised ones too) are then perturbed, so every
/// path of the graph carries signal.
fn perturbed_run() -> (
    QnaUnet,
    sinmdm_train::run::checkpoint::CheckpointState,
    PathBuf,
) {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let mut config: TrainConfig = TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap();
    config.training.steps = 3;
    let run = scratch("run");
    let clip = root().join("tests/data/bvh/fox_survey_khronos.bvh");
    let mut trainer = Trainer::start(&clip, config, &run, Device::flex().autodiff()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    let state = trainer.state().clone();
    let device = Device::flex();
    device.seed(5);
    let model = perturb(trainer.inference_model(), 0.05);
    (model, state, run)
}

#[test]
fn onnxruntime_matches_burn_for_any_batch_and_length() {
    let (model, state, run) = perturbed_run();
    let file = run.join("model.onnx");
    export_model(&model, &state, &file).unwrap();
    let rt = sinmdm::init_onnxruntime().expect("run scripts/setup.sh first");
    let mut session = Session::builder(rt.environment())
        .unwrap()
        .commit_from_file(&file)
        .unwrap();
    let f = state.features;
    for b in [1, 3] {
        for n in [23, 24, 157, 600] {
            let (x, t) = input(b, f, n);
            let expected = burn_forward(&model, &x, &t, b, f, n);
            let got = ort_forward(&mut session, &x, &t, b, f, n);
            let scale = expected.iter().fold(0f32, |m, v| m.max(v.abs()));
            let worst = expected
                .iter()
                .zip(&got)
                .map(|(e, g)| (e - g).abs())
                .fold(0f32, f32::max);
            assert!(scale > 1e-2, "outputs are trivially small ({scale})");
            assert!(
                worst <= 1e-4,
                "B {b}, N {n}: max |diff| {worst} (outputs up to {scale})"
            );
        }
    }
    // Every operator is on the allow-list kept in the repository, and the file declares
    // IR <= 10 and opset 17.
    let allowed: Vec<&str> = sinmdm_export::ALLOWED_OPS.lines().collect();
    let bytes = std::fs::read(&file).unwrap();
    let parsed =
        <onnx_protobuf::ModelProto as onnx_protobuf::Message>::parse_from_bytes(&bytes).unwrap();
    assert!(parsed.ir_version <= 10);
    assert_eq!(parsed.opset_import[0].version, 17);
    for node in &parsed.graph.node {
        assert!(
            allowed.contains(&node.op_type.as_str()),
            "{} is not allowed",
            node.op_type
        );
    }
    assert!(weights_of(&model).contains_key("attention1.rpe"));
    std::fs::remove_dir_all(&run).unwrap();
}

/// A one-step run of configs/tiny.yaml with `channels`; returns its newest checkpoint folder.
fn one_step_run(name: &str, channels: usize) -> PathBuf {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let mut config: TrainConfig = TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap();
    config.training.steps = 1;
    config.model.channels = channels;
    let run = scratch(name);
    let clip = root().join("tests/data/bvh/fox_survey_khronos.bvh");
    let mut trainer = Trainer::start(&clip, config, &run, Device::flex().autodiff()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    sinmdm_train::run::checkpoint::resolve(&run).unwrap()
}

#[test]
fn a_checkpoint_with_weights_of_another_shape_is_refused() {
    let small = one_step_run("small", 32);
    let large = one_step_run("large", 64);
    std::fs::copy(large.join("model.bpk"), small.join("model.bpk")).unwrap();
    let out = small.join("model.onnx");
    let e = sinmdm_train::export::export_checkpoint(&small, &out).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("the weights do not fit this model"),
        "{message}"
    );
    assert!(message.contains("model.bpk"), "{message}");
    assert!(!out.exists(), "a file was written");
    let e = sinmdm_train::export::export_checkpoint(&root().join("configs"), &out).unwrap_err();
    assert!(e.to_string().contains("configs"), "{e}");
    for run in [small, large] {
        std::fs::remove_dir_all(run.parent().unwrap().parent().unwrap()).unwrap();
    }
}
