//! The clip a model learns: read, encoded, normalised, and fingerprinted; the noised batches
//! drawn from it ([`batch`]); how long its motion stays correlated ([`motion_span`]).

use std::path::Path;

use ndarray::Array2;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use sinmdm::model_file::ClipSourceFacts;
use sinmdm::motion::{
    ChannelClip, ContactConfig, EncodeOptions, FeatureLayout, Normalizer, RootLayout, encode,
};
use sinmdm_formats::{
    AnimationChoice, ClipFormat, FileAccess, ReadOptions, STILL_TOLERANCE, clip_moves,
    read_clip_with_access,
};

use crate::config::DataConfig;
use crate::error::TrainError;

pub mod batch;
pub mod motion_span;

/// What a trained model must remember about its clip (saved in every checkpoint, and later in
/// the ONNX metadata).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipFacts {
    /// File name of the clip.
    pub name: String,
    /// SHA-256 of the clip file, hex.
    pub sha256: String,
    /// Frames after resampling.
    pub frames: usize,
    /// Column layout and static skeleton data.
    pub layout: FeatureLayout,
    /// Per-feature mean and std of the clip.
    pub normalizer: Normalizer,
    /// The up axis used and where it came from (the detection's evidence, or the config).
    #[serde(default)]
    pub up: String,
    /// The clip is an in-place cycle (contacts measured against its treadmill).
    #[serde(default)]
    pub in_place: bool,
    /// What the file was, when not BVH: its format and the animation read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<ClipSourceFacts>,
    /// The root layout the features use and why (absent in runs made before it was recorded).
    #[serde(default)]
    pub root: String,
    /// What was left out of the file before encoding (a converter's bind pose in its first
    /// frame), and why; `None` when every frame was learned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dropped: Option<String>,
}

impl ClipFacts {
    /// The root layout the clip's features use.
    pub fn root_layout(&self) -> RootLayout {
        self.layout
            .root
            .as_ref()
            .map_or(RootLayout::World, |r| r.layout())
    }
}

/// A clip ready for training: its facts and normalised features `[F, N]`.
#[derive(Debug, Clone)]
pub struct ClipData {
    /// The facts a checkpoint keeps.
    pub facts: ClipFacts,
    /// Normalised features `[F, N]`.
    pub features: Array2<f32>,
}

/// Hex SHA-256 of bytes.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl ClipData {
    /// Reads (BVH, or glTF or FBX with `data.animation` choosing the animation), encodes and normalises
    /// `path`. Its length is checked against a network's field once the network is final
    /// ([`ClipData::check_length`]): the rule that reads the clip may change the field.
    pub fn load(path: &Path, data: &DataConfig) -> Result<ClipData, TrainError> {
        let format = ClipFormat::of(path)?;
        let bytes = sinmdm::files::read_regular_file(path, format.file_limit(), None).map_err(
            |source| TrainError::Io {
                what: "read the clip",
                path: path.to_path_buf(),
                reason: source,
            },
        )?;
        let (clip, source) = read_clip(path, format, &bytes, data)?;
        if !clip_moves(&clip) {
            return Err(TrainError::StillClip {
                path: path.to_path_buf(),
                what: "the clip".into(),
                tolerance: STILL_TOLERANCE,
            });
        }
        let options = EncodeOptions {
            fps: data.fps,
            contacts: ContactConfig {
                joints: data.contact_joints.clone(),
                speed_threshold: data.contact_speed,
                ..ContactConfig::default()
            },
            up: data.up,
            root: data.root_layout,
        };
        let encoded = encode(&clip, &options).map_err(|source| TrainError::Motion {
            path: path.to_path_buf(),
            reason: source,
        })?;
        let frames = encoded.features.ncols();
        let normalizer = Normalizer::fit(encoded.features.view(), data.std_floor as f32);
        let features = normalizer.normalize(encoded.features.view());
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let up = match &encoded.up_detection {
            Some(found) => format!("{} (read from the motion)", found.describe()),
            None => format!("{} (data.up in the config)", encoded.layout.up),
        };
        let root = describe_root(&encoded);
        let dropped = encoded.bind_pose.as_ref().map(|found| found.describe());
        Ok(ClipData {
            facts: ClipFacts {
                root,
                dropped,
                up,
                in_place: encoded.in_place,
                name,
                sha256: sha256_hex(&bytes),
                frames,
                layout: encoded.layout,
                normalizer,
                source,
            },
            features,
        })
    }

    /// An error naming the clip (its file `path`) when it is shorter than `receptive_field`, the
    /// frames the network sees at once at the clip's frame rate: no window of it would fill one.
    pub fn check_length(&self, path: &Path, receptive_field: usize) -> Result<(), TrainError> {
        let frames = self.features.ncols();
        if frames < receptive_field {
            return Err(TrainError::ClipTooShort {
                path: path.to_path_buf(),
                frames,
                fps: self.facts.layout.fps,
                receptive_field,
            });
        }
        Ok(())
    }
}

