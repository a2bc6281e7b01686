//! How each of a character's nodes is driven by the motions' joints: which joint it follows,
//! the constant turn from the joint's global rotation to the node's, and whether it carries
//! the travel. Three relations, read from the rest geometry:
//! - **the same frames**: the model was trained from this file (or one like it), so a joint's
//!   local rotation is the node's, and its offsets point where the node's children sit;
//! - **the bind pose is the clip's rest pose**: the character was made from the clip (a BVH
//!   imported into Blender, say), whose bones have their own rest rotations `B_j`; the node's
//!   global rotation is then the joint's global rotation times `B_j`;
//! - **retargeted**: any other rig, through a bone map. Each paired bone turns in the world as
//!   its joint turns from its rest, after a fixed turn that makes its rest point the way the
//!   joint's rest does; the travel is scaled by the ratio of the two hip heights.

use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{Skeleton, UpAxis};

use super::nodes::Similarity;
use crate::retarget::align::fitted_rotation;
use crate::retarget::{BoneMap, Convention, Rig};

/// Largest angle, in radians, between a bone's direction in the motions' skeleton and in the
/// character's for the two to count as the same bone.
const DIRECTION_TOLERANCE: f64 = 0.02;

/// Largest relative difference between one bone's length ratio (character to model) and the
/// rig's for the two to count as the same rig at another scale.
const PROPORTION_TOLERANCE: f64 = 0.02;

/// A character stands on its origin's ground at rest when its lowest paired bone is within this
/// share of its hip height of it.
const STANDING: f64 = 0.1;

/// A character node that follows a joint of the motions.
#[derive(Debug, Clone, Copy)]
pub(super) struct Driven {
    /// The character's node.
    pub node: usize,
    /// The motions' joint.
    pub joint: usize,
    /// The node's global rotation is the joint's times this.
    pub turn: Mat3,
    /// Whether the node's translation is animated too.
    pub moves: bool,
}

/// What a retargeting did, for the user to read (and keep: the map is a file they can edit).
#[derive(Debug, Clone, PartialEq)]
pub struct Retargeted {
    /// Why the motion was retargeted rather than copied bone for bone.
    pub reason: String,
    /// Which character bone follows which joint.
    pub map: BoneMap,
    /// The conventions recognised (character, model), for an automatic map.
    pub conventions: Option<(Convention, Convention)>,
    /// The hips' rest heights above the lowest paired bone: the character's (its units) and the
    /// model's (the motions' units); the travel is scaled by their ratio.
    pub hip_heights: [f64; 2],
    /// Character bones under the hips that follow no joint and keep their rest pose.
    pub still_bones: Vec<String>,
    /// Model joints no character bone follows.
    pub dropped_joints: Vec<String>,
    /// The character's bones whose contacts with the ground were held still again (the model's
    /// feet, as the motion shows them, on the bones that follow them).
    pub planted_feet: Vec<String>,
}

/// The nodes driven, and how the motions' positions become the character's.
#[derive(Debug, Clone)]
pub(super) struct Drive {
    pub driven: Vec<Driven>,
    /// Character units per unit of the motions.
    pub scale: f64,
    /// For a retargeted character that stands on its origin's ground at rest, that ground (the
    /// rest height of its lowest paired bone) and the joints whose lowest is the motions'
    /// ground: travel is carried from ground to ground. A rig that hangs from its hips at the
    /// origin (one made from a BVH file) walks on the motions' ground, scaled.
    pub grounds: Option<(f64, Vec<usize>)>,
    pub retargeted: Option<Retargeted>,
}

/// The motions' rest pose in glTF's frame: identity rotations, the top joint turned to +Y up.
/// Each joint's (global rotation, position).
pub(super) fn model_rest(skeleton: &Skeleton, up_axis: UpAxis) -> Vec<(Mat3, Vec3)> {
    let turn = up_axis.canonical_from_file();
    let mut rest: Vec<(Mat3, Vec3)> = Vec::with_capacity(skeleton.len());
    for joint in &skeleton.joints {
        let g = match joint.parent {
            None => (turn, (turn * joint.offset)),
            Some(p) => {
                let (r, t) = rest[p];
                (r, (t + (r * joint.offset)))
            }
        };
        rest.push(g);
    }
    rest
}

