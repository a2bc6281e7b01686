//! `sinmdm stream`: endless motion written chunk by chunk, as a game would pull it.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use ndarray::{Array2, s};

use sinmdm::bvh::BvhStreamWriter;
use sinmdm::features_file::write_features;
use sinmdm::tasks::INBETWEEN_RAMP;
use sinmdm::{Model, ModelOptions, Stream, StreamOptions};

use crate::sampling::{
    DEFAULT_STREAM_STEPS, FeetArg, check_writable, parse_position, parse_steps, progress_bar,
};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm stream -m onnx-models/human_walk_cmu.onnx --seconds 600 -o out/ten_minutes.bvh
  sinmdm stream -m onnx-models/human_walk_cmu.onnx --seconds 60 --chunk 0.5s --seed 3 -o out/minute.bvh
  sinmdm stream -m onnx-models/human_zombie_walk_fair.onnx --seconds 60 --circle 3 -o out/round.bvh";

/// Arguments of `sinmdm stream`.
#[derive(Debug, Args)]
pub struct StreamArgs {
    /// The trained model (.onnx written by sinmdm-export).
    #[arg(short, long, value_name = "MODEL.onnx")]
    model: PathBuf,
    /// Output BVH file, written chunk by chunk (it takes its name once complete).
    #[arg(short, long, value_name = "OUT.bvh")]
    output: PathBuf,
    /// Length in seconds.
    #[arg(long, conflicts_with = "frames")]
    seconds: Option<f64>,
    /// Length in frames.
    #[arg(long)]
    frames: Option<usize>,
    /// Frames asked of the stream at a time, in frames or seconds (`1s`); the motion is the
    /// same whatever the chunk size.
    #[arg(long, default_value = "1s")]
    chunk: String,
    /// Frames each block makes final, in frames or seconds (the motion depends on it; default:
    /// the training clip's length).
    #[arg(long)]
    block: Option<String>,
    /// Seed of the noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Denoising steps per block: a number of respaced steps, or `all` (default: 20, fewer than
    /// a one-shot run's 50: a block continues the context it is conditioned on).
    #[arg(long, default_value = DEFAULT_STREAM_STEPS, value_name = "S|all")]
    steps: String,
    #[command(flatten)]
    method: crate::sampling::MethodArgs,
    /// Feet: planted (held during contact, nothing below the ground) or raw.
    #[arg(long, value_enum, default_value_t = FeetArg::Planted)]
    feet: FeetArg,
    /// Threads for the network (default: every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Steer the stream along a course (a heading-relative model; see `sinmdm steer`): its
    /// commands are given to the stream ahead of time, all at once.
    #[command(flatten)]
    course: crate::steer::CourseArgs,
    /// Also write the raw features of the whole stream as JSON here (for the Python reference).
    #[arg(long, value_name = "OUT.json")]
    features_json: Option<PathBuf>,
    /// Do not show the progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Runs `sinmdm stream`.
pub fn run(args: &StreamArgs) -> Result<()> {
    if args.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    let mut model = Model::open(
        &args.model,
        &ModelOptions {
            threads: args.threads,
        },
    )?;
    let fps = model.fps();
    let total = match (args.frames, args.seconds) {
        (Some(f), _) => f,
        (None, Some(s)) if s.is_finite() && s > 0.0 => (s * fps).round() as usize,
        (None, Some(s)) => bail!("--seconds must be a positive number, got {s}"),
        (None, None) => bail!("give the length with --seconds or --frames"),
    };
    if total == 0 {
        bail!("the stream must have at least one frame");
    }
    let chunk = parse_position(&args.chunk, fps).context("--chunk")?;
    if chunk == 0 {
        bail!("--chunk must be at least one frame");
    }
    let block = match &args.block {
        Some(b) => Some(parse_position(b, fps).context("--block")?),
        None => None,
    };
    let options = StreamOptions {
        seed: args.seed,
        steps: parse_steps(&args.steps)?,
        block_frames: block,
        context_frames: None,
        ramp: INBETWEEN_RAMP,
        feet: args.feet.into(),
        compose: None,
        method: args.method.method()?,
    };
    let mut stream = Stream::new(model.metadata(), options)?;
    if args.course.given() {
        let commands = args.course.commands(model.metadata(), total)?;
        stream.steer(&commands)?;
    }
    let mut outputs = vec![args.output.clone()];
    outputs.extend(args.features_json.iter().cloned());
    check_writable(&outputs)?;
    let mut writer = BvhStreamWriter::create(&args.output, model.skeleton(), fps, total)?;
    let mut features = args
        .features_json
        .as_ref()
        .map(|_| Array2::<f32>::zeros((model.features(), total)));
    let bar = progress_bar(
        args.quiet,
        total,
        format!(
            "{total} frames in chunks of {chunk}, blocks of {}",
            stream.sizes().block
        ),
    );
    let started = Instant::now();
    let mut made = 0;
    while made < total {
        let n = chunk.min(total - made);
        let out = stream.next(&mut model, n)?;
        writer.append(&out.motion)?;
        if let Some(all) = features.as_mut() {
            all.slice_mut(s![.., made..made + n]).assign(&out.features);
        }
        made += n;
        bar.set_position(made as u64);
    }
    bar.finish_and_clear();
    for warning in stream.warnings() {
        eprintln!("warning: {warning}");
    }
    writer.finish()?;
    let seconds = started.elapsed().as_secs_f64();
    eprintln!(
        "wrote {} ({total} frames, {:.1} s of motion in {seconds:.1} s: {:.1}x real time)",
        args.output.display(),
        total as f64 / fps,
        total as f64 / fps / seconds.max(1e-9)
    );
    if let (Some(path), Some(all)) = (&args.features_json, &features) {
        write_features(
            path,
            &model.metadata().layout,
            all.view().insert_axis(ndarray::Axis(0)),
        )?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
