//! The skeleton of a glTF file: the skin's joints in depth-first order, the nodes above each
//! folded into it, and the BVH-style joints (channels, offsets, End Sites) built from their
//! motion.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{Channel, Joint, Skeleton};

use super::EXTRAS_KEY;
use super::nodes::{Similarity, Trs, node_name, numbers, uniform};
use crate::error::{FormatError, Part};

/// The skin's joints as a skeleton's: node indices in depth-first order from the root joint,
/// each joint's parent joint (an index into `order`), the fixed transform of the non-joint
/// nodes above each, and the scale of the nodes above the root (which multiplies every
/// translation below it).
pub(super) struct SkinJoints {
    pub(super) order: Vec<usize>,
    pub(super) parents: Vec<Option<usize>>,
    pub(super) pre: Vec<Similarity>,
    pub(super) unit: f64,
}

impl SkinJoints {
    /// The joint index of node `n`, if it is a joint.
    pub(super) fn joint_of(&self, n: usize) -> Option<usize> {
        self.order.iter().position(|&o| o == n)
    }
}

/// The skin with the most joints, its joints ordered and the nodes above them folded.
pub(super) fn skin_joints(
    path: &Path,
    json: &Value,
    nodes: &[Value],
    parent: &[Option<usize>],
    rest: &[Trs],
) -> Result<SkinJoints, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    // The skin: the one with the most joints.
    let skins = json.get("skins").and_then(Value::as_array);
    let (skin_index, skin) = skins
    .into_iter()
    .flatten()
    .enumerate()
    .max_by_key(|(_, s)| s.get("joints").and_then(Value::as_array).map_or(0, Vec::len))
    .ok_or_else(|| {
        bad(
            Part::Json,
            "has no skin, so no skeleton: export the armature with its skin (a skinned mesh or the armature's bones)".into(),
        )
    })?;
    let joint_nodes: Vec<usize> = skin
        .get("joints")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|j| j.as_u64().map(|j| j as usize).filter(|&j| j < nodes.len()))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| {
            bad(
                Part::Skin(skin_index),
                "names a joint that is not a node".into(),
            )
        })?;
    if joint_nodes.is_empty() {
        return Err(bad(Part::Skin(skin_index), "has no joints".into()));
    }
    let is_joint = |n: usize| joint_nodes.contains(&n);
    let joint_parent = |n: usize| -> Option<usize> {
        let mut at = parent[n];
        while let Some(p) = at {
            if is_joint(p) {
                return Some(p);
            }
            at = parent[p];
        }
        None
    };
    let roots: Vec<usize> = joint_nodes
        .iter()
        .copied()
        .filter(|&n| joint_parent(n).is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<String> = roots
            .iter()
            .map(|&n| node_name(&nodes[n]).unwrap_or_else(|| format!("node {n}")))
            .collect();
        return Err(bad(
            Part::Skin(skin_index),
            format!(
                "has {} root joints ({}); a skeleton needs exactly one",
                roots.len(),
                names.join(", ")
            ),
        ));
    }
    // Depth-first order from the root, children in file order.
    let mut order = Vec::with_capacity(joint_nodes.len());
    let mut stack = vec![roots[0]];
    while let Some(n) = stack.pop() {
        if is_joint(n) {
            order.push(n);
        }
        let children: Vec<usize> = nodes[n]
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|c| c.as_u64().map(|c| c as usize))
            .collect();
        stack.extend(children.into_iter().rev());
    }
    // The non-joint nodes above each joint, folded into one transform.
    let mut pre: Vec<Similarity> = Vec::with_capacity(order.len());
    for &n in &order {
        let stop = joint_parent(n);
        let mut fold = Similarity::IDENTITY;
        let mut at = parent[n];
        while at.is_some() && at != stop {
            let p = at.expect("checked");
            let trs = rest[p];
            let scale = uniform(trs.scale).ok_or_else(|| {
                bad(
                    Part::Node(p, node_name(&nodes[p])),
                    format!("has a non-uniform scale {:?} above a joint", trs.scale),
                )
            })?;
            if stop.is_some() && (scale - 1.0).abs() > 1e-4 {
                return Err(bad(
                    Part::Node(p, node_name(&nodes[p])),
                    format!(
                        "scales by {scale} between two joints; only nodes above the root may scale"
                    ),
                ));
            }
            fold = Similarity {
                rotation: trs.rotation,
                translation: trs.translation,
                scale,
            }
            .then(&fold);
            at = parent[p];
        }
        pre.push(fold);
    }
    // The scale of the nodes above the root multiplies every translation below it.
    let unit = pre[0].scale;
    // Parents precede children in depth-first order, so each parent's index is known.
    let parents = order
        .iter()
        .map(|&n| joint_parent(n).and_then(|p| order.iter().position(|&o| o == p)))
        .collect();

    Ok(SkinJoints {
        order,
        parents,
        pre,
        unit,
    })
}