/// Reads `path` (its `bytes` already read) as `format`: the clip, and what the file was when not
/// BVH; rejects `data.animation` for a BVH file and a still glTF or FBX animation.
fn read_clip(
    path: &Path,
    format: ClipFormat,
    bytes: &[u8],
    data: &DataConfig,
) -> Result<(ChannelClip, Option<ClipSourceFacts>), TrainError> {
    let read_options = ReadOptions {
        animation: data.animation.as_deref().map(AnimationChoice::parse),
        fps: None,
    };
    let clip_and_source = match format {
        ClipFormat::Bvh => {
            if data.animation.is_some() {
                return Err(TrainError::Config {
                    path: path.to_path_buf(),
                    message: "data.animation (--clip-anim) picks an animation of a glTF or FBX clip; a BVH file holds one".into(),
                });
            }
            let text = String::from_utf8_lossy(bytes);
            (
                sinmdm::bvh::parse_bvh(&text, &path.display().to_string())?,
                None,
            )
        }
        format @ (ClipFormat::Gltf | ClipFormat::Fbx) => {
            let access = FileAccess {
                allow_outside_folder: data.allow_outside_folder,
            };
            let (clip, source) = read_clip_with_access(path, &read_options, access)?;
            let read = source
                .animation
                .expect("a glTF or FBX clip names its animation");
            if read.still == Some(true) {
                return Err(TrainError::StillClip {
                    path: path.to_path_buf(),
                    what: format!("animation {}", read.describe()),
                    tolerance: STILL_TOLERANCE,
                });
            }
            let facts = ClipSourceFacts {
                format: format.name().into(),
                animation: Some(read.name.unwrap_or_else(|| format!("#{}", read.index))),
                animations: source.animations.len(),
                file_unit_meters: source.file_unit_meters,
            };
            (clip, Some(facts))
        }
    };
    Ok(clip_and_source)
}

/// The root layout of `encoded` in words, with why it was chosen when the clip chose it
/// ([`RootLayout::Auto`]).
fn describe_root(encoded: &sinmdm::motion::EncodedClip) -> String {
    let asked = encoded.root_asked;
    let skeleton = &encoded.layout.skeleton;
    let heading = encoded
        .layout
        .root
        .as_ref()
        .and_then(|r| r.heading.as_ref());
    match (heading, &encoded.world_root_reason) {
        (Some(h), _) => format!(
            "heading-relative: facing across {} and {} (sides by {:?}){}",
            skeleton.joints[h.left].name,
            skeleton.joints[h.right].name,
            h.sides,
            if asked == RootLayout::Auto {
                ", chosen from the clip (data.root_layout auto)"
            } else {
                ""
            }
        ),
        (None, Some(why)) => format!(
            "world: ground displacement in world axes; the heading-relative root needs what this clip lacks: {why} (data.root_layout auto)"
        ),
        (None, None) => "world: ground displacement in world axes (data.root_layout world)".into(),
    }
}
