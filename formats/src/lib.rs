//! # sinmdm-formats
//!
//! Motion files beyond the engine's BVH: glTF 2.0 (`.glb`, `.gltf`) read as clips and written
//! from generated motion, chosen by file extension. Kept out of the engine crate, which takes
//! and returns poses and stays free of file-format dependencies.

#![warn(missing_docs)]

pub mod error;
pub mod gltf;
mod sampled;
pub mod units;

use std::path::Path;

use sinmdm::motion::ChannelClip;

pub use error::{FormatError, Part};
pub use gltf::{AnimationChoice, AnimationInfo, GltfReadOptions, GltfWriteOptions};
pub use units::UnitGuess;

/// A motion file format, as its extension names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClipFormat {
    /// `.bvh`.
    Bvh,
    /// `.glb` or `.gltf`.
    Gltf,
}

impl ClipFormat {
    /// The format of `path` by its extension (case-insensitive), or an error that names what is
    /// read and, for FBX, the way round.
    pub fn of(path: &Path) -> Result<ClipFormat, FormatError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match extension.as_str() {
            "bvh" => Ok(ClipFormat::Bvh),
            "glb" | "gltf" => Ok(ClipFormat::Gltf),
            "fbx" => Err(FormatError::Unsupported {
                path: path.to_path_buf(),
                message: "FBX is not read yet; export the clip as glTF (.glb) or BVH from Blender or your DCC tool".into(),
            }),
            _ => Err(FormatError::Unsupported {
                path: path.to_path_buf(),
                message: "is not a motion file this reads (.bvh, .glb, .gltf)".into(),
            }),
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
}

/// Reads a clip from a `.bvh`, `.glb` or `.gltf` file. `options` choose the animation and the
/// frame rate of formats that hold keyframes rather than frames (BVH ignores them).
pub fn read_clip(
    path: &Path,
    options: &GltfReadOptions,
) -> Result<(ChannelClip, ClipSource), FormatError> {
    match ClipFormat::of(path)? {
        ClipFormat::Bvh => Ok((
            sinmdm::bvh::read_bvh(path)?,
            ClipSource {
                format: ClipFormat::Bvh,
                animation: None,
                animations: Vec::new(),
            },
        )),
        ClipFormat::Gltf => {
            let read = gltf::read_gltf(path, options)?;
            Ok((
                read.clip,
                ClipSource {
                    format: ClipFormat::Gltf,
                    animation: Some(read.animation),
                    animations: read.animations,
                },
            ))
        }
    }
}
