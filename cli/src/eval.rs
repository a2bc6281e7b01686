//! `sinmdm eval`: samples a model and scores the samples against its training clip.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use ndarray::Axis;
use serde::Serialize;

use crate::sampling::{
    DEFAULT_STEPS, DEFAULT_STREAM_STEPS, check_writable, parse_steps, progress_bar,
    reference_features,
};
use sinmdm::features_file::write_features;
use sinmdm::files::write_atomically;
use sinmdm::{Feet, Generated, Request, Stream, StreamOptions, Task};
use sinmdm::{Model, ModelOptions};
use sinmdm_eval::{
    COVERAGE_WINDOW, FeetReport, KinematicReport, ModelEvaluation, REPLAY_TOLERANCE, ReplayReport,
    Report, evaluate_generated, evaluate_model,
};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm eval -m onnx-models/human_walk_cmu.onnx --clip tests/data/bvh/human_walk_cmu_131_01.bvh
  sinmdm eval -m walk.onnx --clip walk.bvh --samples 20 --steps all --json out/walk_eval.json
  sinmdm eval -m walk.onnx --clip walk.bvh --samples 3 --frames 1800 --stream   # 60 s streams

Samples are twice the clip's length by default, as in the published benchmark. The table is
Markdown, ready for a model card.";

/// Arguments of `sinmdm eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The trained model.
    #[arg(short, long, value_name = "MODEL.onnx")]
    model: PathBuf,
    /// The clip to score against: the model's training clip.
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    clip: PathBuf,
    #[command(flatten)]
    up: crate::clip_files::ClipUpArg,
    /// Samples to generate (one batched run).
    #[arg(long, default_value_t = 20)]
    samples: usize,
    /// Frames per sample (default: twice the clip).
    #[arg(long)]
    frames: Option<usize>,
    /// Denoising steps: a number S of respaced steps, or `all` (default: 50, or a stream's 20
    /// per block with --stream).
    #[arg(long, value_name = "S|all")]
    steps: Option<String>,
    /// Seed of the samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Root-mean-square difference per 6D component under which a sample frame counts as a
    /// verbatim copy of a clip frame, for the replay figure.
    #[arg(long, default_value_t = REPLAY_TOLERANCE, value_name = "RMS")]
    replay_tolerance: f64,
    /// Threads for the network and the metrics (default: every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Also write the scores (with every sample's) as JSON here.
    #[arg(long, value_name = "OUT.json")]
    json: Option<PathBuf>,
    /// Also write the samples' raw features as JSON here (to check the scores elsewhere).
    #[arg(long, value_name = "OUT.json")]
    features_json: Option<PathBuf>,
    #[command(flatten)]
    method: crate::sampling::MethodArgs,
    /// Make every sample as a stream (`sinmdm stream`, blocks of the training clip's length)
    /// instead of in one shot; sample i uses seed + i.
    #[arg(long)]
    stream: bool,
    /// Do not show the progress bar.
    #[arg(long)]
    quiet: bool,
    /// Dance instead of free generation when music is given (--music, --beats or --bpm; the
    /// clip is the reference): the scores then include the beat-hit rate and the Beat Align
    /// Score, each beside its random-phase control.
    #[command(flatten)]
    dance: crate::dance::DanceOptions,
    /// Steer every sample along a course instead of free generation (a heading-relative model;
    /// see `sinmdm steer`), and say how closely each followed it.
    #[command(flatten)]
    course: crate::steer::CourseArgs,
}

/// The JSON file `--json` writes.
#[derive(Debug, Serialize)]
struct EvalFile<'a> {
    format: &'static str,
    version: u32,
    model: String,
    clip: String,
    model_training_steps: u64,
    samples: usize,
    frames: usize,
    steps: String,
    sampler: String,
    seed: u64,
    sampling_seconds: f64,
    report: &'a Report,
    body_report: &'a Report,
    raw_motion_report: &'a Report,
    planted_report: &'a Report,
    feet: &'a FeetReport,
    kinematics: &'a KinematicReport,
    replay: &'a ReplayReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    beats: Option<sinmdm_eval::BeatScores>,
}

