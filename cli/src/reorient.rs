//! `sinmdm reorient`: rewrite a clip with another up axis and/or turned about its up axis.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;

use sinmdm::bvh::write_bvh;

use crate::clip_files::read_motion_file;
use sinmdm::motion::math;
use sinmdm::motion::up::{UP, UpAxis, reorient, reorient_problem};
use sinmdm::motion::up_detect::detect_up;

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm reorient zup_clip.bvh --to y -o yup_clip.bvh         # for a Y-up engine
  sinmdm reorient walk.bvh --to z -o walk_zup.bvh             # as a Z-up pipeline writes it
  sinmdm reorient walk.bvh --turn 90 -o walk_turned.bvh       # a quarter turn about up";

/// Arguments of `sinmdm reorient`.
#[derive(Debug, Args)]
pub struct ReorientArgs {
    /// The clip (.bvh, .glb, .gltf, .fbx).
    pub clip: PathBuf,
    /// The animation of a glTF clip to read, by name or index (default: the first).
    #[arg(long, value_name = "NAME|INDEX")]
    pub clip_anim: Option<String>,
    /// The BVH file to write (same joints, offsets and channel lists; the top joint's OFFSET,
    /// position and rotation turned).
    #[arg(short, long, value_name = "OUT.bvh")]
    pub output: PathBuf,
    /// The clip's up axis (default: read from the motion).
    #[arg(long, value_name = "AXIS")]
    pub up: Option<UpAxis>,
    /// The up axis of the written file (default: the clip's).
    #[arg(long, value_name = "AXIS")]
    pub to: Option<UpAxis>,
    /// Also turn the motion about its up axis by this many degrees (counter-clockwise seen from
    /// above).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub turn: f64,
}

pub(crate) fn run(args: &ReorientArgs) -> Result<()> {
    if !args.turn.is_finite() {
        bail!("--turn must be a number of degrees, got {}", args.turn);
    }
    let clip = read_motion_file(&args.clip, args.clip_anim.as_deref())?;
    if let Some(problem) = reorient_problem(&clip.skeleton) {
        bail!("{}: {problem}", args.clip.display());
    }
    let motion = clip.to_local();
    let from = match args.up {
        Some(up) => up,
        None => {
            let found = detect_up(&motion);
            eprintln!("{}: up axis {}", args.clip.display(), found.describe());
            found.axis
        }
    };
    let to = args.to.unwrap_or(from);
    let turn = math::axis_rotation(UP, args.turn.to_radians());
    let rotation = to.file_from_canonical() * (turn * from.canonical_from_file());
    write_bvh(&args.output, &reorient(&motion, &rotation).to_channels())?;
    eprintln!(
        "wrote {} ({from}-up -> {to}-up, turned {} degrees)",
        args.output.display(),
        args.turn
    );
    Ok(())
}
