//! `sinmdm render`, and the `--render` pictures of the generating subcommands.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};

use crate::clip_files::read_motion_file;
use sinmdm::files::write_atomically;
use sinmdm::motion::{Confidence, ContactConfig, detect_up};
use sinmdm_render::{Camera, Figure, RenderOptions, contact_sheet, gif_bytes};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm render tests/data/bvh/human_walk_cmu_131_01.bvh -o out/walk.gif
  sinmdm render out/crowd_000.bvh out/crowd_001.bvh out/crowd_002.bvh -o out/crowd.gif
  sinmdm render out/walk.bvh -o out/walk_sheet.png --sheet-frames 10 --camera fixed";

/// Camera choice on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum CameraArg {
    /// Centred on the root at every frame.
    Follow,
    /// Still, framing the whole path.
    Fixed,
}

/// Arguments of `sinmdm render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Clips (.bvh, .glb, .gltf, .fbx), drawn side by side.
    #[arg(required = true)]
    pub clips: Vec<PathBuf>,
    /// The picture: `.gif` (animated, at the clip's frame rate) or `.png` (a contact sheet).
    #[arg(short, long, value_name = "OUT.gif|OUT.png")]
    pub output: PathBuf,
    /// Camera.
    #[arg(long, value_enum, default_value = "follow")]
    pub camera: CameraArg,
    /// Panel size in pixels (square).
    #[arg(long, default_value_t = 320)]
    pub size: usize,
    /// Frames on a PNG contact sheet.
    #[arg(long, default_value_t = 8)]
    pub sheet_frames: usize,
    #[command(flatten)]
    pub up: crate::clip_files::ClipUpArg,
}

/// Writes `figures` as a GIF or PNG chosen by the extension of `path`.
pub fn write_picture(
    path: &Path,
    figures: &[Figure],
    camera: Camera,
    size: usize,
    sheet_frames: usize,
) -> Result<()> {
    if !(32..=2048).contains(&size) {
        bail!("--size must be between 32 and 2048 pixels, got {size}");
    }
    let options = RenderOptions {
        panel_width: size,
        panel_height: size,
        camera,
    };
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes = match ext.as_str() {
        "gif" => gif_bytes(figures, &options)?,
        "png" => contact_sheet(figures, sheet_frames, &options).to_png(),
        _ => bail!(
            "'{}': the picture must end in .gif (animation) or .png (contact sheet)",
            path.display()
        ),
    };
    write_atomically(path, &bytes).with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    let mut figures = Vec::new();
    for path in &args.clips {
        let clip = read_motion_file(path, args.up.clip_anim.as_deref())?;
        let label = path
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        let motion = clip.to_local();
        let up = match args.up.up {
            Some(up) => up,
            None => {
                let found = detect_up(&motion);
                if found.confidence == Confidence::Unsure {
                    eprintln!(
                        "{}: up axis {}; pass --up if the figure is not upright",
                        path.display(),
                        found.describe()
                    );
                }
                found.axis
            }
        };
        figures.push(Figure::new(
            &motion,
            up,
            label,
            ContactConfig::default().speed_threshold,
        ));
    }
    let camera = match args.camera {
        CameraArg::Follow => Camera::Follow,
        CameraArg::Fixed => Camera::Fixed,
    };
    write_picture(&args.output, &figures, camera, args.size, args.sheet_frames)
}