pub(crate) fn run(args: &EvalArgs) -> Result<()> {
    check_args(args)?;
    let default_steps = if args.stream {
        DEFAULT_STREAM_STEPS
    } else {
        DEFAULT_STEPS
    };
    let steps = parse_steps(args.steps.as_deref().unwrap_or(default_steps))?;
    let method = args.method.method()?;
    let mut model = Model::open(
        &args.model,
        &ModelOptions {
            threads: args.threads,
        },
    )?;
    let clip = reference_features(&model, &args.clip, &args.up)?;
    let clip_frames = clip.len_of(Axis(1));
    let frames = args.frames.unwrap_or(2 * clip_frames);
    if frames < COVERAGE_WINDOW {
        bail!("--frames must be at least {COVERAGE_WINDOW} (the coverage window), got {frames}");
    }
    let training = model.metadata().training.clone();
    note_another_clip(&training, &args.clip, clip_frames);
    let made = what_to_make(args, &model, &clip, frames)?;
    let sampling = Sampling {
        frames,
        steps,
        method,
        threads: args.threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        }),
    };
    let evaluation = sample_and_score(args, &mut model, &clip, &made, &sampling)?;
    let replay = if args.replay_tolerance == evaluation.replay.tolerance {
        evaluation.replay.clone()
    } else {
        ReplayReport::of_features(
            evaluation.generated.layout(),
            clip.view(),
            evaluation.generated.features.view(),
            args.replay_tolerance,
        )
    };
    if let Some(commands) = &made.commands {
        crate::steer::print_following(&evaluation.generated, model.metadata(), commands);
    }
    crate::steer::print_facing(&evaluation.generated, clip.view());
    println!(
        "model {} ({} training steps), clip {} ({} frames at {} fps)",
        args.model.display(),
        training.steps,
        args.clip.display(),
        clip_frames,
        evaluation.generated.layout().fps
    );
    println!(
        "{} samples x {} frames{}, {} {} steps, seed {}: sampled in {:.1} s, scored in {:.1} s",
        args.samples,
        frames,
        if args.stream { " (streamed)" } else { "" },
        steps_text(steps),
        method.name(),
        args.seed,
        evaluation.sampling_seconds,
        evaluation.scoring_seconds
    );
    print_reports(&evaluation, &replay);
    let beats = made.dance.as_ref().map(|dance| {
        let scores = dance.scores(&evaluation.planted, args.seed);
        println!();
        crate::dance::print_scores(&scores);
        sinmdm_eval::mean_beat_scores(&scores)
    });
    if let Some(path) = &args.features_json {
        let generated = &evaluation.generated;
        write_features(path, generated.layout(), generated.features.view())?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.json {
        write_json(
            path,
            args,
            &training,
            &sampling,
            &evaluation,
            &replay,
            beats,
        )?;
    }
    Ok(())
}

/// Says so when the clip scored against is not the one the model was trained on.
fn note_another_clip(training: &sinmdm::model_file::TrainingFacts, clip: &Path, frames: usize) {
    let trained_on = Path::new(&training.clip);
    if clip.file_name() != trained_on.file_name() || frames != training.clip_frames {
        eprintln!(
            "note: the model was trained on {} ({} frames); scoring against {} ({} frames)",
            training.clip,
            training.clip_frames,
            clip.display(),
            frames
        );
    }
}

/// The arguments no clip or model is needed to refuse.
fn check_args(args: &EvalArgs) -> Result<()> {
    if args.samples == 0 {
        bail!("--samples must be at least 1");
    }
    if !(args.replay_tolerance.is_finite() && args.replay_tolerance >= 0.0) {
        bail!(
            "--replay-tolerance must be a finite number >= 0, got {}",
            args.replay_tolerance
        );
    }
    if args.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    if args.stream && args.dance.has_music() {
        bail!("--stream and a dance's music (--music, --beats, --bpm) do not go together");
    }
    let outputs: Vec<PathBuf> = args
        .json
        .iter()
        .chain(args.features_json.iter())
        .cloned()
        .collect();
    check_writable(&outputs)
}

/// What the samples are asked to be: free motion, a dance to music, or a steered course.
struct WhatToMake {
    dance: Option<crate::dance::Dance>,
    commands: Option<Vec<sinmdm::steer::SteerFrame>>,
    task: Task,
}

