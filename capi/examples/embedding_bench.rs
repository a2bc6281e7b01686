//! What an engine embedding pays and gets, printed as figures (the machine is shared: compare
//! the ratios, each measured side by side in one run):
//! - a stream's time per 1-second chunk at the default steps (median, 90th percentile, worst)
//!   and its speed against real time;
//! - its memory over 10 minutes of motion in 1-second chunks (resident set after the first
//!   minute and at the end);
//! - joint acceleration at block seams against inside blocks (99th percentiles);
//! - coverage and global diversity of 60 s streamed against one-shot 60 s samples;
//! - the C ABI's overhead over the Rust call for the same generate + poses.
//!
//! `cargo run --release -p sinmdm-c --example embedding_bench [MODEL.onnx CLIP.bvh [MINUTES [BLOCK_SECONDS]]]`

use std::ops::ControlFlow;
use std::time::Instant;

use sinmdm::motion::{LocalMotion, encode_for_model, global_poses};
use sinmdm::{FeatureLayout, Feet, Model, ModelOptions, Request, Stream, StreamOptions, Task};
use sinmdm_c::{
    SINMDM_FEET_PLANTED, SinmdmModel, SinmdmPoseBuffers, SinmdmResult, SinmdmSampling,
    SinmdmStatus, sinmdm_generate, sinmdm_model_free, sinmdm_model_open, sinmdm_result_free,
    sinmdm_result_poses,
};
use sinmdm_eval::{evaluate, metric_features};

