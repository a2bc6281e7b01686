//! What sampling costs beyond its network, side by side in one process:
//!
//! - **loop**: one sample of all 1 000 steps through the runtime (`plan(..).run`, raw feet)
//!   against a bare onnxruntime loop over the same file (a session opened as the runtime opens
//!   its own: one intra-op thread, full graph optimisation, no spinning; its output fed back as
//!   the next input), in alternating paired rounds; the median of the per-round ratios. For
//!   reference it also times the bare loop on onnxruntime's own two-thread pool (what a Python
//!   loop with default options gets, at the price of values that depend on the thread count).
//! - **stream**: a stream's 1-second chunks at the default options (mean, median, worst) against
//!   the same stream at a one-shot run's step count (what streams took before), alternating, the
//!   share of their time spent inside the network, and the worst chunk when the stream is
//!   prepared a few steps per chunk ([`Stream::prepare`]) as a game would.
//! - **crowd**: 20 samples at the default steps, in process.
//!
//! `cargo bench -p sinmdm --bench roofline -- [MODEL.onnx] [FRAMES] [ROUNDS] [loop|stream|crowd]`
//! (default: the shipped walk, 498 frames, 5 rounds, all three parts). `scripts/bench_roofline.sh` runs it with the GEMM
//! roofline and the whole-process crowd of `lab/scripts/profile_network.py`.

use std::ops::ControlFlow;
use std::time::Instant;

mod common;

use common::{Timed, median, open_session};
use ort::session::Session;
use ort::value::Tensor;
use sinmdm::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};
use sinmdm::{Feet, Model, ModelOptions, Request, Stream, StreamOptions, Task};

/// A bare loop: `steps` calls of one session, each call's output the next call's input.
struct BareLoop {
    session: Session,
    features: usize,
    frames: usize,
    x: Vec<f32>,
}

impl BareLoop {
    fn open(path: &str, threads: usize, features: usize, frames: usize) -> BareLoop {
        let session = open_session(path, threads);
        BareLoop {
            session,
            features,
            frames,
            x: vec![0.5f32; features * frames],
        }
    }

    /// One call at diffusion step `k`, its output kept as the next input.
    fn call(&mut self, k: usize) {
        let shape = [1, self.features, self.frames];
        let xs = Tensor::from_array((shape, std::mem::take(&mut self.x))).expect("input");
        let ts = Tensor::from_array(([1usize], vec![k as i64])).expect("step");
        let out = self
            .session
            .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
            .expect("run");
        let (_, v) = out[OUTPUT_FEATURES]
            .try_extract_tensor::<f32>()
            .expect("x0");
        self.x = v.to_vec();
    }

    /// Seconds for `steps` calls.
    fn run(&mut self, steps: usize) -> f64 {
        self.x.fill(0.5);
        let start = Instant::now();
        for k in (0..steps).rev() {
            self.call(k);
        }
        std::hint::black_box(self.x[0]);
        start.elapsed().as_secs_f64()
    }
}

fn request(count: usize, frames: usize, steps: Option<usize>) -> Request {
    Request {
        task: Task::Generate { frames },
        count,
        seed: 7,
        steps,
        feet: Feet::Raw,
        method: Default::default(),
    }
}

fn generate(model: &mut Model, count: usize, frames: usize, steps: Option<usize>) -> f64 {
    generate_timed(model, count, frames, steps).0
}

/// Seconds for a run, and the seconds of it spent inside the network's calls.
fn generate_timed(
    model: &mut Model,
    count: usize,
    frames: usize,
    steps: Option<usize>,
) -> (f64, f64) {
    let plan = sinmdm::plan(model.metadata(), &request(count, frames, steps)).expect("plan");
    let mut timed = Timed { model, inside: 0.0 };
    let start = Instant::now();
    let out = plan
        .run(&mut timed, &mut |_, _| ControlFlow::Continue(()))
        .expect("run");
    std::hint::black_box(out.normalized[[0, 0, 0]]);
    (start.elapsed().as_secs_f64(), timed.inside)
}