/// The task of the samples, from the dance and course arguments.
fn what_to_make(
    args: &EvalArgs,
    model: &Model,
    clip: &ndarray::Array2<f32>,
    frames: usize,
) -> Result<WhatToMake> {
    let dance = if args.dance.has_music() {
        let dance = crate::dance::build_dance(
            &model.metadata().layout,
            clip.clone(),
            &args.dance,
            Some(frames),
            frames,
            args.seed,
        )?;
        dance.describe();
        if let Some(path) = &args.dance.beats_out {
            dance.write_beats(path)?;
        }
        Some(dance)
    } else {
        None
    };
    if args.course.given() && dance.is_some() {
        bail!("a steering course does not go with a dance's music");
    }
    let commands = if args.course.given() {
        Some(args.course.commands(model.metadata(), frames)?)
    } else {
        None
    };
    let task = match (&dance, &commands) {
        (Some(d), _) => d.task(),
        (None, Some(c)) => Task::Steer {
            frames,
            commands: c.clone(),
            ramp: sinmdm::tasks::INBETWEEN_RAMP,
        },
        (None, None) => Task::Generate { frames },
    };
    Ok(WhatToMake {
        dance,
        commands,
        task,
    })
}

/// How the samples are made: their length, steps, update rule and threads.
struct Sampling {
    frames: usize,
    steps: Option<usize>,
    method: sinmdm::Method,
    threads: usize,
}

/// The step count as the report and the JSON write it.
fn steps_text(steps: Option<usize>) -> String {
    steps.map_or("all".to_string(), |s| s.to_string())
}

/// Makes the samples, in one batched run or as streams, and scores them against the clip.
fn sample_and_score(
    args: &EvalArgs,
    model: &mut Model,
    clip: &ndarray::Array2<f32>,
    made: &WhatToMake,
    sampling: &Sampling,
) -> Result<ModelEvaluation> {
    let Sampling {
        frames,
        steps,
        method,
        threads,
    } = *sampling;
    // The run's step count comes with each progress call: the request is planned once, inside.
    let bar = progress_bar(
        args.quiet,
        0,
        format!("{} x {} frames", args.samples, frames),
    );
    let metadata = model.metadata().clone();
    let evaluation = if args.stream {
        let started = std::time::Instant::now();
        bar.set_length(args.samples as u64);
        let mut normalized =
            ndarray::Array3::<f32>::zeros((args.samples, metadata.network.features, frames));
        for i in 0..args.samples {
            let options = StreamOptions {
                seed: args.seed + i as u64,
                steps,
                feet: Feet::Raw,
                method,
                ..StreamOptions::default()
            };
            let mut stream = Stream::new(&metadata, options)?;
            if let Some(commands) = &made.commands {
                stream.steer(commands)?;
            }
            let chunk = stream.next(model, frames)?;
            for warning in stream.warnings() {
                eprintln!("warning: {warning}");
            }
            normalized
                .index_axis_mut(Axis(0), i)
                .assign(&metadata.normalizer.normalize(chunk.features.view()));
            bar.set_position(i as u64 + 1);
        }
        let generated = Generated::from_normalized(metadata.clone(), normalized);
        evaluate_generated(
            generated,
            clip.view(),
            threads,
            started.elapsed().as_secs_f64(),
        )
    } else {
        let request = Request {
            task: made.task.clone(),
            count: args.samples,
            seed: args.seed,
            steps,
            feet: Feet::Planted,
            method,
        };
        evaluate_model(
            model,
            &metadata,
            &request,
            clip.view(),
            threads,
            &mut |done, steps| {
                bar.set_length(steps as u64);
                bar.set_position(done as u64);
                ControlFlow::Continue(())
            },
        )
    }
    .with_context(|| format!("cannot score against {}", args.clip.display()))?;
    bar.finish_and_clear();
    Ok(evaluation)
}

/// The scores' tables: raw, body alone, planted, feet, kinematics and replay.
fn print_reports(evaluation: &ModelEvaluation, replay: &ReplayReport) {
    let ModelEvaluation {
        generated,
        report,
        body_report,
        raw_motion_report,
        planted_report,
        feet,
        kinematics,
        ..
    } = evaluation;
    println!();
    println!("samples as the network made them (--feet raw):");
    print!("{}", report.markdown_table());
    print_rarely_made(report, generated.layout().fps);
    println!(
        "the body alone (no root rotation, which the root layouts mean differently): coverage {:.1}, \
         global diversity {:.3}, local {:.3}, intra diversity diff {:.3} (clip's own {:.3})",
        body_report.coverage.mean,
        body_report.global_diversity.mean,
        body_report.local_diversity.mean,
        body_report.intra_diversity_diff,
        body_report.clip_intra_diversity
    );
    println!();
    println!("samples with their feet planted (the default output):");
    print!("{}", planted_report.markdown_table());
    println!();
    println!(
        "(planting's cost: coverage / global diversity {:.1} / {:.3} planted against {:.1} / {:.3} \
         for the raw motion as written, decoded and scored the same way)",
        planted_report.coverage.mean,
        planted_report.global_diversity.mean,
        raw_motion_report.coverage.mean,
        raw_motion_report.global_diversity.mean
    );
    println!();
    print!("{}", feet.markdown_table());
    println!();
    print_kinematics(kinematics);
    println!();
    print_replay(replay);
}

