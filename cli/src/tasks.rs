//! The generating subcommands: `generate`, `inbetween`, `expand`, `compose`, `harmonize`.

use std::path::{Path, PathBuf};

use ndarray::Array2;
use sinmdm::FeatureLayout;

use anyhow::Result;
use clap::Args;

use crate::clip_files::ClipUpArg;
use crate::sampling::{
    SamplingArgs, parse_position, parse_spans, reference_features, run_task, seconds_to_frames,
};
use sinmdm::tasks::{
    EXPAND_RAMP, HARMONIZE_FACTOR, HARMONIZE_FREE_SHARE, INBETWEEN_RAMP, Task, joints_by_name,
    subtree,
};

pub(crate) const GENERATE_EXAMPLES: &str = "Examples:
  sinmdm generate -m onnx-models/walk.onnx -o out/walk.bvh
  sinmdm generate -m onnx-models/walk.onnx --seconds 20 -o out/long.bvh
  sinmdm generate -m onnx-models/walk.onnx --count 8 --seed 7 -o out/crowd.bvh   # crowd_000..007.bvh
  sinmdm generate -m onnx-models/walk.onnx --steps all -o out/full.bvh           # all 1000 steps";

pub(crate) const INBETWEEN_EXAMPLES: &str = "Examples:
  sinmdm inbetween -m onnx-models/walk.onnx --reference walk.bvh --keep 0:60 --keep 180: -o out/inbetween.bvh
  sinmdm inbetween -m onnx-models/walk.onnx --reference walk.bvh --keep 0s:2s --keep 6s: -o out/ib.bvh --count 4";

pub(crate) const EXPAND_EXAMPLES: &str = "Examples:
  sinmdm expand -m onnx-models/walk.onnx --reference walk.bvh --prefix 2s --suffix 2s -o out/expanded.bvh
  sinmdm expand -m onnx-models/walk.onnx --reference walk.bvh --suffix 300 -o out/longer.bvh";

pub(crate) const COMPOSE_EXAMPLES: &str = "Examples:
  sinmdm compose -m onnx-models/walk.onnx --reference walk.bvh --part LeftUpLeg --part RightUpLeg --root -o out/new_upper_body.bvh
  sinmdm compose -m onnx-models/walk.onnx --reference walk.bvh --joints Head,Neck --frames 0:120 -o out/c.bvh";

pub(crate) const HARMONIZE_EXAMPLES: &str = "Examples:
  sinmdm harmonize -m onnx-models/hop.onnx --content walk.bvh -o out/walk_in_hop_style.bvh
  sinmdm harmonize -m onnx-models/hop.onnx --content walk.bvh --factor 4 --free-share 0.05 -o out/t.bvh";

/// Arguments of `sinmdm generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Frames per sample (default: twice the training clip).
    #[arg(long, conflicts_with = "seconds")]
    frames: Option<usize>,
    /// Length per sample in seconds, at the model's frame rate.
    #[arg(long)]
    seconds: Option<f64>,
}

/// Arguments of `sinmdm inbetween`.
#[derive(Debug, Args)]
pub struct InbetweenArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The clip whose spans are kept (same skeleton as the model).
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    reference: PathBuf,
    #[command(flatten)]
    up: ClipUpArg,
    /// A span of the reference to keep, START:END (END exclusive; empty END = the end), in frames
    /// or seconds (`2s`). Repeat for several; the gaps between them are generated.
    #[arg(long, required = true, value_name = "START:END")]
    keep: Vec<String>,
    /// Soft border inside each kept span, in frames.
    #[arg(long, default_value_t = INBETWEEN_RAMP)]
    ramp: usize,
}

/// Arguments of `sinmdm expand`.
#[derive(Debug, Args)]
pub struct ExpandArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The clip to expand (same skeleton as the model).
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    reference: PathBuf,
    #[command(flatten)]
    up: ClipUpArg,
    /// New motion before the clip, in frames or seconds (`2s`).
    #[arg(long, default_value = "0")]
    prefix: String,
    /// New motion after the clip, in frames or seconds (`2s`).
    #[arg(long, default_value = "0")]
    suffix: String,
    /// Soft border inside the clip, in frames.
    #[arg(long, default_value_t = EXPAND_RAMP)]
    ramp: usize,
}

