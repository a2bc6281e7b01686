//! New animations spliced into a character's own GLB file: its meshes, skin, materials and every
//! other part are kept byte for byte in the JSON (only the arrays the animations need grow, and
//! the binary buffer), and each motion becomes one more animation of its joints, matched by name.
//!
//! The motions' joint frames are related to the character's nodes in one of two ways, read from
//! the rest geometry:
//! - **the same frames**: the model was trained from this file (or one like it), so a joint's
//!   local rotation is the node's, and its offsets point where the node's children sit;
//! - **the bind pose is the clip's rest pose**: the character was made from the clip (a BVH
//!   imported into Blender, say), whose bones have their own rest rotations `B_j`; the node's
//!   global rotation is then the joint's global rotation times `B_j`.
//!
//! A character whose bones fit neither is refused, naming the first bone that does not. The
//! root's travel is scaled from the motions' units to the character's by the ratio of their
//! bone lengths.

use std::path::Path;

use serde_json::{Value, json};
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{LocalMotion, UpAxis, global_poses, up};

use super::container::{Asset, glb_bytes, parse_glb};
use super::nodes::{Similarity, node_name, node_trs, parents, uniform};
use super::write::{Binary, quaternion_xyzw, unit_f32};
use crate::error::{FormatError, Part};
use crate::sampled::without_namespace;

/// Largest angle, in radians, between a bone's direction in the motions' skeleton and in the
/// character's for the two to count as the same bone.
const DIRECTION_TOLERANCE: f64 = 0.02;

/// What a splice did.
#[derive(Debug, Clone, PartialEq)]
pub struct SpliceReport {
    /// Animations the character file had.
    pub kept_animations: usize,
    /// Animations added.
    pub added_animations: usize,
    /// Character units per unit of the motions.
    pub scale: f64,
    /// Whether the motions' joint frames are the character's (else its bind pose is their rest
    /// pose).
    pub same_frames: bool,
}

/// Each node's global rest transform (uniform scale only).
fn global_rest(
    path: &Path,
    nodes: &[Value],
    parent: &[Option<usize>],
) -> Result<Vec<Similarity>, FormatError> {
    let mut local = Vec::with_capacity(nodes.len());
    for n in 0..nodes.len() {
        let trs = node_trs(path, nodes, n)?;
        let scale = uniform(trs.scale).ok_or_else(|| {
            FormatError::bad(
                path,
                Part::Node(n, node_name(&nodes[n])),
                format!("has a non-uniform scale {:?}", trs.scale),
            )
        })?;
        local.push(Similarity {
            rotation: trs.rotation,
            translation: trs.translation,
            scale,
        });
    }
    let mut global: Vec<Option<Similarity>> = vec![None; nodes.len()];
    for start in 0..nodes.len() {
        let mut chain = vec![start];
        while let Some(p) = parent[*chain.last().expect("non-empty")] {
            if global[p].is_some() {
                break;
            }
            chain.push(p);
        }
        for &n in chain.iter().rev() {
            if global[n].is_none() {
                let above = parent[n]
                    .and_then(|p| global[p])
                    .unwrap_or(Similarity::IDENTITY);
                global[n] = Some(above.then(&local[n]));
            }
        }
    }
    Ok(global
        .into_iter()
        .map(|g| g.expect("every node visited"))
        .collect())
}

/// The angle between two vectors, in radians (0 when either is too short to have a direction).
fn angle(a: Vec3, b: Vec3) -> f64 {
    let (na, nb) = (a.norm(), b.norm());
    if na < 1e-12 || nb < 1e-12 {
        return 0.0;
    }
    (a.dot(b) / (na * nb)).clamp(-1.0, 1.0).acos()
}

