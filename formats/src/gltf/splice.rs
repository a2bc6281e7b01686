//! New animations spliced into a character's own GLB file: its meshes, skin, materials and every
//! other part are kept byte for byte in the JSON (only the arrays the animations need grow, and
//! the binary buffer), and each motion becomes one more animation of the character's bones.
//! Which bone follows which joint, and how, is the [`super::drive`] module's.

use std::path::Path;

use serde_json::{Value, json};
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{LocalMotion, Skeleton, UpAxis};

use super::animate::{retargeted_animation, spliced_animation};
use super::container::{Asset, glb_bytes, parse_glb};
use super::drive::{Drive, Pairing, Retargeted, by_frames, model_rest, retargeted};
use super::nodes::{Similarity, node_name, node_trs, parents, uniform};
use super::write::Binary;
use crate::error::{FormatError, Part};
use crate::retarget::bone_map::{check_chains, pairs_by_name, pairs_by_role};
use crate::retarget::{BoneMatch, Rig};

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
    /// pose, or the motion was retargeted).
    pub same_frames: bool,
    /// What retargeting did, when the character is not the model's rig.
    pub retargeted: Option<Retargeted>,
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

/// Splices `motions` (one skeleton, in their file's frame with up axis `up`) into the character
/// file `character` (a `.glb`) as new animations, and writes the result to `path` (a `.glb`).
/// The names of a character file's bones: its skins' joints, or every node when it has no
/// skin; for saying which naming convention it follows.
pub fn character_bones(path: &Path) -> Result<Vec<String>, FormatError> {
    let asset = super::container::read_asset(path, crate::FileAccess::default())?;
    let nodes: Vec<Value> = asset.json["nodes"].as_array().cloned().unwrap_or_default();
    let mut joints: Vec<usize> = asset.json["skins"]
        .as_array()
        .into_iter()
        .flatten()
        .flat_map(|skin| skin["joints"].as_array().cloned().unwrap_or_default())
        .filter_map(|j| j.as_u64().map(|j| j as usize))
        .filter(|&j| j < nodes.len())
        .collect();
    joints.sort_unstable();
    joints.dedup();
    if joints.is_empty() {
        joints = (0..nodes.len()).collect();
    }
    Ok(joints
        .into_iter()
        .map(|n| node_name(&nodes[n]).unwrap_or_else(|| format!("node {n}")))
        .collect())
}

/// Bones are matched by name; see [`splice_retargeted`].
pub fn splice_into_character(
    character: &Path,
    path: &Path,
    motions: &[(String, &LocalMotion)],
    up_axis: UpAxis,
) -> Result<SpliceReport, FormatError> {
    splice_retargeted(character, path, motions, up_axis, &BoneMatch::Names)
}

/// Splices `motions` into `character` as [`splice_into_character`] does, its bones matched to
/// the motions' joints as `bones` says: a character that is not the model's rig (other rest
/// pose, proportions or names) has the motion retargeted onto it.
pub fn splice_retargeted(
    character: &Path,
    path: &Path,
    motions: &[(String, &LocalMotion)],
    up_axis: UpAxis,
    bones: &BoneMatch,
) -> Result<SpliceReport, FormatError> {
    let (mut json, buffers) = read_character(character)?;
    let bad = |part: Part, message: String| FormatError::bad(character, part, message);
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

    let target_names: Vec<String> = nodes
        .iter()
        .enumerate()
        .map(|(n, node)| node_name(node).unwrap_or_else(|| format!("node {n}")))
        .collect();
    let source_names: Vec<String> = skeleton.joints.iter().map(|j| j.name.clone()).collect();
    let source_parents: Vec<Option<usize>> = skeleton.joints.iter().map(|j| j.parent).collect();
    let target = Rig {
        names: &target_names,
        parents: &parent,
    };
    let source = Rig {
        names: &source_names,
        parents: &source_parents,
    };
    let model = model_rest(skeleton, up_axis);
    let drive = character_drive(
        character,
        bones,
        skeleton,
        (&target, &source),
        (&model, &rest),
    )?;
    let scale = drive.scale;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(bad(
            Part::Skeleton,
            format!("has bones of scale {scale} to the model's"),
        ));
    }

    // The binary data goes after the character's, in its one buffer.
    let mut bin = buffers.into_iter().next().unwrap_or_default();
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap_or(0) as usize;
    bin.truncate(declared);
    let first_accessor = json["accessors"].as_array().map_or(0, Vec::len);
    let first_view = json["bufferViews"].as_array().map_or(0, Vec::len);
    let mut binary = Binary::after(bin, first_accessor, first_view);
    let kept_animations = json["animations"].as_array().map_or(0, Vec::len);
    let mut planted_feet = Vec::new();
    let mut animations = Vec::with_capacity(motions.len());
    for (name, motion) in motions {
        if motion.skeleton != *skeleton {
            return Err(FormatError::Write {
                path: path.to_path_buf(),
                message: format!("motion '{name}' has another skeleton than the first"),
            });
        }
        let retargeted = drive.retargeted.is_some().then(|| {
            retargeted_animation(
                &mut binary,
                (name, motion),
                up_axis,
                &drive,
                (&parent, &rest, &target_names),
            )
        });
        match retargeted.flatten() {
            Some((animation, feet)) => {
                planted_feet = feet;
                animations.push(animation);
            }
            None => animations.push(spliced_animation(
                &mut binary,
                name,
                motion,
                up_axis,
                &drive,
                (&parent, &rest),
            )),
        }
    }
    append_animations(&mut json, &mut binary, animations);
    let out = glb_bytes(&json, &binary.bytes);
    sinmdm::files::write_atomically(path, &out).map_err(|reason| FormatError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    Ok(SpliceReport {
        kept_animations,
        added_animations: motions.len(),
        scale,
        same_frames: drive.retargeted.is_none()
            && drive.driven.iter().all(|d| d.turn == math::IDENTITY),
        retargeted: drive.retargeted.map(|r| Retargeted { planted_feet, ..r }),
    })
}