/// The angle between two vectors, in radians (0 when either is too short to have a direction).
fn angle(a: Vec3, b: Vec3) -> f64 {
    let (na, nb) = (a.norm(), b.norm());
    if na < 1e-12 || nb < 1e-12 {
        return 0.0;
    }
    (a.dot(b) / (na * nb)).clamp(-1.0, 1.0).acos()
}

/// The drive of a character whose every joint has its node (`mapped[j]`) and whose bones fit
/// one of the two fixed relations at one scale; else what the first bone that does not fit does.
pub(super) fn by_frames(
    skeleton: &Skeleton,
    model: &[(Mat3, Vec3)],
    rest: &[Similarity],
    mapped: &[usize],
) -> Result<Drive, String> {
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
        let ours_world = model[j].1 - model[p].1;
        let theirs_world = rest[mapped[j]].translation - rest[mapped[p]].translation;
        if ours_world.norm() <= 1e-3 * longest {
            continue;
        }
        ratios.push((joint.name.as_str(), theirs_world.norm() / ours_world.norm()));
        // In the parent's frame: our offset, and the character's bone seen from the parent node.
        let theirs_local = rest[mapped[p]].rotation.transpose() * theirs_world;
        let fits_local = angle(joint.offset, theirs_local) <= DIRECTION_TOLERANCE;
        let fits_world = angle(ours_world, theirs_world) <= DIRECTION_TOLERANCE;
        same_frames &= fits_local;
        bind_is_rest &= fits_world;
        if !fits_local && !fits_world && first_misfit.is_none() {
            first_misfit = Some(joint.name.clone());
        }
    }
    if !(same_frames || bind_is_rest) {
        return Err(format!(
            "bone '{}' points elsewhere",
            first_misfit.unwrap_or_default()
        ));
    }
    let mut sorted: Vec<f64> = ratios.iter().map(|&(_, r)| r).collect();
    sorted.sort_by(f64::total_cmp);
    let scale = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
    // A rig of other proportions (longer legs, shorter arms) is another character.
    if let Some((name, ratio)) = ratios
        .iter()
        .find(|&&(_, r)| (r / scale - 1.0).abs() > PROPORTION_TOLERANCE)
    {
        return Err(format!(
            "bone '{name}' is {ratio:.3}x the model's where the rig is {scale:.3}x"
        ));
    }
    // The constant turn from each joint's frame to its node's: identity, or the bind pose's.
    let driven = skeleton
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| Driven {
            node: mapped[j],
            joint: j,
            turn: if same_frames {
                math::IDENTITY
            } else {
                model[j].0.transpose() * rest[mapped[j]].rotation
            },
            moves: joint.parent.is_none() || !joint.position_axes().is_empty(),
        })
        .collect();
    Ok(Drive {
        driven,
        scale,
        grounds: None,
        retargeted: None,
    })
}

/// How a retargeting is asked for: the pairs `(node, joint)`, already checked against both
/// hierarchies, and why.
pub(super) struct Pairing {
    pub pairs: Vec<(usize, usize)>,
    pub reason: String,
    pub conventions: Option<(Convention, Convention)>,
}

