//! # sinmdm-formats
//!
//! Motion files beyond the engine's BVH: glTF 2.0 (`.glb`, `.gltf`) read as clips and written
//! from generated motion, and FBX (`.fbx`, binary and ASCII) read as clips, chosen by file
//! extension. Kept out of the engine crate, which takes
//! and returns poses and stays free of file-format dependencies.

#![warn(missing_docs)]

pub mod animation;
pub mod error;
pub mod fbx;
pub mod files;
pub mod gltf;
pub mod retarget;
mod sampled;
pub use sinmdm::motion::units;

use std::path::Path;

use sinmdm::motion::ChannelClip;

pub use animation::{
    AnimationChoice, AnimationInfo, BYTES_PER_SPARSE_TRANSFORM, MAX_CLIP_FRAMES, MAX_JOINT_FRAMES,
    MAX_SPARSE_TRANSFORMS, ReadOptions, STILL_TOLERANCE, clip_moves,
};
pub use error::{FormatError, Part};
pub use files::FileAccess;
pub use gltf::GltfWriteOptions;
pub use units::UnitGuess;

/// A motion file format, as its extension names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClipFormat {
    /// `.bvh`.
    Bvh,
    /// `.glb` or `.gltf`.
    Gltf,
    /// `.fbx` (binary or ASCII).
    Fbx,
}

impl ClipFormat {
    /// The format's short name (`bvh`, `gltf`, `fbx`), as model files record it.
    pub fn name(self) -> &'static str {
        match self {
            ClipFormat::Bvh => "bvh",
            ClipFormat::Gltf => "gltf",
            ClipFormat::Fbx => "fbx",
        }
    }

    /// The format of `path` by its extension (case-insensitive), or an error that names what is
    /// read.
    pub fn of(path: &Path) -> Result<ClipFormat, FormatError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match extension.as_str() {
            "bvh" => Ok(ClipFormat::Bvh),
            "glb" | "gltf" => Ok(ClipFormat::Gltf),
            "fbx" => Ok(ClipFormat::Fbx),
            _ => Err(FormatError::Unsupported {
                path: path.to_path_buf(),
                message: "is not a motion file this reads (.bvh, .glb, .gltf, .fbx)".into(),
            }),
        }
    }
}

impl ClipFormat {
    /// The size limit of a file of this format, checked before it is read.
    pub fn file_limit(self) -> sinmdm::files::FileLimit {
        match self {
            ClipFormat::Bvh => sinmdm::bvh::BVH_LIMIT,
            ClipFormat::Gltf => files::GLTF_LIMIT,
            ClipFormat::Fbx => files::FBX_LIMIT,
        }
    }
}

/// Where a clip came from, beside its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipSource {
    /// The file's format.
    pub format: ClipFormat,
    /// The animation read, for formats that hold several.
    pub animation: Option<AnimationInfo>,
    /// Every animation of the file (empty for BVH).
    pub animations: Vec<AnimationInfo>,
    /// The length of the file's own unit in metres, where the format says (glTF: 1; FBX: its
    /// unit, 0.01 for centimetres), the clip then being read in metres. `None` for BVH, whose
    /// units are guessed from the skeleton.
    pub file_unit_meters: Option<f64>,
}

/// Reads a clip from a `.bvh`, `.glb`, `.gltf` or `.fbx` file. `options` choose the animation and the
/// frame rate of formats that hold keyframes rather than frames (BVH ignores them). A `.gltf`
/// file's side-car buffers are read only from its own folder.
pub fn read_clip(
    path: &Path,
    options: &ReadOptions,
) -> Result<(ChannelClip, ClipSource), FormatError> {
    read_clip_with_access(path, options, FileAccess::default())
}

/// [`read_clip`], with `access` saying which files besides `path` may be read.
pub fn read_clip_with_access(
    path: &Path,
    options: &ReadOptions,
    access: FileAccess,
) -> Result<(ChannelClip, ClipSource), FormatError> {
    match ClipFormat::of(path)? {
        ClipFormat::Bvh => Ok((
            sinmdm::bvh::read_bvh(path)?,
            ClipSource {
                format: ClipFormat::Bvh,
                animation: None,
                animations: Vec::new(),
                file_unit_meters: None,
            },
        )),
        ClipFormat::Gltf => {
            let read = gltf::read_gltf_with_access(path, options, access)?;
            Ok((
                read.clip,
                ClipSource {
                    format: ClipFormat::Gltf,
                    animation: Some(read.animation),
                    animations: read.animations,
                    file_unit_meters: Some(1.0),
                },
            ))
        }
        ClipFormat::Fbx => {
            let read = fbx::read_fbx(path, options)?;
            Ok((
                read.clip,
                ClipSource {
                    format: ClipFormat::Fbx,
                    animation: Some(read.animation),
                    animations: read.animations,
                    file_unit_meters: Some(read.file_unit_meters),
                },
            ))
        }
    }
}

/// The animations of a glTF or FBX file with their lengths, as `inspect` lists them (empty for
/// BVH, which holds one motion).
pub fn list_animations(path: &Path) -> Result<Vec<AnimationInfo>, FormatError> {
    match ClipFormat::of(path)? {
        ClipFormat::Bvh => Ok(Vec::new()),
        ClipFormat::Gltf => gltf::list_animations(path),
        ClipFormat::Fbx => fbx::list_fbx_animations(path),
    }
}

/// The format to write `path` in, or an error naming the way round for formats that are read
/// but not written (FBX).
pub fn writable_format(path: &Path) -> Result<ClipFormat, FormatError> {
    match ClipFormat::of(path)? {
        ClipFormat::Fbx => Err(FormatError::Unsupported {
            path: path.to_path_buf(),
            message: "FBX is read but not written: write .glb (Blender, Godot, Unity's glTFast, Unreal and three.js import it) or .bvh".into(),
        }),
        format => Ok(format),
    }
}