/// The runtime's run (planning, every step, finishing) and the bare loop's calls interleaved
/// step by step, so both see the same moment of a shared machine: (runtime, bare) seconds.
fn interleaved(model: &mut Model, bare: &mut BareLoop, frames: usize) -> (f64, f64) {
    let steps = model.metadata().diffusion.steps;
    bare.x.fill(0.5);
    let start = Instant::now();
    let plan = sinmdm::plan(model.metadata(), &request(1, frames, None)).expect("plan");
    let mut run = plan.start().expect("start");
    let mut ours = start.elapsed().as_secs_f64();
    let mut theirs = 0.0;
    for k in (0..steps).rev() {
        let t = Instant::now();
        run.step(model, 1).expect("step");
        ours += t.elapsed().as_secs_f64();
        let t = Instant::now();
        bare.call(k);
        theirs += t.elapsed().as_secs_f64();
    }
    let t = Instant::now();
    let out = run.finish().expect("finish");
    std::hint::black_box(out.normalized[[0, 0, 0]]);
    ours += t.elapsed().as_secs_f64();
    (ours, theirs)
}

fn loop_against_bare(path: &str, frames: usize, rounds: usize) {
    let mut model = Model::open(path, &ModelOptions { threads: Some(1) }).expect("model");
    let f = model.features();
    let steps = model.metadata().diffusion.steps;
    let mut bare = BareLoop::open(path, 1, f, frames);
    let mut pool = BareLoop::open(path, 2, f, frames);
    bare.run(5);
    pool.run(5);
    generate(&mut model, 1, frames, Some(5));
    let (mut ours, mut bares, mut pools, mut ratios) = (vec![], vec![], vec![], vec![]);
    let (mut outside, mut inside_ratios) = (vec![], vec![]);
    for round in 0..rounds {
        let ((o, inside), b) = if round % 2 == 0 {
            let o = generate_timed(&mut model, 1, frames, None);
            (o, bare.run(steps))
        } else {
            let b = bare.run(steps);
            (generate_timed(&mut model, 1, frames, None), b)
        };
        ours.push(o);
        bares.push(b);
        ratios.push(o / b);
        outside.push((o - inside) / o);
        inside_ratios.push(inside / b);
        pools.push(pool.run(steps));
    }
    let (lo, hi) = ratios
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    println!(
        "loop, 1 sample x {frames} frames x {steps} steps (median of {rounds} paired rounds):"
    );
    println!(
        "  runtime {:.3} s, bare onnxruntime loop (the runtime's session options) {:.3} s: ratio {:.3} (rounds {lo:.3} to {hi:.3})",
        median(&ours),
        median(&bares),
        median(&ratios)
    );
    println!(
        "  the runtime's own work (sampler, noise hand-over, planning): {:.2} % of its run; its network calls against the bare loop's: {:.3}",
        median(&outside) * 100.0,
        median(&inside_ratios)
    );
    println!(
        "  bare loop on onnxruntime's two-thread pool {:.3} s: runtime / pool {:.3} (values depend on the thread count)",
        median(&pools),
        median(&ours) / median(&pools)
    );
    let step_ratios: Vec<f64> = (0..rounds)
        .map(|_| {
            let (o, b) = interleaved(&mut model, &mut bare, frames);
            o / b
        })
        .collect();
    let (lo, hi) = step_ratios
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    println!(
        "  interleaved step by step (the runtime's run, then one bare call, {steps} times): ratio {:.3} (rounds {lo:.3} to {hi:.3})",
        median(&step_ratios)
    );
}

/// Mean seconds per 1-second chunk of a stream with `options`, read with `next` alone, and the
/// share of that time inside the network; prints the line.
fn chunk_cost(model: &mut Model, options: &StreamOptions, seconds: usize, label: &str) -> f64 {
    let second = model.fps().round() as usize;
    let mut stream = Stream::new(model.metadata(), options.clone()).expect("stream");
    let mut times = Vec::new();
    let mut timed = Timed { model, inside: 0.0 };
    let start = Instant::now();
    for _ in 0..seconds {
        let t = Instant::now();
        std::hint::black_box(stream.next(&mut timed, second).expect("chunk").frames());
        times.push(t.elapsed().as_secs_f64());
    }
    let total = start.elapsed().as_secs_f64();
    let worst = times.iter().copied().fold(0.0, f64::max);
    println!(
        "  {label}: mean {:.2} ms, median {:.2} ms, worst {:.1} ms per chunk; {:.1} % of the time inside the network",
        total / seconds as f64 * 1e3,
        median(&times) * 1e3,
        worst * 1e3,
        timed.inside / total * 100.0
    );
    total / seconds as f64
}