/// Splices `motions` (one skeleton, in their file's frame with up axis `up`) into the character
/// file `character` (a `.glb`) as new animations, and writes the result to `path` (a `.glb`).
pub fn splice_into_character(
    character: &Path,
    path: &Path,
    motions: &[(String, &LocalMotion)],
    up_axis: UpAxis,
) -> Result<SpliceReport, FormatError> {
    let bytes = crate::files::read_file(character, crate::files::GLTF_LIMIT)?;
    if !super::container::is_glb(&bytes) {
        return Err(FormatError::Unsupported {
            path: character.to_path_buf(),
            message: "is not a .glb: the character file is read as binary glTF (.glb), whose mesh and skin travel in one file; export it as glTF Binary (.glb), e.g. from Blender (File > Export > glTF 2.0, Format: glTF Binary)".into(),
        });
    }
    let Asset { mut json, buffers } = parse_glb(character, &bytes)?;
    let bad = |part: Part, message: String| FormatError::bad(character, part, message);
    if buffers.len() > 1
        || json["buffers"]
            .get(0)
            .is_some_and(|b| b.get("uri").is_some())
    {
        return Err(bad(
            Part::Json,
            "keeps its data outside the GLB's binary chunk; re-export it as one .glb".into(),
        ));
    }
    let Some((_, first)) = motions.first() else {
        return Err(FormatError::Write {
            path: path.to_path_buf(),
            message: "no motion to write".into(),
        });
    };
    let skeleton = &first.skeleton;
    let nodes: Vec<Value> = json["nodes"].as_array().cloned().unwrap_or_default();
    let parent = parents(character, &nodes)?;
    let rest = global_rest(character, &nodes, &parent)?;

    // Our joints by name among the character's nodes: the same name, or else the one node whose
    // name is it after a namespace (a model read from Mixamo's FBX has `Hips` where the
    // character's GLB has `mixamorig:Hips`).
    let mapped: Vec<usize> = skeleton
        .joints
        .iter()
        .map(|joint| {
            let exact = nodes
                .iter()
                .position(|n| node_name(n).as_deref() == Some(joint.name.as_str()));
            let namespaced = || {
                let mut found = nodes.iter().enumerate().filter(|(_, n)| {
                    node_name(n).is_some_and(|name| without_namespace(&name) == joint.name)
                });
                match (found.next(), found.next()) {
                    (Some((index, _)), None) => Some(index),
                    _ => None,
                }
            };
            exact.or_else(namespaced).ok_or_else(|| {
                bad(
                    Part::Skeleton,
                    format!(
                        "has no node named '{}', a joint of the model's skeleton",
                        joint.name
                    ),
                )
            })
        })
        .collect::<Result<_, _>>()?;

    // Our rest pose in glTF's frame: identity rotations, the top joint turned to +Y up.
    let turn = up_axis.canonical_from_file();
    let mut our_rest: Vec<(Mat3, Vec3)> = Vec::with_capacity(skeleton.len());
    for joint in &skeleton.joints {
        let g = match joint.parent {
            None => (turn, (turn * joint.offset)),
            Some(p) => {
                let (r, t) = our_rest[p];
                (r, (t + (r * joint.offset)))
            }
        };
        our_rest.push(g);
    }
    // Bones (joint, parent): their length ratio, and which frame relation their directions fit.
    // Bones much shorter than the longest have no direction to compare (a joint on its
    // parent: a zero offset, or an exporter's rounding of one).
    let longest = skeleton
        .joints
        .iter()
        .map(|j| j.offset.norm())
        .fold(0.0, f64::max);
    let mut ratios = Vec::new();
    let mut same_frames = true;
    let mut bind_is_rest = true;
    let mut first_misfit = None;
    for (j, joint) in skeleton.joints.iter().enumerate() {
        let Some(p) = joint.parent else { continue };
        let ours_world = our_rest[j].1 - our_rest[p].1;
        let theirs_world = rest[mapped[j]].translation - rest[mapped[p]].translation;
        if ours_world.norm() <= 1e-3 * longest {
            continue;
        }
        ratios.push(theirs_world.norm() / ours_world.norm());
        // In the parent's frame: our offset, and the character's bone seen from the parent node.
        let parent_frame = rest[mapped[p]];
        let theirs_local = parent_frame.rotation.transpose() * theirs_world;
        let fits_local = angle(joint.offset, theirs_local) <= DIRECTION_TOLERANCE;
        let fits_world = angle(ours_world, theirs_world) <= DIRECTION_TOLERANCE;
        same_frames &= fits_local;
        bind_is_rest &= fits_world;
        if !fits_local && !fits_world && first_misfit.is_none() {
            first_misfit = Some(joint.name.clone());
        }
    }
    if !(same_frames || bind_is_rest) {
        return Err(bad(
            Part::Skeleton,
            format!(
                "is not the model's skeleton: bone '{}' points elsewhere (neither in its parent's frame nor in the bind pose)",
                first_misfit.unwrap_or_default()
            ),
        ));
    }
    ratios.sort_by(f64::total_cmp);
    let scale = ratios.get(ratios.len() / 2).copied().unwrap_or(1.0);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(bad(
            Part::Skeleton,
            format!("has bones of scale {scale} to the model's"),
        ));
    }
    // The constant turn from each joint's frame to its node's: identity, or the bind pose's.
    let offset_turn: Vec<Mat3> = (0..skeleton.len())
        .map(|j| {
            if same_frames {
                math::IDENTITY
            } else {
                our_rest[j].0.transpose() * rest[mapped[j]].rotation
            }
        })
        .collect();

    // The binary data goes after the character's, in its one buffer.
    let mut bin = buffers.into_iter().next().unwrap_or_default();
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap_or(0) as usize;
    bin.truncate(declared);
    let first_accessor = json["accessors"].as_array().map_or(0, Vec::len);
    let first_view = json["bufferViews"].as_array().map_or(0, Vec::len);
    let mut binary = Binary::after(bin, first_accessor, first_view);
    let kept_animations = json["animations"].as_array().map_or(0, Vec::len);
    let mut animations = Vec::with_capacity(motions.len());
    for (name, motion) in motions {
        if motion.skeleton != *skeleton {
            return Err(FormatError::Write {
                path: path.to_path_buf(),
                message: format!("motion '{name}' has another skeleton than the first"),
            });
        }
        animations.push(spliced_animation(
            &mut binary,
            name,
            motion,
            up_axis,
            scale,
            &mapped,
            &offset_turn,
            (&parent, &rest),
        ));
    }
    // Append: the arrays grow, nothing else of the document changes but the buffer's length.
    for (key, items) in [
        ("accessors", std::mem::take(&mut binary.accessors)),
        ("bufferViews", std::mem::take(&mut binary.views)),
        ("animations", animations),
    ] {
        match json[key].as_array_mut() {
            Some(array) => array.extend(items),
            None => json[key] = Value::Array(items),
        }
    }
    if json["buffers"].as_array().is_none_or(Vec::is_empty) {
        json["buffers"] = json!([{}]);
    }
    json["buffers"][0]["byteLength"] = json!(binary.bytes.len());
    let out = glb_bytes(&json, &binary.bytes);
    sinmdm::files::write_atomically(path, &out).map_err(|reason| FormatError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    Ok(SpliceReport {
        kept_animations,
        added_animations: motions.len(),
        scale,
        same_frames,
    })
}