/// The joints' names: the nodes', with whitespace runs as `_`, `joint_N` for unnamed nodes, and
/// `_2`, `_3`, ... after repeats, so every name is unique.
pub(super) fn unique_names(nodes: &[Value], order: &[usize]) -> Vec<String> {
    let mut names: Vec<String> = Vec::with_capacity(order.len());
    for &n in order {
        let base = node_name(&nodes[n])
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.split_whitespace().collect::<Vec<_>>().join("_"))
            .unwrap_or_else(|| format!("joint_{n}"));
        let mut name = base.clone();
        let mut k = 2;
        while names.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        names.push(name);
    }

    names
}

/// Whether `channels` is a list a BVH joint can have: each rotation axis and each position
/// axis at most once.
fn well_formed(channels: &[Channel]) -> bool {
    let mut seen = Vec::with_capacity(channels.len());
    channels.iter().all(|c| {
        let new = !seen.contains(c);
        seen.push(*c);
        new
    })
}

/// The channels this crate's writer recorded for node `n` (when well formed), and its End Site.
fn recorded(node: &Value, unit: f64) -> (Option<Vec<Channel>>, Option<Vec3>) {
    let extras = node.get("extras").and_then(|e| e.get(EXTRAS_KEY));
    let channels = extras
        .and_then(|e| e.get("channels"))
        .and_then(Value::as_array)
        .and_then(|list| {
            list.iter()
                .map(|c| c.as_str().and_then(Channel::parse))
                .collect::<Option<Vec<_>>>()
        })
        .filter(|channels| well_formed(channels));
    let end = numbers::<3>(extras.and_then(|e| e.get("end_site"))).map(|e| math::scale(e, unit));
    (channels, end)
}

/// A joint's translation holds still when it changes by less than this share of its length
/// over the clip (glTF's f32 values round at about 1e-7 of it; exporters that sample every bone
/// every frame write that rounding as motion).
const STILL_SHARE: f64 = 1e-5;
/// A joint's rotation holds still when no matrix entry changes by more than this.
const STILL_TURN: f64 = 1e-5;

/// Whether joint `j` turns and whether it moves, over the frames.
fn turns_and_moves(
    rotations: &[Mat3],
    translations: &[Vec3],
    joints: usize,
    frames: usize,
    j: usize,
) -> (bool, bool) {
    let (turns, moves) = joint_motion(rotations, translations, joints, frames, j);
    let length = math::norm(translations[j]).max(1e-12);
    (turns > STILL_TURN, moves > STILL_SHARE * length)
}

/// Largest change of joint `j`'s local rotation and translation over the frames.
fn joint_motion(
    rotations: &[Mat3],
    translations: &[Vec3],
    joints: usize,
    frames: usize,
    j: usize,
) -> (f64, f64) {
    let (r0, t0) = (rotations[j], translations[j]);
    let mut worst = (0.0f64, 0.0f64);
    for f in 1..frames {
        let k = f * joints + j;
        worst.0 = worst.0.max(math::mat_max_abs_diff(&rotations[k], &r0));
        worst.1 = worst.1.max(math::norm(math::sub(translations[k], t0)));
    }
    worst
}