fn stream_chunks(path: &str, seconds: usize) {
    let mut model = Model::open(path, &ModelOptions::default()).expect("model");
    let second = model.fps().round() as usize;
    let block = Stream::new(model.metadata(), StreamOptions::default())
        .expect("stream")
        .sizes()
        .block;
    println!(
        "stream, {seconds} 1-second chunks (blocks of {block} frames), read with `next` alone:"
    );
    // The default (sinmdm::DEFAULT_STREAM_STEPS per block) against a one-shot run's step count,
    // which streams took before, alternating so both see the same machine.
    let before = StreamOptions {
        steps: Some(sinmdm::DEFAULT_STEPS),
        ..StreamOptions::default()
    };
    let (mut now, mut then) = (Vec::new(), Vec::new());
    for round in 0..2 {
        let label = |steps: usize| format!("round {}, {steps} steps per block", round + 1);
        then.push(chunk_cost(
            &mut model,
            &before,
            seconds,
            &label(sinmdm::DEFAULT_STEPS),
        ));
        now.push(chunk_cost(
            &mut model,
            &StreamOptions::default(),
            seconds,
            &label(sinmdm::DEFAULT_STREAM_STEPS),
        ));
    }
    println!(
        "  default ({} steps) against {} steps per block: {:.2} ms against {:.2} ms per chunk, {:.2}x less",
        sinmdm::DEFAULT_STREAM_STEPS,
        sinmdm::DEFAULT_STEPS,
        median(&now) * 1e3,
        median(&then) * 1e3,
        median(&then) / median(&now)
    );
    // The default stream prepared a few steps per chunk (as a game's frame loop would): the
    // steps per chunk that keep a block ahead, and the worst chunk then.
    let mut stream = Stream::new(model.metadata(), StreamOptions::default()).expect("stream");
    // No block is under way yet, so the steps per block come from the options.
    let steps = StreamOptions::default()
        .steps
        .unwrap_or(model.metadata().diffusion.steps);
    let per_chunk = (steps * second).div_ceil(block) + 1;
    let mut times = Vec::new();
    let start = Instant::now();
    for _ in 0..seconds {
        let t = Instant::now();
        std::hint::black_box(stream.next(&mut model, second).expect("chunk").frames());
        stream
            .prepare(&mut model, per_chunk, block + second)
            .expect("prepare");
        times.push(t.elapsed().as_secs_f64());
    }
    let total = start.elapsed().as_secs_f64();
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "  prepared {per_chunk} steps per chunk: mean {:.2} ms, worst {:.1} ms (the first chunk pays its block), worst after it {:.1} ms",
        total / seconds as f64 * 1e3,
        sorted[sorted.len() - 1] * 1e3,
        times[1..].iter().copied().fold(0.0, f64::max) * 1e3
    );
}

fn crowd(path: &str, frames: usize, rounds: usize) {
    let mut model = Model::open(path, &ModelOptions::default()).expect("model");
    generate(&mut model, 2, frames, Some(2));
    let times: Vec<f64> = (0..rounds.min(3))
        .map(|_| generate(&mut model, 20, frames, Some(sinmdm::DEFAULT_STEPS)))
        .collect();
    println!(
        "crowd, 20 samples x {frames} frames x {} steps on {} threads, in process: {:.3} s (median of {})",
        sinmdm::DEFAULT_STEPS,
        model.threads(),
        median(&times),
        times.len()
    );
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let path = args
        .first()
        .filter(|p| !p.is_empty())
        .cloned()
        .unwrap_or_else(|| common::SHIPPED_WALK.to_string());
    let frames: usize = args.get(1).map_or(498, |s| s.parse().expect("FRAMES"));
    let rounds: usize = args.get(2).map_or(5, |s| s.parse().expect("ROUNDS"));
    let only = args.get(3).map(String::as_str);
    println!("model {path}");
    if only.is_none_or(|o| o == "loop") {
        loop_against_bare(&path, frames, rounds);
    }
    if only.is_none_or(|o| o == "stream") {
        stream_chunks(&path, 180);
    }
    if only.is_none_or(|o| o == "crowd") {
        crowd(&path, frames, rounds);
    }
}
