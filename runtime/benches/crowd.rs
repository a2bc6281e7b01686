//! Characters per core: N steered walks on one shared model run on one thread, advanced as a
//! game advances them, one model frame at a time, two ways side by side: each character its own
//! [`Stream`] (each frame every character prepares ahead within a step budget, then takes its
//! frame), and one [`Crowd`] (each frame the crowd prepares within a budget of steps, the same
//! budget per character as the streams', then every character takes its frame).
//! Characters join at staggered block phases (their first frames are pulled, and the next
//! prepared, before the clock starts), as characters of a game do, so their blocks do not all
//! start on one frame.
//!
//! Prints, for each crowd size: CPU time of this thread per character-second of motion (and the
//! characters one core animates in real time at the model's frame rate), the worst frame's wait
//! for the whole crowd and per character, and the memory the crowd's streams hold per
//! character. Linux: CPU time of the whole process (every thread, the streams' noise workers
//! included) from /proc/self/stat, memory from /proc/self/status.
//!
//! `cargo bench -p sinmdm --bench crowd [-- MODEL.onnx]` (default: the shipped walk).
//! `SINMDM_CROWD_SIZES=1,8,64,512` and `SINMDM_CROWD_SECONDS=20` (motion per character) change
//! the run; `SINMDM_CROWD_BUDGET=4` is the steps a character may spend preparing per frame;
//! `SINMDM_CROWD_FREE=1` leaves the characters unsteered; `SINMDM_CROWD_CHUNK=30` reads 30
//! frames a call (then a "frame" below is one such read); `SINMDM_CROWD_WAY=streams` or `crowd`
//! runs one way only (`crowd-one-call`: a crowd whose blocks are one onnxruntime call per
//! thread, `OneCallPerThread`); `SINMDM_CROWD_STEPS=20` sets the denoising steps per block.

use std::time::Instant;

mod common;

use sinmdm::steer::SteerFrame;
use sinmdm::{Crowd, Feet, Model, ModelOptions, OneCallPerThread, Stream, StreamOptions};

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Nanoseconds the whole process has run on a CPU, user and system, every thread (wall time
/// where /proc says nothing). /proc counts in clock ticks, 100 a second on Linux.
fn process_cpu_ns(start: Instant) -> u128 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // Fields after the command's closing parenthesis; utime and stime are the 12th and
            // 13th of them.
            let rest = &s[s.rfind(')')? + 2..];
            let fields: Vec<&str> = rest.split_whitespace().collect();
            let ticks: u128 =
                fields.get(11)?.parse::<u128>().ok()? + fields.get(12)?.parse::<u128>().ok()?;
            Some(ticks * 10_000_000)
        })
        .unwrap_or_else(|| start.elapsed().as_nanos())
}

/// The resident memory of the process in bytes (0 where /proc says nothing).
fn resident_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))?
                .split_whitespace()
                .nth(1)?
                .parse::<u64>()
                .ok()
        })
        .map_or(0, |kb| kb * 1024)
}

/// Character `i`'s commands: walk at the clip's pace, turning left or right by its index.
fn commands(i: usize, frames: usize, fps: f64) -> Vec<SteerFrame> {
    let turn = (i as f64 % 7.0 - 3.0) * 0.1;
    (0..frames)
        .map(|f| SteerFrame::Velocity {
            forward: 12.0,
            turn: turn * (f as f64 / fps).sin().signum(),
        })
        .collect()
}

struct Figures {
    cpu_ms_per_character_second: f64,
    worst_frame_ms: f64,
    worst_character_ms: Option<f64>,
    bytes_per_character: f64,
}

/// How the characters of one run are made.
#[derive(Clone, Copy)]
struct Run {
    size: usize,
    seconds: f64,
    budget: usize,
    free: bool,
    chunk: usize,
    steps: usize,
}

impl Run {
    fn options(&self, i: usize) -> StreamOptions {
        StreamOptions {
            seed: i as u64,
            steps: Some(self.steps),
            feet: Feet::Planted,
            ..StreamOptions::default()
        }
    }

    /// Character `i`'s join frame (staggered over a block) and its commands, if steered.
    fn start(&self, i: usize, stream: &Stream, fps: f64) -> (usize, Option<Vec<SteerFrame>>) {
        let block = stream.sizes().block;
        let join = i * block / self.size.max(1);
        let frames = (self.seconds * fps).round() as usize;
        let steer =
            (!self.free).then(|| commands(i, join + frames + stream.lookahead() + block, fps));
        (join, steer)
    }
}

/// One way of making a run's characters.
type Way = fn(&mut Model, Run) -> Figures;

/// Each character its own stream.
fn streams(model: &mut Model, run: Run) -> Figures {
    let fps = model.metadata().layout.fps;
    let frames = (run.seconds * fps).round() as usize;
    let before = resident_bytes();
    let mut streams: Vec<Stream> = (0..run.size)
        .map(|i| {
            let mut stream = Stream::new(model.metadata(), run.options(i)).expect("stream");
            let (join, steer) = run.start(i, &stream, fps);
            if let Some(commands) = steer {
                stream.steer(&commands).expect("steer");
            }
            stream.next(model, join + 1).expect("join");
            stream
        })
        .collect();
    let held = resident_bytes().saturating_sub(before) as f64 / run.size as f64;
    // Every character starts the clock prepared as far ahead as the loop keeps it, so the
    // worst frame is the loop's own, not the crowd's first frame.
    let ahead = streams[0].sizes().block / 4;
    for stream in &mut streams {
        stream.prepare(model, usize::MAX, ahead).expect("prepare");
    }
    let clock = Instant::now();
    let cpu = process_cpu_ns(clock);
    let (mut worst_frame, mut worst_character) = (0f64, 0f64);
    for _ in 0..frames / run.chunk {
        let frame = Instant::now();
        for stream in &mut streams {
            let one = Instant::now();
            stream.prepare(model, run.budget, ahead).expect("prepare");
            stream.next(model, run.chunk).expect("next");
            worst_character = worst_character.max(one.elapsed().as_secs_f64());
        }
        worst_frame = worst_frame.max(frame.elapsed().as_secs_f64());
    }
    let cpu_s = (process_cpu_ns(clock) - cpu) as f64 / 1e9;
    Figures {
        cpu_ms_per_character_second: 1e3 * cpu_s / (run.size as f64 * run.seconds),
        worst_frame_ms: 1e3 * worst_frame,
        worst_character_ms: Some(1e3 * worst_character),
        bytes_per_character: held,
    }
}