fn resident_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn percentile(values: &[f64], p: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn append(all: &mut Option<LocalMotion>, motion: LocalMotion) {
    match all {
        None => *all = Some(motion),
        Some(a) => {
            a.rotations.extend(motion.rotations);
            a.translations.extend(motion.translations);
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let model_path = args
        .get(1)
        .cloned()
        .unwrap_or(format!("{root}/onnx-models/human_walk_cmu.onnx"));
    let clip_path = args
        .get(2)
        .cloned()
        .unwrap_or(format!("{root}/tests/data/bvh/human_walk_cmu_131_01.bvh"));
    let minutes: usize = args.get(3).and_then(|m| m.parse().ok()).unwrap_or(10);
    let block_seconds: Option<f64> = args.get(4).and_then(|b| b.parse().ok());
    let mut model = Model::open(&model_path, &ModelOptions::default())?;
    let fps = model.fps();
    let second = fps.round() as usize;
    let options = StreamOptions {
        block_frames: block_seconds.map(|b| (b * fps).round() as usize),
        ..StreamOptions::default()
    };
    let layout = model.metadata().layout.clone();
    println!(
        "model {model_path}, {fps} fps, default steps, blocks of {}",
        block_seconds.map_or("the clip's length".into(), |b| format!("{b} s"))
    );

    let (stream, first_minute) = speed_and_memory(&mut model, &options, second, minutes)?;
    seams(first_minute, stream.sizes().block);
    quality(&mut model, &layout, &options, &clip_path, second)?;
    c_abi_overhead(&mut model, &model_path)?;
    Ok(())
}

/// Speed and memory: `minutes` of motion in 1-second chunks of `second` frames, printed; returns
/// the stream and its first minute of motion.
fn speed_and_memory(
    model: &mut Model,
    options: &StreamOptions,
    second: usize,
    minutes: usize,
) -> Result<(Stream, Option<LocalMotion>), Box<dyn std::error::Error>> {
    let mut stream = Stream::new(model.metadata(), options.clone())?;
    let mut times = Vec::new();
    let mut first_minute: Option<LocalMotion> = None;
    let mut rss_after_minute = 0.0;
    let started = Instant::now();
    for chunk in 0..minutes * 60 {
        let t = Instant::now();
        let out = stream.next(model, second)?;
        times.push(t.elapsed().as_secs_f64());
        if chunk < 60 {
            append(&mut first_minute, out.motion);
        }
        if chunk == 59 {
            rss_after_minute = resident_mib();
        }
    }
    let total = started.elapsed().as_secs_f64();
    println!(
        "1-second chunk: mean {:.3} s, median {:.3} s, p90 {:.3} s, worst {:.3} s (a chunk that starts a block pays for it); {} min of motion in {total:.1} s = {:.1}x real time",
        total / times.len() as f64,
        percentile(&times, 0.5),
        percentile(&times, 0.9),
        percentile(&times, 1.0),
        minutes,
        minutes as f64 * 60.0 / total
    );
    let rss_end = resident_mib();
    println!(
        "resident memory: {rss_after_minute:.1} MiB after 1 min, {rss_end:.1} MiB after {minutes} min (growth {:.2} MiB)",
        rss_end - rss_after_minute
    );
    Ok((stream, first_minute))
}

/// Seams: joint acceleration of `first_minute` at the boundaries of blocks of `block` frames
/// against inside blocks, printed.
fn seams(first_minute: Option<LocalMotion>, block: usize) {
    let motion = first_minute.expect("a minute of motion");
    let poses = global_poses(&motion);
    let (mut seam, mut inside) = (Vec::new(), Vec::new());
    for i in 1..poses.len() - 1 {
        let a: f64 = (0..poses[i].joints.len())
            .map(|j| {
                let p = |k: usize| poses[k].joints[j];
                let d: Vec<f64> = (0..3)
                    .map(|c| p(i + 1)[c] - 2.0 * p(i)[c] + p(i - 1)[c])
                    .collect();
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .sum::<f64>()
            / poses[i].joints.len() as f64;
        if i % block == 0 || i % block == block - 1 {
            seam.push(a);
        } else {
            inside.push(a);
        }
    }
    let (s99, i99) = (percentile(&seam, 0.99), percentile(&inside, 0.99));
    println!(
        "joint acceleration p99: at seams {s99:.4}, inside blocks {i99:.4} (ratio {:.2})",
        s99 / i99
    );
}

/// Quality: 60 s streamed against 60 s in one shot, three seeds each, printed.
fn quality(
    model: &mut Model,
    layout: &FeatureLayout,
    options: &StreamOptions,
    clip_path: &str,
    second: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let clip = encode_for_model(&sinmdm::bvh::read_bvh(clip_path)?, layout, None)?.features;
    let clip_metric = metric_features(layout, clip.view());
    let frames = 60 * second;
    let (mut streamed, mut one_shot) = (Vec::new(), Vec::new());
    for seed in 0..3u64 {
        let mut s = Stream::new(
            model.metadata(),
            StreamOptions {
                seed,
                feet: Feet::Raw,
                ..options.clone()
            },
        )?;
        let features = s.next(model, frames)?.features;
        streamed.push(metric_features(layout, features.view()));
        let request = Request {
            task: Task::Generate { frames },
            count: 1,
            seed,
            steps: Some(100),
            feet: Feet::Raw,
            method: Default::default(),
        };
        let generated = sinmdm::run(model, &request, &mut |_, _| ControlFlow::Continue(()))?;
        one_shot.push(metric_features(
            layout,
            generated.features.index_axis(ndarray::Axis(0), 0),
        ));
    }
    let a = evaluate(clip_metric.view(), &streamed, 2)?;
    let b = evaluate(clip_metric.view(), &one_shot, 2)?;
    println!(
        "60 s streamed: coverage {:.1}, global diversity {:.3}; one-shot: coverage {:.1}, global diversity {:.3}",
        a.coverage.mean, a.global_diversity.mean, b.coverage.mean, b.global_diversity.mean
    );
    Ok(())
}

/// The C ABI against the Rust call: generate + poses, interleaved, printed.
fn c_abi_overhead(model: &mut Model, model_path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let path = std::ffi::CString::new(model_path)?;
    let mut handle: *mut SinmdmModel = std::ptr::null_mut();
    let status = unsafe { sinmdm_model_open(path.as_ptr(), 0, &mut handle) };
    assert_eq!(status, SinmdmStatus::Ok);
    let joints = model.skeleton().len();
    let frames = 120;
    let (mut root, mut rot, mut trans) = (
        vec![0f32; 3 * frames],
        vec![0f32; 4 * joints * frames],
        vec![0f32; 3 * joints * frames],
    );
    let buffers = SinmdmPoseBuffers {
        root_positions: root.as_mut_ptr(),
        root_positions_capacity: root.len(),
        rotations: rot.as_mut_ptr(),
        rotations_capacity: rot.len(),
        translations: trans.as_mut_ptr(),
        translations_capacity: trans.len(),
    };
    let sampling = SinmdmSampling {
        seed: 1,
        count: 1,
        steps: 20,
        feet: SINMDM_FEET_PLANTED,
        method: 0,
        eta: 0.0,
    };
    let request = Request {
        task: Task::Generate { frames },
        count: 1,
        seed: 1,
        steps: Some(20),
        feet: Feet::Planted,
        method: Default::default(),
    };
    let (mut rust, mut c) = (Vec::new(), Vec::new());
    for _ in 0..15 {
        let t = Instant::now();
        let generated = sinmdm::run(model, &request, &mut |_, _| ControlFlow::Continue(()))?;
        std::hint::black_box(generated.poses(0)?);
        rust.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut result: *mut SinmdmResult = std::ptr::null_mut();
        unsafe {
            assert_eq!(
                sinmdm_generate(handle, &sampling, frames, &mut result),
                SinmdmStatus::Ok
            );
            assert_eq!(sinmdm_result_poses(result, 0, &buffers), SinmdmStatus::Ok);
            sinmdm_result_free(result);
        }
        c.push(t.elapsed().as_secs_f64());
    }
    unsafe { sinmdm_model_free(handle) };
    let (mr, mc) = (percentile(&rust, 0.5), percentile(&c, 0.5));
    println!(
        "generate + poses (120 frames, 20 steps): Rust {:.1} ms, C ABI {:.1} ms (median of 15; overhead {:+.2} %)",
        mr * 1e3,
        mc * 1e3,
        100.0 * (mc / mr - 1.0)
    );
    Ok(())
}