/// Arguments of `sinmdm compose`.
#[derive(Debug, Args)]
pub struct ComposeArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The clip the chosen joints come from (same skeleton as the model).
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    reference: PathBuf,
    #[command(flatten)]
    up: ClipUpArg,
    /// Joints taken from the reference, comma-separated names.
    #[arg(long, value_delimiter = ',')]
    joints: Vec<String>,
    /// A body part taken from the reference: the named joint and every joint below it
    /// (e.g. `LeftUpLeg` for the left leg, `Spine` for the upper body). Repeat for several.
    #[arg(long, value_name = "JOINT")]
    part: Vec<String>,
    /// Take the root's travel and height from the reference.
    #[arg(long)]
    root: bool,
    /// Frame spans where the reference is kept, START:END in frames or seconds (default: all).
    #[arg(long, value_name = "START:END")]
    frames: Vec<String>,
    /// Soft border at the ends of --frames spans, in frames.
    #[arg(long, default_value_t = INBETWEEN_RAMP)]
    ramp: usize,
}

/// Arguments of `sinmdm harmonize`.
#[derive(Debug, Args)]
pub struct HarmonizeArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The content clip (same skeleton as the model, which was trained on the style clip).
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    content: PathBuf,
    #[command(flatten)]
    up: ClipUpArg,
    /// Down-sampling factor of the low-pass that carries the content.
    #[arg(long, default_value_t = HARMONIZE_FACTOR)]
    factor: usize,
    /// Share of the final steps run without the content's low frequencies.
    #[arg(long, default_value_t = HARMONIZE_FREE_SHARE)]
    free_share: f64,
}

pub(crate) fn generate(args: &GenerateArgs) -> Result<()> {
    let mut model = args.sampling.open_model()?;
    let meta = model.metadata();
    let frames = match (args.frames, args.seconds) {
        (Some(f), _) => f,
        (None, Some(s)) => seconds_to_frames(s, meta.layout.fps)?,
        (None, None) => 2 * meta.training.clip_frames,
    };
    run_task(&args.sampling, &mut model, Task::Generate { frames })?;
    Ok(())
}

/// The tasks that start from a clip: opens the model, reads `clip` in its layout, builds the
/// task from the layout and the clip's features, and runs it.
fn run_from_clip(
    sampling: &SamplingArgs,
    clip: &Path,
    read: &ClipUpArg,
    task: impl FnOnce(&FeatureLayout, Array2<f32>) -> Result<Task>,
) -> Result<()> {
    let mut model = sampling.open_model()?;
    let features = reference_features(&model, clip, read)?;
    let task = task(&model.metadata().layout, features)?;
    run_task(sampling, &mut model, task)?;
    Ok(())
}

pub(crate) fn inbetween(args: &InbetweenArgs) -> Result<()> {
    run_from_clip(
        &args.sampling,
        &args.reference,
        &args.up,
        |layout, reference| {
            Ok(Task::Inbetween {
                keep: parse_spans(&args.keep, layout.fps, reference.ncols())?,
                reference,
                ramp: args.ramp,
            })
        },
    )
}

pub(crate) fn expand(args: &ExpandArgs) -> Result<()> {
    run_from_clip(
        &args.sampling,
        &args.reference,
        &args.up,
        |layout, reference| {
            Ok(Task::Expand {
                reference,
                prefix: parse_position(&args.prefix, layout.fps)?,
                suffix: parse_position(&args.suffix, layout.fps)?,
                ramp: args.ramp,
            })
        },
    )
}

pub(crate) fn compose(args: &ComposeArgs) -> Result<()> {
    run_from_clip(
        &args.sampling,
        &args.reference,
        &args.up,
        |layout, reference| {
            let mut joints = joints_by_name(layout, &args.joints)?;
            for top in joints_by_name(layout, &args.part)? {
                joints.extend(subtree(layout, top));
            }
            Ok(Task::Compose {
                spans: parse_spans(&args.frames, layout.fps, reference.ncols())?,
                reference,
                joints,
                root: args.root,
                ramp: args.ramp,
            })
        },
    )
}

pub(crate) fn harmonize(args: &HarmonizeArgs) -> Result<()> {
    run_from_clip(&args.sampling, &args.content, &args.up, |_, content| {
        Ok(Task::Harmonize {
            content,
            factor: args.factor,
            free_share: args.free_share,
        })
    })
}
