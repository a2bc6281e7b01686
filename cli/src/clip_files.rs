//! Motion files in and out by extension (through `sinmdm-formats`): `.bvh`, `.glb` and `.gltf`
//! in and out, `.fbx` in.

use std::path::Path;
use std::sync::OnceLock;

use anyhow::{Context, Result};
use clap::Args;
use sinmdm::bvh::to_bvh_string;
use sinmdm::files::write_atomically;
use sinmdm::motion::{ChannelClip, LocalMotion, UpAxis};
use sinmdm_formats::{
    AnimationChoice, ClipFormat, FileAccess, GltfWriteOptions, ReadOptions, UnitGuess,
    read_clip_with_access, writable_format,
};

/// Which files besides those named the command may read, set once from the command line
/// (`--allow-outside-folder`) for every clip it reads.
static FILE_ACCESS: OnceLock<FileAccess> = OnceLock::new();

/// Sets the file access of every clip read from now on; the first call wins.
pub fn set_file_access(access: FileAccess) {
    let _ = FILE_ACCESS.set(access);
}

/// The file access of clips read: set from the command line, else the strict default.
pub fn file_access() -> FileAccess {
    FILE_ACCESS.get().copied().unwrap_or_default()
}

/// Reads a clip from a `.bvh`, `.glb`, `.gltf` or `.fbx` file; `animation` picks one of a glTF
/// or FBX file's animations by name or index (default: the first), and which one was read is said when the
/// file holds several.
pub fn read_motion_file(path: &Path, animation: Option<&str>) -> Result<ChannelClip> {
    Ok(read_motion_file_and_source(path, animation)?.0)
}

/// [`read_motion_file`], with what the file held besides (its animations), read in the same
/// pass.
pub fn read_motion_file_and_source(
    path: &Path,
    animation: Option<&str>,
) -> Result<(ChannelClip, sinmdm_formats::ClipSource)> {
    let options = ReadOptions {
        animation: animation.map(AnimationChoice::parse),
        fps: None,
    };
    if animation.is_some() && ClipFormat::of(path)? == ClipFormat::Bvh {
        anyhow::bail!(
            "{}: --clip-anim picks an animation of a glTF or FBX file; a BVH file holds one",
            path.display()
        );
    }
    let (clip, source) = read_clip_with_access(path, &options, file_access())?;
    if let Some(read) = &source.animation
        && source.animations.len() > 1
    {
        eprintln!(
            "{}: read animation {} ({:.2} s), one of {}; --clip-anim NAME|INDEX picks another",
            path.display(),
            describe_animation(read),
            read.seconds,
            source.animations.len()
        );
    }
    Ok((clip, source))
}

/// `'Walk' (#0)` or `#0`.
pub fn describe_animation(info: &sinmdm_formats::AnimationInfo) -> String {
    info.describe()
}

/// Whether `path` names a glTF file, which holds every sample of a run as one animation each.
pub fn is_gltf(path: &Path) -> bool {
    matches!(ClipFormat::of(path), Ok(ClipFormat::Gltf))
}

/// Checks that motion can be written to `path` (BVH or glTF; FBX is read only).
pub fn check_output(path: &Path) -> Result<ClipFormat> {
    Ok(writable_format(path)?)
}

/// Metres per file unit for a glTF output: `explicit`, or the guess from the skeleton's height
/// in file units (said when it is only a guess).
pub fn metres_per_unit(height: f64, explicit: Option<f64>) -> Result<f64> {
    if let Some(scale) = explicit {
        anyhow::ensure!(
            scale.is_finite() && scale > 0.0,
            "--unit-scale must be a positive number of metres per file unit, got {scale}"
        );
        return Ok(scale);
    }
    let guess = UnitGuess::from_height(height);
    if !guess.is_sure() {
        eprintln!(
            "note: the figure is {height:.3} file units tall; units {}, so one unit = {:.4} m in the glTF file (--unit-scale METRES overrides)",
            guess.describe(),
            guess.metres_per_unit()
        );
    }
    Ok(guess.metres_per_unit())
}

/// Each motion with its animation name in a glTF file: `sample_000`, `sample_001`, ...
pub fn named_samples(motions: &[LocalMotion]) -> Vec<(String, &LocalMotion)> {
    motions
        .iter()
        .enumerate()
        .map(|(i, m)| (format!("sample_{i:03}"), m))
        .collect()
}

/// How motions go into a glTF file: their up axis, metres per unit, and whether to add the
/// proxy mesh.
#[derive(Debug, Clone, Copy)]
pub struct GltfPlacement {
    /// The motions' up axis.
    pub up: UpAxis,
    /// Metres per unit.
    pub metres: f64,
    /// Add a one-triangle mesh skinned to the root.
    pub proxy_mesh: bool,
}

impl GltfPlacement {
    /// For BVH output, where none of it applies.
    pub const NONE: GltfPlacement = GltfPlacement {
        up: UpAxis::PosY,
        metres: 1.0,
        proxy_mesh: false,
    };
}

/// Writes motions to `path`: glTF (`.glb`/`.gltf`) takes all of them, one animation each named
/// `sample_000`, ... (or `name` when there is one motion); BVH takes one.
pub fn write_motion_file(
    path: &Path,
    motions: &[LocalMotion],
    name: Option<&str>,
    placement: GltfPlacement,
) -> Result<()> {
    if is_gltf(path) {
        let named = match (name, motions) {
            (Some(name), [motion]) => vec![(name.to_string(), motion)],
            _ => named_samples(motions),
        };
        let options = GltfWriteOptions {
            up: placement.up,
            metres_per_unit: placement.metres,
            proxy_mesh: placement.proxy_mesh,
        };
        sinmdm_formats::gltf::write_gltf(path, &named, &options)?;
        return Ok(());
    }
    check_output(path)?;
    anyhow::ensure!(
        !placement.proxy_mesh,
        "{}: --proxy-mesh is for glTF output; BVH has no meshes",
        path.display()
    );
    let [motion] = motions else {
        anyhow::bail!(
            "{}: a BVH file holds one motion, {} were given",
            path.display(),
            motions.len()
        );
    };
    write_atomically(path, to_bvh_string(&motion.to_channels()).as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// `--up`: the up axis of a clip the command reads.
#[derive(Debug, Clone, Args)]
pub struct ClipUpArg {
    /// The clip's up axis: x, y, z, -x, -y or -z (default: read from the motion; for a
    /// reference or content clip, the model's own when the motion does not say clearly).
    #[arg(long, value_name = "AXIS")]
    pub up: Option<UpAxis>,
    /// The animation of a glTF clip (or stack of an FBX clip) to read, by name or index (default:
    /// the first that moves).
    #[arg(long, value_name = "NAME|INDEX")]
    pub clip_anim: Option<String>,
}