/// The drive of any character through a bone map (see the module's documentation).
pub(super) fn retargeted(
    pairing: Pairing,
    (target, source): (&Rig, &Rig),
    model: &[(Mat3, Vec3)],
    rest: &[Similarity],
) -> Result<Drive, String> {
    let mut pairs = pairing.pairs;
    if pairs.is_empty() {
        return Err("no bone of the character follows a joint of the model".into());
    }
    // In the character's hierarchy order, so a bone's paired ancestor comes first.
    pairs.sort_by_key(|&(node, _)| target.depth(node));
    let paired_parent = paired_parents(&pairs, target);
    // The bone that carries the body: the top paired bone following the highest joint.
    let top = (0..pairs.len())
        .filter(|&k| paired_parent[k].is_none())
        .min_by_key(|&k| source.depth(pairs[k].1))
        .unwrap_or(0);
    // Each bone's rest alignment, from the directions to its paired children.
    let align = rest_alignments(&pairs, &paired_parent, model, rest);
    // Hip heights above the lowest paired bone, at rest.
    let lowest_target = pairs
        .iter()
        .map(|&(n, _)| rest[n].translation[1])
        .fold(f64::INFINITY, f64::min);
    let lowest_model = pairs
        .iter()
        .map(|&(_, j)| model[j].1[1])
        .fold(f64::INFINITY, f64::min);
    let hip_heights = [
        rest[pairs[top].0].translation[1] - lowest_target,
        model[pairs[top].1].1[1] - lowest_model,
    ];
    if !(hip_heights.iter().all(|h| h.is_finite() && *h > 1e-9)) {
        return Err(format!(
            "the hips ('{}') stand no higher than the feet at rest ({:.4} on the character, {:.4} on the model), so there is no leg length to scale the travel by",
            target.names[pairs[top].0], hip_heights[0], hip_heights[1]
        ));
    }
    let scale = hip_heights[0] / hip_heights[1];
    let driven = pairs
        .iter()
        .enumerate()
        .map(|(k, &(node, joint))| Driven {
            node,
            joint,
            turn: model[joint].0.transpose() * align[k] * rest[node].rotation,
            moves: k == top,
        })
        .collect();
    let still_bones = (0..target.names.len())
        .filter(|&n| {
            n != pairs[top].0
                && target.holds(pairs[top].0, n)
                && !pairs.iter().any(|&(p, _)| p == n)
        })
        .map(|n| target.names[n].clone())
        .collect();
    let dropped_joints = (0..source.names.len())
        .filter(|&j| !pairs.iter().any(|&(_, p)| p == j))
        .map(|j| source.names[j].clone())
        .collect();
    Ok(Drive {
        scale,
        grounds: (lowest_target.abs() <= STANDING * hip_heights[0])
            .then(|| (lowest_target, pairs.iter().map(|&(_, j)| j).collect())),
        retargeted: Some(Retargeted {
            reason: pairing.reason,
            map: BoneMap::of(&pairs, target, source),
            conventions: pairing.conventions,
            hip_heights,
            still_bones,
            dropped_joints,
            planted_feet: Vec::new(),
        }),
        driven,
    })
}

/// For each pair, the index of the pair holding its nearest paired ancestor in the character's
/// hierarchy, if any.
fn paired_parents(pairs: &[(usize, usize)], target: &Rig) -> Vec<Option<usize>> {
    pairs
        .iter()
        .map(|&(node, _)| {
            let mut at = target.parents[node];
            let mut steps = 0;
            while let Some(a) = at {
                if let Some(k) = pairs.iter().position(|&(n, _)| n == a) {
                    return Some(k);
                }
                steps += 1;
                if steps > target.parents.len() {
                    break;
                }
                at = target.parents[a];
            }
            None
        })
        .collect()
}

/// Each paired bone's rest alignment, from the directions to its paired children (or its
/// paired parent's alignment when it has none).
fn rest_alignments(
    pairs: &[(usize, usize)],
    paired_parent: &[Option<usize>],
    model: &[(Mat3, Vec3)],
    rest: &[Similarity],
) -> Vec<Mat3> {
    let mut align: Vec<Mat3> = Vec::with_capacity(pairs.len());
    for (k, &(node, joint)) in pairs.iter().enumerate() {
        let directions: Vec<(Vec3, Vec3)> = (0..pairs.len())
            .filter(|&c| paired_parent[c] == Some(k))
            .map(|c| {
                let (child_node, child_joint) = pairs[c];
                (
                    rest[child_node].translation - rest[node].translation,
                    model[child_joint].1 - model[joint].1,
                )
            })
            .filter(|(a, b)| a.norm() > 1e-9 && b.norm() > 1e-9)
            .collect();
        let a = if directions.is_empty() {
            paired_parent[k].map_or(math::IDENTITY, |p| align[p])
        } else {
            fitted_rotation(&directions)
        };
        align.push(a);
    }
    align
}
