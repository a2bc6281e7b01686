//! Sampling speed and memory through onnxruntime: seconds per denoiser step and per sample, the
//! loop's overhead over bare onnxruntime calls, and peak memory.
//!
//! `cargo bench -p sinmdm --bench sampling -- MODEL.onnx [FRAMES] [THREADS]`; without a model it
//! uses `SINMDM_BENCH_MODEL`. `scripts/bench_runtime.sh` makes a paper-size (C 256) model first.

use std::time::Instant;

use ndarray::Array3;
use ort::session::Session;
use ort::value::Tensor;
use sinmdm::diffusion::Schedule;
use sinmdm::diffusion::sampler::{Guidance, sample};
use sinmdm::model::{Model, ModelOptions};

/// Peak resident memory of this process in MiB (Linux `VmHWM`), if known.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Mean seconds of one bare onnxruntime call on a fresh session of the same file.
fn bare_step_seconds(
    path: &str,
    threads: usize,
    b: usize,
    f: usize,
    n: usize,
    calls: usize,
) -> f64 {
    let rt = sinmdm::onnxruntime::init().expect("onnxruntime");
    let mut session = Session::builder(&rt.environment)
        .and_then(|s| Ok(s.with_intra_threads(threads)?))
        .and_then(|s| Ok(s.with_intra_op_spinning(false)?))
        .and_then(|mut s| s.commit_from_file(path))
        .expect("session");
    let x = vec![0.1f32; b * f * n];
    let t = vec![500i64; b];
    let mut run = || {
        let xs = Tensor::from_array(([b, f, n], x.clone().into_boxed_slice())).unwrap();
        let ts = Tensor::from_array(([b], t.clone().into_boxed_slice())).unwrap();
        let out = session.run(ort::inputs!["x_t" => xs, "t" => ts]).unwrap();
        let (_, v) = out["x0"].try_extract_tensor::<f32>().unwrap();
        std::hint::black_box(v[0]);
    };
    run();
    let start = Instant::now();
    for _ in 0..calls {
        run();
    }
    start.elapsed().as_secs_f64() / calls as f64
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
    println!(
        "| batch | steps | bare ort s/call | loop s/step | overhead | s/sample run | peak MiB |"
    );
    println!("|---|---|---|---|---|---|---|");
    for &(batch, steps) in &[(1, 1000), (1, 100), (16, 100), (16, 1000)] {
        if batch == 16 && steps == 1000 && std::env::var("SINMDM_BENCH_LONG").is_err() {
            continue;
        }
        let calls = steps.min(100);
        let bare = bare_step_seconds(&path, threads, batch, f, frames, calls);
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
        let start = Instant::now();
        let out = sample(
            &mut model,
            &schedule,
            batch,
            frames,
            1,
            &Guidance::default(),
            &mut |_, _| {},
        )
        .unwrap();
        let total = start.elapsed().as_secs_f64();
        std::hint::black_box(out[[0, 0, 0]]);
        let per_step = total / steps as f64;
        println!(
            "| {batch} | {steps} | {:.2} ms | {:.2} ms | {:+.1} % | {:.2} s | {:.0} |",
            bare * 1e3,
            per_step * 1e3,
            (per_step / bare - 1.0) * 100.0,
            total,
            peak_memory_mib().unwrap_or(f64::NAN)
        );
    }
}