/// One motion as an animation of the character's nodes: each mapped node's rotation (and the
/// root's translation, and that of joints with position channels) every frame.
#[allow(clippy::too_many_arguments)]
fn spliced_animation(
    binary: &mut Binary,
    name: &str,
    motion: &LocalMotion,
    up_axis: UpAxis,
    scale: f64,
    mapped: &[usize],
    offset_turn: &[Mat3],
    (parent, rest): (&[Option<usize>], &[Similarity]),
) -> Value {
    let mut canonical = up::to_canonical(motion, up_axis);
    for t in &mut canonical.translations {
        *t = *t * scale;
    }
    let poses = global_poses(&canonical);
    let frames = motion.frame_count();
    let input = binary.key_times(frames, motion.fps);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (j, joint) in motion.skeleton.joints.iter().enumerate() {
        let node = mapped[j];
        let moves = joint.parent.is_none() || !joint.position_axes().is_empty();
        let mut rotations = Vec::with_capacity(frames * 4);
        let mut translations = Vec::with_capacity(frames * 3);
        let (anchor, fixed) = parent_frame(node, parent, rest, mapped);
        let mut previous = None;
        for pose in &poses {
            let parent_global = match anchor {
                Some((k, p)) => Similarity {
                    rotation: (pose.rotations[k] * offset_turn[k]),
                    translation: pose.joints[k],
                    scale: rest[p].scale,
                }
                .then(&fixed),
                None => fixed,
            };
            let inverse_parent = parent_global.rotation.transpose();
            let global_rotation = pose.rotations[j] * offset_turn[j];
            let local_rotation = inverse_parent * global_rotation;
            let q = quaternion_xyzw(&local_rotation, previous);
            previous = Some(q);
            rotations.extend(unit_f32(q));
            if moves {
                let local = (inverse_parent * (pose.joints[j] - parent_global.translation))
                    * (1.0 / parent_global.scale);
                translations.extend(local.map(|v| v as f32));
            }
        }
        let output = binary.accessor(&rotations, "VEC4", 4, false);
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "rotation"}}),
        );
        if moves {
            let output = binary.accessor(&translations, "VEC3", 3, false);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": "translation"}}));
        }
    }
    json!({"name": name, "samplers": samplers, "channels": channels})
}

/// How the global transform of node `n`'s parent is had at any frame: the nearest mapped joint
/// above it (its index among the motion's joints, and its node) followed by the fixed rest
/// transforms of the nodes between; or, with no joint above, that parent's fixed global rest
/// transform.
fn parent_frame(
    n: usize,
    parent: &[Option<usize>],
    rest: &[Similarity],
    mapped: &[usize],
) -> (Option<(usize, usize)>, Similarity) {
    let mut chain: Vec<usize> = Vec::new();
    let mut at = parent[n];
    while let Some(p) = at {
        if let Some(k) = mapped.iter().position(|&m| m == p) {
            let fixed = chain.iter().rev().fold(Similarity::IDENTITY, |g, &c| {
                let above = rest[parent[c].expect("a node below a joint has a parent")];
                g.then(&relative(&above, &rest[c]))
            });
            return (Some((k, p)), fixed);
        }
        chain.push(p);
        at = parent[p];
    }
    let fixed = chain.first().map_or(Similarity::IDENTITY, |&c| rest[c]);
    (None, fixed)
}

/// `local` as a transform relative to `above` (both global): `above^-1 local`.
fn relative(above: &Similarity, local: &Similarity) -> Similarity {
    let inverse_rotation = above.rotation.transpose();
    Similarity {
        rotation: (inverse_rotation * local.rotation),
        translation: ((inverse_rotation * (local.translation - above.translation))
            * (1.0 / above.scale)),
        scale: local.scale / above.scale,
    }
}