/// The skeleton's joints: offsets from the first frame's translations where no position
/// channel moves them, and channels as recorded, or rotations (and positions where they move).
pub(super) fn build_joints(
    skin: &SkinJoints,
    nodes: &[Value],
    names: &[String],
    rotations: &[Mat3],
    translations: &[Vec3],
    frames: usize,
) -> Vec<Joint> {
    let SkinJoints {
        order,
        parents,
        unit,
        ..
    } = skin;
    let joints = order.len();
    (0..joints)
        .map(|j| {
            let (recorded_channels, end_site) = recorded(&nodes[order[j]], *unit);
            let (turns, moves) = turns_and_moves(rotations, translations, joints, frames, j);
            let parent = parents[j];
            let default_channels = || {
                let mut channels = Vec::new();
                if parent.is_none() || moves {
                    channels.extend(
                        ["Xposition", "Yposition", "Zposition"]
                            .map(|c| Channel::parse(c).expect("channel")),
                    );
                }
                channels.extend(
                    ["Zrotation", "Xrotation", "Yrotation"]
                        .map(|c| Channel::parse(c).expect("channel")),
                );
                channels
            };
            // Recorded channels are kept only when they can carry the motion: no rotation
            // channel means the identity, no position channel a fixed offset.
            let channels = match recorded_channels {
                Some(channels) => {
                    let rotates = channels.iter().any(|c| matches!(c, Channel::Rotation(_)));
                    let positions = channels.iter().any(|c| matches!(c, Channel::Position(_)));
                    let identity =
                        math::mat_max_abs_diff(&rotations[j], &math::IDENTITY) < STILL_TURN;
                    if (rotates || (!turns && identity)) && (positions || !moves) {
                        channels
                    } else {
                        default_channels()
                    }
                }
                None => default_channels(),
            };
            Joint {
                name: names[j].clone(),
                parent,
                offset: translations[j],
                channels,
                end_site,
            }
        })
        .collect()
}

/// Leaf joints that never move and are their parent's only child become the parent's End Site
/// (files this crate wrote keep their End Sites in extras and have no such joints).
pub(super) fn drop_static_leaves(
    mut joints: Vec<Joint>,
    rotations: Vec<Mat3>,
    translations: Vec<Vec3>,
    frames: usize,
    nodes: &[Value],
    order: &[usize],
) -> (Skeleton, Vec<Mat3>, Vec<Vec3>) {
    let count = joints.len();
    let mut keep = vec![true; count];
    for j in 1..count {
        let written_by_us = nodes[order[j]]
            .get("extras")
            .and_then(|e| e.get(EXTRAS_KEY))
            .is_some();
        let Some(p) = joints[j].parent else { continue };
        let leaf = !joints.iter().any(|o| o.parent == Some(j));
        let only_child = joints.iter().filter(|o| o.parent == Some(p)).count() == 1;
        let (turns, moves) = turns_and_moves(&rotations, &translations, count, frames, j);
        if !written_by_us && leaf && only_child && !turns && !moves && joints[p].end_site.is_none()
        {
            joints[p].end_site = Some(translations[j]);
            keep[j] = false;
        }
    }
    if keep.iter().all(|&k| k) {
        return (Skeleton { joints }, rotations, translations);
    }
    let new_index: Vec<Option<usize>> = keep
        .iter()
        .scan(0, |next, &k| {
            let index = k.then_some(*next);
            *next += usize::from(k);
            Some(index)
        })
        .collect();
    let kept: Vec<Joint> = joints
        .into_iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(mut joint, _)| {
            joint.parent = joint.parent.and_then(|p| new_index[p]);
            joint
        })
        .collect();
    (
        Skeleton { joints: kept },
        kept_joints(rotations, &keep),
        kept_joints(translations, &keep),
    )
}

/// The `[frames][joints]` values of the joints marked in `keep`.
fn kept_joints<T>(values: Vec<T>, keep: &[bool]) -> Vec<T> {
    values
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep[i % keep.len()])
        .map(|(_, v)| v)
        .collect()
}