/// The JSON and buffers of the character file `character`, which must be a `.glb` whose data
/// all lies in its binary chunk.
fn read_character(character: &Path) -> Result<(Value, Vec<Vec<u8>>), FormatError> {
    let bytes = crate::files::read_file(character, crate::files::GLTF_LIMIT)?;
    if !super::container::is_glb(&bytes) {
        return Err(FormatError::Unsupported {
            path: character.to_path_buf(),
            message: "is not a .glb: the character file is read as binary glTF (.glb), whose mesh and skin travel in one file; export it as glTF Binary (.glb), e.g. from Blender (File > Export > glTF 2.0, Format: glTF Binary)".into(),
        });
    }
    let Asset { json, buffers, .. } = parse_glb(character, &bytes)?;
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
    Ok((json, buffers))
}

/// How the character's nodes are driven by the model's joints, its bones matched to them as
/// `bones` says: by the same frames when they fit, else retargeted.
fn character_drive(
    character: &Path,
    bones: &BoneMatch,
    skeleton: &Skeleton,
    (target, source): (&Rig, &Rig),
    (model, rest): (&[(Mat3, Vec3)], &[Similarity]),
) -> Result<Drive, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(character, part, message);
    let pairing = match bones {
        BoneMatch::Names => {
            // Our joints by name among the character's nodes: the same name, or else the one
            // node whose name is it after a namespace (a model read from Mixamo's FBX has
            // `Hips` where the character's GLB has `mixamorig:Hips`).
            let pairs = pairs_by_name(target, source);
            let mut mapped = vec![usize::MAX; skeleton.len()];
            for &(node, joint) in &pairs {
                mapped[joint] = node;
            }
            if let Some(missing) = mapped.iter().position(|&n| n == usize::MAX) {
                return Err(bad(
                    Part::Skeleton,
                    format!(
                        "has no node named '{}', a joint of the model's skeleton; for a rig with other bone names pass --retarget auto (or a bone map: --retarget MAP.yaml)",
                        skeleton.joints[missing].name
                    ),
                ));
            }
            match by_frames(skeleton, model, rest, &mapped) {
                Ok(drive) => Ok(drive),
                Err(misfit) => Err(Pairing {
                    pairs,
                    reason: format!(
                        "its bones have the model's names but it is another rig: {misfit}"
                    ),
                    conventions: None,
                }),
            }
        }
        BoneMatch::Auto => {
            let found = pairs_by_role(target, source).map_err(|m| bad(Part::Skeleton, m))?;
            Err(Pairing {
                pairs: found.pairs,
                reason: format!(
                    "--retarget auto: the character's bones read as {}, the model's as {}",
                    found.target, found.source
                ),
                conventions: Some((found.target, found.source)),
            })
        }
        BoneMatch::Map(map, file) => Err(Pairing {
            pairs: map.indices(target, source, file)?,
            reason: format!("--retarget {}", file.display()),
            conventions: None,
        }),
    };
    Ok(match pairing {
        Ok(drive) => drive,
        Err(pairing) => {
            check_chains(&pairing.pairs, target, source).map_err(|m| bad(Part::Skeleton, m))?;
            retargeted(pairing, (target, source), model, rest)
                .map_err(|m| bad(Part::Skeleton, m))?
        }
    })
}

/// Appends the new accessors, buffer views and animations to the document's arrays and sets
/// its buffer's length to the binary's.
fn append_animations(json: &mut Value, binary: &mut Binary, animations: Vec<Value>) {
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
}
