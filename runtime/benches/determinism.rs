//! What the same bits on every machine cost: the runtime's way (each sample its own
//! onnxruntime call on one intra-op thread, the batch spread over the model's threads) against
//! the old way (the whole batch in one call, onnxruntime's intra-op pool over `THREADS`
//! threads), side by side in one process, alternating rounds; medians and ratios. It also
//! prints how far the old way's values stray between thread counts, which is what the change
//! removes.
//!
//! `cargo bench -p sinmdm --bench determinism -- [MODEL.onnx] [FRAMES] [THREADS]` (default: the
//! shipped walk, 498 frames, 2 threads).

mod common;

use std::ops::ControlFlow;
use std::time::Instant;

use common::{median, open_session};
use ndarray::{Array3, ArrayView3};
use ort::session::Session;
use ort::value::Tensor;
use sinmdm::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};
use sinmdm::{Denoiser, Feet, Model, ModelError, ModelOptions, Request, Task};

/// The old way: one session whose intra-op pool has `threads` threads, the batch in one call.
struct BatchSession {
    session: Session,
    features: usize,
}

impl BatchSession {
    fn open(path: &str, threads: usize, features: usize) -> BatchSession {
        let session = open_session(path, threads);
        BatchSession { session, features }
    }
}

impl Denoiser for BatchSession {
    type Error = ModelError;
    fn features(&self) -> usize {
        self.features
    }
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, ModelError> {
        let (b, f, n) = x_t.dim();
        let xs = Tensor::from_array(([b, f, n], x_t.iter().copied().collect::<Vec<_>>()))
            .expect("input");
        let ts = Tensor::from_array(([b], t.to_vec())).expect("steps");
        let out = self
            .session
            .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
            .expect("run");
        let (_, v) = out[OUTPUT_FEATURES]
            .try_extract_tensor::<f32>()
            .expect("x0");
        Ok(Array3::from_shape_vec((b, f, n), v.to_vec()).expect("shape"))
    }
}

fn request(count: usize, frames: usize) -> Request {
    Request {
        task: Task::Generate { frames },
        count,
        seed: 3,
        steps: Some(sinmdm::DEFAULT_STEPS),
        feet: Feet::Raw,
        method: Default::default(),
    }
}

fn features_of<D: Denoiser>(
    model: &Model,
    denoiser: &mut D,
    count: usize,
    frames: usize,
) -> Vec<f32>
where
    sinmdm::TaskError: From<D::Error>,
{
    let plan = sinmdm::plan(model.metadata(), &request(count, frames)).expect("plan");
    let generated = plan
        .run(denoiser, &mut |_, _| ControlFlow::Continue(()))
        .expect("run");
    generated.normalized.iter().copied().collect()
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let path = args
        .first()
        .cloned()
        .unwrap_or_else(|| common::SHIPPED_WALK.into());
    let frames: usize = args.get(1).map_or(498, |s| s.parse().expect("FRAMES"));
    let threads: usize = args.get(2).map_or(2, |s| s.parse().expect("THREADS"));
    let rounds: usize = std::env::var("SINMDM_BENCH_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let mut exact = Model::open(
        &path,
        &ModelOptions {
            threads: Some(threads),
        },
    )
    .expect("model");
    let f = exact.features();
    let mut old = BatchSession::open(&path, threads, f);
    println!(
        "{path}: {frames} frames, {} steps, {threads} threads, {rounds} rounds",
        sinmdm::DEFAULT_STEPS
    );

    // The bits: the old way at 1 thread against 2 and 4, and sample 0 of a batch of 3
    // against the same seed alone; the runtime's way gives 0 for every line.
    let short = frames.min(200);
    let alone = features_of(&exact, &mut BatchSession::open(&path, 1, f), 1, short);
    for t in [2, 4] {
        let other = features_of(&exact, &mut BatchSession::open(&path, t, f), 1, short);
        let ours = features_of(
            &exact,
            &mut Model::open(&path, &ModelOptions { threads: Some(t) }).expect("model"),
            1,
            short,
        );
        let ours_alone = features_of(
            &exact,
            &mut Model::open(&path, &ModelOptions { threads: Some(1) }).expect("model"),
            1,
            short,
        );
        println!(
            "max |diff| threads 1 vs {t}: old way {:.2e}, runtime {:.2e}",
            max_diff(&alone, &other),
            max_diff(&ours, &ours_alone)
        );
    }
    let batch_old = features_of(&exact, &mut BatchSession::open(&path, threads, f), 3, short);
    let alone_old = features_of(&exact, &mut BatchSession::open(&path, threads, f), 1, short);
    let batch_new = features_of(&exact, &mut exact_model(&path, threads), 3, short);
    let alone_new = features_of(&exact, &mut exact_model(&path, threads), 1, short);
    let first = alone_new.len();
    println!(
        "max |diff| sample 0 of 3 vs alone: old way {:.2e}, runtime {:.2e}",
        max_diff(&batch_old[..first], &alone_old),
        max_diff(&batch_new[..first], &alone_new)
    );

    println!(
        "| samples | old way s (one call, intra-op pool) | runtime s (sample per call) | runtime / old |"
    );
    println!("|---|---|---|---|");
    for count in [1, 20] {
        let (mut olds, mut news) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            let start = Instant::now();
            std::hint::black_box(features_of(&exact, &mut old, count, frames));
            olds.push(start.elapsed().as_secs_f64());
            let model = &mut exact;
            let start = Instant::now();
            let plan = sinmdm::plan(model.metadata(), &request(count, frames)).expect("plan");
            let generated = plan
                .run(model, &mut |_, _| ControlFlow::Continue(()))
                .expect("run");
            std::hint::black_box(generated.normalized[[0, 0, 0]]);
            news.push(start.elapsed().as_secs_f64());
        }
        let (o, n) = (median(&olds), median(&news));
        println!("| {count} | {o:.3} | {n:.3} | {:.2} |", n / o);
    }
}

fn exact_model(path: &str, threads: usize) -> Model {
    Model::open(
        path,
        &ModelOptions {
            threads: Some(threads),
        },
    )
    .expect("model")
}
