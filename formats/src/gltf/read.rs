//! glTF 2.0 to a clip: the skeleton is the skin's joints, the motion one of the file's
//! animations, evaluated frame by frame as the glTF specification says.
//!
//! - Joint order is depth-first from the skin's root joint, so parents precede children. A joint's
//!   parent is its nearest ancestor node among the skin's joints. Nodes above the root joint (an
//!   armature object, a unit scale) are folded into the root: their rotation and translation into
//!   its transform, their uniform scale into every translation, so joints keep unit scale.
//! - The animation is sampled at its frame rate (the median spacing of its keys, snapped to a
//!   whole rate, unless one is given) from its first key, `round(duration x fps) + 1` frames.
//!   LINEAR rotations are interpolated by slerp, CUBICSPLINE values by the spec's Hermite form
//!   (rotations renormalised), STEP holds the previous key; times outside a sampler's keys hold
//!   its first or last value. Joints the animation does not move keep their rest transform.
//! - A leaf joint that never moves (Blender's and Mixamo's end bones) becomes its parent's End
//!   Site when it is the parent's only child, so no features are spent on it. Files this crate
//!   wrote keep each joint's BVH channels and End Site in node `extras`, and read back with them.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::ChannelClip;
use sinmdm::motion::math::{self, Vec3};

use super::accessor::{field_usize, read_floats};
use super::container::{Asset, read_asset};
use super::nodes::{Similarity, Trs, node_name, node_trs, parents, rotation_of, unit_scale};
use super::skin::{SkinJoints, node_names, recorded_joints, skin_joints};
use super::tracks::{Property, Track, frame_rate, read_tracks};
use crate::animation::{AnimationInfo, ReadOptions, choose_and_sample};
use crate::error::{FormatError, Part};
use crate::files::FileAccess;
use crate::sampled::{SampledJoints, unique_names};

/// A clip read from a glTF file, with what the file held besides.
#[derive(Debug, Clone)]
pub struct GltfClip {
    /// The clip, in the file's frame (glTF: +Y up) and units (metres).
    pub clip: ChannelClip,
    /// The animation it was read from.
    pub animation: AnimationInfo,
    /// Every animation of the file.
    pub animations: Vec<AnimationInfo>,
}

/// The animations of the file, for choosing and listing.
fn animation_infos(asset: &Asset) -> Vec<AnimationInfo> {
    let Some(animations) = asset.json.get("animations").and_then(Value::as_array) else {
        return Vec::new();
    };
    animations
        .iter()
        .enumerate()
        .map(|(index, animation)| {
            let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
            for sampler in animation
                .get("samplers")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
            {
                if let Some(input) = field_usize(sampler, "input") {
                    let accessor = asset.json.get("accessors").and_then(|a| a.get(input));
                    let bound = |key: &str| {
                        accessor
                            .and_then(|a| a.get(key))
                            .and_then(|v| v.get(0))
                            .and_then(Value::as_f64)
                    };
                    match (bound("min"), bound("max")) {
                        (Some(lo), Some(hi)) => {
                            first = first.min(lo);
                            last = last.max(hi);
                        }
                        _ => {
                            if let Ok(times) = read_floats(asset, input, 1)
                                && let (Some(lo), Some(hi)) = (times.first(), times.last())
                            {
                                first = first.min(f64::from(*lo));
                                last = last.max(f64::from(*hi));
                            }
                        }
                    }
                }
            }
            AnimationInfo {
                index,
                name: node_name(animation),
                seconds: if last >= first { last - first } else { 0.0 },
                still: None,
            }
        })
        .collect()
}

/// The animations of a glTF file with their lengths (for `inspect`).
pub fn list_animations(path: &Path) -> Result<Vec<AnimationInfo>, FormatError> {
    Ok(animation_infos(&read_asset(path, FileAccess::default())?))
}

