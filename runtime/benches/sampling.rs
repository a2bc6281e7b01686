//! Sampling speed and memory through onnxruntime: seconds per denoiser step and per sample, the
//! loop's overhead over bare onnxruntime calls, and peak memory.
//!
//! `cargo bench -p sinmdm --bench sampling -- MODEL.onnx [FRAMES] [THREADS]`; without a model it
//! uses `SINMDM_BENCH_MODEL`. `lab/scripts/bench_runtime.sh` makes a paper-size (C 256) model
//! first.

mod common;

use std::time::Instant;

use common::{Timed, median};
use ndarray::Array3;
use ort::session::Session;
use ort::value::Tensor;
use sinmdm::diffusion::Schedule;
use sinmdm::diffusion::sampler::{Guidance, Sampler};
use sinmdm::network::{INPUT_FEATURES, INPUT_STEP, OUTPUT_FEATURES};
use sinmdm::{Model, ModelOptions};

/// Peak resident memory of this process in MiB (Linux `VmHWM`), if known.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// A plain onnxruntime session on the same file, fed the same shapes as the sampler.
struct BareSession {
    session: Session,
    b: usize,
    f: usize,
    n: usize,
}

impl BareSession {
    fn open(path: &str, threads: usize, b: usize, f: usize, n: usize) -> BareSession {
        let rt = sinmdm::init_onnxruntime().expect("onnxruntime");
        let session = Session::builder(rt.environment())
            .and_then(|s| Ok(s.with_intra_threads(threads)?))
            .and_then(|s| Ok(s.with_intra_op_spinning(false)?))
            .and_then(|mut s| s.commit_from_file(path))
            .expect("session");
        let mut bare = BareSession { session, b, f, n };
        bare.call();
        bare
    }

    /// One call, including building the input tensors and reading the output, as the loop does.
    fn call(&mut self) {
        let (b, f, n) = (self.b, self.f, self.n);
        let xs =
            Tensor::from_array(([b, f, n], vec![0.1f32; b * f * n].into_boxed_slice())).unwrap();
        let ts = Tensor::from_array(([b], vec![500i64; b].into_boxed_slice())).unwrap();
        let out = self
            .session
            .run(ort::inputs![INPUT_FEATURES => xs, INPUT_STEP => ts])
            .unwrap();
        let (_, v) = out[OUTPUT_FEATURES].try_extract_tensor::<f32>().unwrap();
        std::hint::black_box(v[0]);
    }
}

/// Times drawing one step's noise, for a batch of 1 and of 16.
fn time_noise(f: usize, frames: usize) {
    for batch in [1, 16] {
        let mut buffer = vec![0.0f32; batch * f * frames];
        let start = Instant::now();
        for stream in 0..50 {
            sinmdm::diffusion::noise::fill_normals(1, stream, &mut buffer);
        }
        println!(
            "noise for one step of batch {batch} ({} normals): {:.3} ms on one thread",
            buffer.len(),
            start.elapsed().as_secs_f64() / 50.0 * 1e3
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let Some(path) = args
        .first()
        .cloned()
        .or_else(|| std::env::var("SINMDM_BENCH_MODEL").ok())
    else {
        eprintln!("usage: cargo bench -p sinmdm --bench sampling -- MODEL.onnx [FRAMES] [THREADS]");
        return;
    };
    let frames: usize = args.get(1).map_or(200, |s| s.parse().expect("FRAMES"));
    let threads: usize = args.get(2).map_or(2, |s| s.parse().expect("THREADS"));
    let mut model = Model::open(
        &path,
        &ModelOptions {
            threads: Some(threads),
        },
    )
    .expect("model");
    let f = model.features();
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    println!(
        "model {path}: F {f}, C {}, {} parameters, {:.1} MB; {frames} frames, {threads} threads",
        model.metadata().network.channels,
        model.metadata().network.parameters,
        size as f64 / 1e6
    );
    time_noise(f, frames);
    // A bare call follows every step of the sampling loop (from its progress callback, when the
    // noise thread is idle), so a slow spell of the machine hits the loop's steps and the bare
    // calls alike. A round is one sampling run; its overhead is (loop time without the
    // callbacks) / (time of its bare calls) - 1, and the table gives the median over rounds.
    let rounds: usize = std::env::var("SINMDM_BENCH_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    println!(
        "| batch | steps | bare ort s/call | loop s/step | overhead, median (range) of {rounds} rounds | time outside ort | s/sample run | peak MiB |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for &(batch, steps) in &[(1, 1000), (1, 100), (16, 100), (16, 1000)] {
        if batch == 16 && steps == 1000 && std::env::var("SINMDM_BENCH_LONG").is_err() {
            continue;
        }
        let mut bare_session = BareSession::open(&path, threads, batch, f, frames);
        let schedule = if steps == 1000 {
            Schedule::cosine(1000).unwrap()
        } else {
            Schedule::respaced(1000, steps).unwrap()
        };
        let _warm = model
            .denoise(
                Array3::<f32>::zeros((batch, f, frames)).view(),
                &vec![1; batch],
            )
            .unwrap();
        let (mut bares, mut loops, mut overheads, mut outside) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            let mut timed = Timed {
                model: &mut model,
                inside: 0.0,
            };
            let mut bare_total = 0.0;
            let start = Instant::now();
            let guidance = Guidance::default();
            let mut sampler = Sampler::new(&schedule, &guidance, batch, f, frames, 1).unwrap();
            while !sampler.is_finished() {
                sampler.step(&mut timed).unwrap();
                let entered = Instant::now();
                bare_session.call();
                bare_total += entered.elapsed().as_secs_f64();
            }
            let out = sampler.into_sample();
            let total = start.elapsed().as_secs_f64() - bare_total;
            std::hint::black_box(out[[0, 0, 0]]);
            bares.push(bare_total / steps as f64);
            loops.push(total / steps as f64);
            overheads.push(total / bare_total - 1.0);
            outside.push((total - timed.inside) / timed.inside);
        }
        let (lo, hi) = overheads
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let per_step = median(&loops);
        println!(
            "| {batch} | {steps} | {:.2} ms | {:.2} ms | {:+.1} % ({:+.1} to {:+.1}) | {:.1} % | {:.2} s | {:.0} |",
            median(&bares) * 1e3,
            per_step * 1e3,
            median(&overheads) * 100.0,
            lo * 100.0,
            hi * 100.0,
            median(&outside) * 100.0,
            per_step * steps as f64,
            peak_memory_mib().unwrap_or(f64::NAN)
        );
    }
}