/// The replay line, with the floors the clip itself puts under it.
fn print_replay(replay: &ReplayReport) {
    print!(
        "replay: the samples' longest verbatim copies of the clip (frames within {} root-mean-square \
         per 6D component) last {:.2} s on average, {:.2} s at most",
        replay.tolerance, replay.mean_seconds, replay.max_seconds
    );
    // A clip that holds a pose still puts a floor under the figure: say how high.
    if replay.clip_hold_frames > 1 {
        print!(
            "; the clip itself holds one pose for {:.2} s, which a sample that holds it as long is \
             counted to copy",
            replay.clip_hold_seconds
        );
    }
    // So does a clip that looks alike both ways over a stretch (slow, or a move and its return):
    // the clip played backwards, not a copy, still matches it there. One frame is the least.
    if replay.clip_backwards_frames > 1 {
        print!(
            "; the clip played backwards (not a copy) scores {:.2} s",
            replay.clip_backwards_seconds
        );
    }
    println!();
}

/// Writes `--json`: the run's arguments and every score.
fn write_json(
    path: &Path,
    args: &EvalArgs,
    training: &sinmdm::model_file::TrainingFacts,
    sampling: &Sampling,
    evaluation: &ModelEvaluation,
    replay: &ReplayReport,
    beats: Option<sinmdm_eval::BeatScores>,
) -> Result<()> {
    let file = EvalFile {
        format: "sinmdm-eval",
        version: 1,
        model: args.model.display().to_string(),
        clip: args.clip.display().to_string(),
        model_training_steps: training.steps,
        samples: args.samples,
        frames: sampling.frames,
        steps: steps_text(sampling.steps),
        sampler: sampling.method.name(),
        seed: args.seed,
        sampling_seconds: evaluation.sampling_seconds,
        report: &evaluation.report,
        body_report: &evaluation.body_report,
        raw_motion_report: &evaluation.raw_motion_report,
        planted_report: &evaluation.planted_report,
        feet: &evaluation.feet,
        kinematics: &evaluation.kinematics,
        replay,
        beats,
    };
    let text = serde_json::to_string_pretty(&file)?;
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// How the samples move against the clip, and which bounds of the fidelity goals they miss.
fn print_kinematics(kinematics: &KinematicReport) {
    print!("{}", kinematics.markdown_table());
    let misses = kinematics.planted.misses(kinematics.clip.still_share);
    if misses.is_empty() {
        println!("the samples move like the clip: every bound of the fidelity goals is met");
    } else {
        let list: Vec<String> = misses.iter().map(ToString::to_string).collect();
        println!("the samples do not move like the clip: {}", list.join("; "));
    }
}

/// Share of the samples under which a stretch of the clip counts as rarely made, in percent.
const RARELY_MADE_BELOW: f64 = 50.0;

/// Names the stretches of the clip that fewer than half of the samples make: where the model
/// falls short of its clip, for a user to look at (or to clip out before training).
fn print_rarely_made(report: &Report, fps: f64) {
    let stretches = report.rarely_made(RARELY_MADE_BELOW);
    if stretches.is_empty() {
        println!(
            "every {COVERAGE_WINDOW}-frame window of the clip is made by at least {RARELY_MADE_BELOW}% of the samples"
        );
        return;
    }
    println!("stretches of the clip that fewer than {RARELY_MADE_BELOW}% of the samples make:");
    for stretch in stretches {
        let end = stretch.last_frame + 1;
        println!(
            "  frames {}:{end} ({:.2}-{:.2} s), the least-made window by {:.0}% of them",
            stretch.first_frame,
            stretch.first_frame as f64 / fps,
            end as f64 / fps,
            stretch.least_share
        );
    }
}