/// One crowd of every character.
fn crowd(model: &mut Model, run: Run) -> Figures {
    crowd_run(model, run, false)
}

/// One crowd of every character, its blocks denoised in one onnxruntime call per thread.
fn crowd_one_call(model: &mut Model, run: Run) -> Figures {
    crowd_run(model, run, true)
}

/// [`Crowd::prepare`] on the model, or on it one call per thread.
fn prepare(crowd: &mut Crowd, model: &mut Model, one_call: bool, steps: usize, ahead: usize) {
    if one_call {
        crowd.prepare(&mut OneCallPerThread(model), steps, ahead)
    } else {
        crowd.prepare(model, steps, ahead)
    }
    .expect("prepare");
}

fn crowd_run(model: &mut Model, run: Run, one_call: bool) -> Figures {
    let fps = model.metadata().layout.fps;
    let frames = (run.seconds * fps).round() as usize;
    let before = resident_bytes();
    let mut crowd = Crowd::new(model.metadata());
    let mut block = 0;
    for i in 0..run.size {
        let id = crowd.join(run.options(i)).expect("join");
        let stream = crowd.character_mut(id).expect("joined");
        block = stream.sizes().block;
        let (join, steer) = run.start(i, stream, fps);
        if let Some(commands) = steer {
            stream.steer(&commands).expect("steer");
        }
        stream.next(model, join + 1).expect("join");
    }
    let held = resident_bytes().saturating_sub(before) as f64 / run.size as f64;
    let ahead = block / 4;
    prepare(&mut crowd, model, one_call, usize::MAX, ahead);
    let clock = Instant::now();
    let cpu = process_cpu_ns(clock);
    let mut worst_frame = 0f64;
    for _ in 0..frames / run.chunk {
        let frame = Instant::now();
        prepare(&mut crowd, model, one_call, run.budget * run.size, ahead);
        let chunks = if one_call {
            crowd.next(&mut OneCallPerThread(model), run.chunk)
        } else {
            crowd.next(model, run.chunk)
        }
        .expect("next");
        std::hint::black_box(chunks);
        worst_frame = worst_frame.max(frame.elapsed().as_secs_f64());
    }
    let cpu_s = (process_cpu_ns(clock) - cpu) as f64 / 1e9;
    Figures {
        cpu_ms_per_character_second: 1e3 * cpu_s / (run.size as f64 * run.seconds),
        worst_frame_ms: 1e3 * worst_frame,
        worst_character_ms: None,
        bytes_per_character: held,
    }
}

fn main() {
    let path = common::model_argument();
    let sizes: Vec<usize> = std::env::var("SINMDM_CROWD_SIZES")
        .unwrap_or_else(|_| "1,8,64,512".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let way = std::env::var("SINMDM_CROWD_WAY").unwrap_or_else(|_| "both".into());
    let base = Run {
        size: 0,
        seconds: env_or("SINMDM_CROWD_SECONDS", 20.0),
        budget: env_or("SINMDM_CROWD_BUDGET", 4),
        free: std::env::var("SINMDM_CROWD_FREE").is_ok_and(|v| v == "1"),
        chunk: env_or("SINMDM_CROWD_CHUNK", 1usize).max(1),
        steps: env_or("SINMDM_CROWD_STEPS", sinmdm::DEFAULT_STREAM_STEPS),
    };
    let mut model = Model::open(&path, &ModelOptions { threads: Some(1) }).expect("model");
    let fps = model.metadata().layout.fps;
    println!(
        "{path}: {} s of {} walk per character at {fps} fps, {} steps per block, one thread, \
         prepare budget {} steps per character per frame",
        base.seconds,
        if base.free { "unsteered" } else { "steered" },
        base.steps,
        base.budget
    );
    println!(
        "| way | characters | CPU ms per character-second | characters per core at {fps} fps | \
         worst frame, whole crowd (ms) | worst frame, one character (ms) | memory per character (KiB) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for size in sizes {
        let run = Run { size, ..base };
        let ways: &[(&str, Way)] = match way.as_str() {
            "streams" => &[("streams", streams)],
            "crowd" => &[("crowd", crowd)],
            "crowd-one-call" => &[("crowd, one call", crowd_one_call)],
            _ => &[
                ("streams", streams),
                ("crowd", crowd),
                ("crowd, one call", crowd_one_call),
            ],
        };
        for (name, go) in ways {
            let f = go(&mut model, run);
            println!(
                "| {name} | {size} | {:.2} | {:.0} | {:.1} | {} | {:.0} |",
                f.cpu_ms_per_character_second,
                1e3 / f.cpu_ms_per_character_second,
                f.worst_frame_ms,
                f.worst_character_ms
                    .map_or("-".to_string(), |ms| format!("{ms:.1}")),
                f.bytes_per_character / 1024.0
            );
        }
    }
}