/// Each joint's local rotation and translation, frame by frame (`[frames][joints]`), from the
/// rest transforms and the tracks, with the nodes above each joint folded in.
fn sample_frames(
    path: &Path,
    nodes: &[Value],
    rest: &[Trs],
    skin: &SkinJoints,
    tracks: &[Track],
    (first, fps, frames): (f64, f64, usize),
) -> Result<(Vec<math::Mat3>, Vec<math::Vec3>), FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    let SkinJoints {
        order, pre, unit, ..
    } = skin;
    let unit = *unit;
    // Each joint's local transform, frame by frame.
    let joints = order.len();
    let mut rotations = Vec::with_capacity(frames * joints);
    let mut translations = Vec::with_capacity(frames * joints);
    for f in 0..frames {
        let t = first + f as f64 / fps;
        // A key this close to the frame's time is the frame's key (a thousandth of a frame, or
        // a few f32 ulps of t for long clips).
        let snap = 1e-3 / fps + 4.0 * f64::from(f32::EPSILON) * t.abs();
        for (j, &n) in order.iter().enumerate() {
            let mut translation = rest[n].translation;
            let mut rotation = rest[n].rotation;
            let mut scale = rest[n].scale;
            for track in tracks.iter().filter(|track| track.joint == j) {
                let v = track.sample(t, snap);
                match track.property {
                    Property::Translation => translation = Vec3::new(v[0], v[1], v[2]),
                    Property::Rotation => rotation = rotation_of(v),
                    Property::Scale => scale = Vec3::new(v[0], v[1], v[2]),
                }
            }
            if !unit_scale(scale) {
                return Err(bad(
                    Part::Node(n, node_name(&nodes[n])),
                    format!(
                        "is a joint with scale {scale:?} at {t:.3} s; joints must keep unit scale (fold a unit scale into a node above the root)"
                    ),
                ));
            }
            let local = pre[j].then(&Similarity {
                rotation,
                translation,
                scale: 1.0,
            });
            // Below the root, the nodes above it scale every translation.
            let factor = if j == 0 { 1.0 } else { unit };
            rotations.push(local.rotation);
            translations.push(local.translation * factor);
        }
    }

    Ok((rotations, translations))
}

/// Reads the clip of one animation of a `.glb` or `.gltf` file, its side-car buffers only from
/// its own folder.
pub fn read_gltf(path: &Path, options: &ReadOptions) -> Result<GltfClip, FormatError> {
    read_gltf_with_access(path, options, FileAccess::default())
}

/// [`read_gltf`], with `access` saying which side-car files may be read.
pub fn read_gltf_with_access(
    path: &Path,
    options: &ReadOptions,
    access: FileAccess,
) -> Result<GltfClip, FormatError> {
    let asset = read_asset(path, access)?;
    let nodes: &[Value] = asset
        .json
        .get("nodes")
        .and_then(Value::as_array)
        .map(Vec::as_slice)
        .unwrap_or(&[]);
    let parent = parents(path, nodes)?;
    let rest: Vec<Trs> = (0..nodes.len())
        .map(|n| node_trs(path, nodes, n))
        .collect::<Result<_, _>>()?;
    let skin = skin_joints(path, &asset.json, nodes, &parent, &rest)?;
    let mut animations = animation_infos(&asset);
    let sample = |chosen: usize| -> Result<ChannelClip, FormatError> {
        let part = Part::Animation(chosen, node_name(&asset.json["animations"][chosen]));
        let tracks = read_tracks(path, &asset, chosen, |n| skin.joint_of(n))?;
        let timing = frame_rate(path, part, &tracks, options.fps)?;
        let (_, fps, frames) = timing;
        crate::animation::check_sampled_size(path, skin.order.len(), frames, asset.bytes_read)?;
        let (rotations, translations) = sample_frames(path, nodes, &rest, &skin, &tracks, timing)?;
        // The joints' own transforms, with the nodes above each folded in.
        let rest_rotations = skin
            .order
            .iter()
            .zip(&skin.pre)
            .map(|(&n, pre)| pre.rotation * rest[n].rotation)
            .collect();
        let motion = SampledJoints {
            names: unique_names(node_names(nodes, &skin.order)),
            parents: skin.parents.clone(),
            recorded: recorded_joints(nodes, &skin),
            fps,
            frames,
            rotations,
            translations,
            rest_rotations,
        }
        .into_motion();
        Ok(motion.to_channels())
    };
    let (chosen, clip) = choose_and_sample(
        path,
        &mut animations,
        options,
        (Part::Json, "animation"),
        sample,
    )?;
    Ok(GltfClip {
        clip,
        animation: animations[chosen].clone(),
        animations,
    })
}
