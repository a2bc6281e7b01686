//! The skeleton of a glTF file: the skin's joints in depth-first order, the nodes above each
//! folded into it, and the BVH-style joints (channels, offsets, End Sites) built from their
//! motion.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::Channel;
use sinmdm::motion::math::Vec3;

use super::EXTRAS_KEY;
use super::nodes::{Similarity, Trs, node_name, numbers, uniform};
use crate::error::{FormatError, Part};
use crate::sampled::{Recorded, well_formed};

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
    let (skin_index, skin) = largest_skin(path, json)?;
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
    let order = depth_first_joints(nodes, roots[0], &joint_nodes);
    // The non-joint nodes above each joint, folded into one transform.
    let mut pre: Vec<Similarity> = Vec::with_capacity(order.len());
    for &n in &order {
        let stop = joint_parent(n);
        let fold = fold_above(path, nodes, (parent, rest), n, stop)?;
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

/// The skin with the most joints, and its index; an error when the file has no skin.
fn largest_skin<'a>(path: &Path, json: &'a Value) -> Result<(usize, &'a Value), FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    let skins = json.get("skins").and_then(Value::as_array);
    skins
    .into_iter()
    .flatten()
    .enumerate()
    .max_by_key(|(_, s)| s.get("joints").and_then(Value::as_array).map_or(0, Vec::len))
    .ok_or_else(|| {
        bad(
            Part::Json,
            "has no skin, so no skeleton: export the armature with its skin (a skinned mesh or the armature's bones)".into(),
        )
    })
}

/// The joint nodes under `root` in depth-first order, children in file order.
fn depth_first_joints(nodes: &[Value], root: usize, joint_nodes: &[usize]) -> Vec<usize> {
    let mut order = Vec::with_capacity(joint_nodes.len());
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if joint_nodes.contains(&n) {
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
    order
}

/// The non-joint nodes between node `n` and its joint parent `stop` (or the top of the
/// hierarchy), folded into one transform; an error for a scale they may not have.
fn fold_above(
    path: &Path,
    nodes: &[Value],
    (parent, rest): (&[Option<usize>], &[Trs]),
    n: usize,
    stop: Option<usize>,
) -> Result<Similarity, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
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
    Ok(fold)
}

/// The joints' names as the nodes hold them (`None` for unnamed nodes).
pub(super) fn node_names(nodes: &[Value], order: &[usize]) -> Vec<Option<String>> {
    order.iter().map(|&n| node_name(&nodes[n])).collect()
}

/// What this crate's writer recorded on each joint's node (channels and End Site), scaled by
/// the nodes above the root.
pub(super) fn recorded_joints(nodes: &[Value], skin: &SkinJoints) -> Vec<Recorded> {
    skin.order
        .iter()
        .map(|&n| {
            let ours = nodes[n]
                .get("extras")
                .and_then(|e| e.get(EXTRAS_KEY))
                .is_some();
            let (channels, end_site) = recorded(&nodes[n], skin.unit);
            Recorded {
                channels,
                end_site,
                ours,
            }
        })
        .collect()
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
    let end = numbers::<3>(extras.and_then(|e| e.get("end_site"))).map(|e| Vec3(e) * unit);
    (channels, end)
}
