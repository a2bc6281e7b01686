//! A retargeted motion as a motion of the character's own skeleton, its feet put where the
//! clip's feet are: a character whose legs are not the clip's legs scaled alike (longer thighs,
//! shorter shins) would otherwise slide its feet while they stand. Each leg above one of the
//! model's contact joints (the joints that reach the ground, read from the motion) bends at the
//! knee and turns at the hip so its ankle is where the clip's ankle is, scaled as the travel is,
//! the foot keeping its turn; a leg that is the clip's scaled alike is left exactly as it was.

use sinmdm::motion::contacts::{ContactConfig, choose_contact_joints};
use sinmdm::motion::feet::leg_chain;
use sinmdm::motion::ground::Body;
use sinmdm::motion::math::{Mat3, Vec3};
use sinmdm::motion::skeleton::{Axis, Channel, Joint, Skeleton};
use sinmdm::motion::{GlobalPose, LocalMotion};

use crate::retarget::Rig;
use crate::retarget::align::shortest_rotation;

use super::drive::Drive;
use super::nodes::Similarity;

/// The character's skeleton under the bone that carries the body, and a motion of it.
pub(super) struct CharacterMotion {
    /// The character's node of each joint of `motion`.
    pub nodes: Vec<usize>,
    /// The global rest transform of the carrying bone's parent: `motion` is in the world, and
    /// the carrying bone's local transform is this one's inverse times its world transform.
    pub above: Similarity,
    /// The motion, in the world's frame and units (+Y up).
    pub motion: LocalMotion,
    /// The joints of `motion` whose legs follow the clip's feet (the ankles).
    pub planted: Vec<usize>,
}

/// The drive's retargeted motion of `poses` (the motions' canonical global poses, scaled, and
/// `lift` from their ground to the character's) as a motion of the character's nodes, its
/// ankles where the clip's are; `None` for a drive with no carrying bone or one below another
/// driven bone.
pub(super) fn character_motion(
    source: &Skeleton,
    poses: &[GlobalPose],
    lift: Vec3,
    fps: f64,
    drive: &Drive,
    (parent, rest, names): (&[Option<usize>], &[Similarity], &[String]),
) -> Option<CharacterMotion> {
    let top = drive.driven.iter().find(|d| d.moves)?;
    // The carrying bone's subtree, breadth first: parents before children.
    let nodes = subtree(top.node, parent);
    let above = match parent[top.node] {
        Some(p) => {
            let rig = Rig {
                names,
                parents: parent,
            };
            if drive.driven.iter().any(|d| rig.holds(d.node, p)) {
                return None;
            }
            rest[p]
        }
        None => Similarity::IDENTITY,
    };
    let skeleton = subtree_skeleton(&nodes, (parent, rest, names));
    let rest_local: Vec<Mat3> = nodes
        .iter()
        .map(|&n| match parent[n] {
            Some(p) => rest[p].rotation.transpose() * rest[n].rotation,
            None => rest[n].rotation,
        })
        .collect();
    // How each joint is driven, looked up once rather than every frame.
    let driven_by: Vec<Option<&super::drive::Driven>> = nodes
        .iter()
        .map(|&n| drive.driven.iter().find(|d| d.node == n))
        .collect();
    let legs = legs(source, poses, drive, &nodes, &skeleton);
    let mut rotations = Vec::with_capacity(poses.len() * nodes.len());
    let mut translations = Vec::with_capacity(poses.len() * nodes.len());
    for pose in poses {
        let mut global: Vec<Mat3> = Vec::with_capacity(nodes.len());
        let mut position: Vec<Vec3> = Vec::with_capacity(nodes.len());
        for (k, driven) in driven_by.iter().enumerate() {
            let up = skeleton.joints[k].parent;
            let g = match driven {
                Some(d) => pose.rotations[d.joint] * d.turn,
                None => match up {
                    Some(p) => global[p] * rest_local[k],
                    None => above.rotation * rest_local[k],
                },
            };
            global.push(g);
            position.push(match up {
                Some(p) => position[p] + global[p] * skeleton.joints[k].offset,
                None => pose.joints[top.joint] + lift,
            });
        }
        for leg in &legs {
            let want = pose.joints[leg.follows] + lift;
            reach(leg, want, &skeleton, &mut global, &mut position);
        }
        for (k, joint) in skeleton.joints.iter().enumerate() {
            rotations.push(match joint.parent {
                Some(p) => global[p].transpose() * global[k],
                None => global[k],
            });
            translations.push(if k == 0 { position[0] } else { joint.offset });
        }
    }
    let planted = legs.iter().map(|leg| leg.ankle).collect();
    let motion = LocalMotion {
        skeleton,
        fps,
        rotations,
        translations,
    };
    Some(CharacterMotion {
        nodes,
        above,
        motion,
        planted,
    })
}

/// The subtree of `parent`'s hierarchy under node `top`, breadth first: parents before children.
fn subtree(top: usize, parent: &[Option<usize>]) -> Vec<usize> {
    let mut nodes = vec![top];
    let mut next = 0;
    while next < nodes.len() {
        let n = nodes[next];
        nodes.extend((0..parent.len()).filter(|&c| parent[c] == Some(n)));
        next += 1;
    }
    nodes
}

/// The skeleton of `nodes` (a subtree, parents first): the first joint moves and turns, the
/// others turn about their rest offsets from their parents.
fn subtree_skeleton(
    nodes: &[usize],
    (parent, rest, names): (&[Option<usize>], &[Similarity], &[String]),
) -> Skeleton {
    let index = |n: usize| nodes.iter().position(|&m| m == n);
    let rotations_only = || {
        [Axis::Z, Axis::X, Axis::Y]
            .into_iter()
            .map(Channel::Rotation)
            .collect::<Vec<_>>()
    };
    let joints: Vec<Joint> = nodes
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let (parent_index, offset, channels) = if k == 0 {
                let mut channels: Vec<Channel> = [Axis::X, Axis::Y, Axis::Z]
                    .into_iter()
                    .map(Channel::Position)
                    .collect();
                channels.extend(rotations_only());
                (None, Vec3::ZERO, channels)
            } else {
                let p = parent[n].expect("below the carrying bone");
                let offset =
                    rest[p].rotation.transpose() * (rest[n].translation - rest[p].translation);
                (index(p), offset, rotations_only())
            };
            Joint {
                name: names[n].clone(),
                parent: parent_index,
                offset,
                channels,
                end_site: None,
            }
        })
        .collect();
    Skeleton { joints }
}

/// A leg of the character that follows one of the clip's: its hip, knee and ankle joints, and
/// the clip's joint its ankle follows.
struct Leg {
    hip: usize,
    knee: usize,
    ankle: usize,
    follows: usize,
}

/// The legs above the model's contact joints (as the motion shows them), on the character.
fn legs(
    source: &Skeleton,
    poses: &[GlobalPose],
    drive: &Drive,
    nodes: &[usize],
    skeleton: &Skeleton,
) -> Vec<Leg> {
    let config = ContactConfig::default();
    let height = Body::travelling(source, poses).height(poses);
    let contacts = choose_contact_joints(source, poses, height, config.ground_fraction);
    let offsets: Vec<Vec3> = skeleton.joints.iter().map(|j| j.offset).collect();
    let joint_of = |k: usize| {
        drive
            .driven
            .iter()
            .find(|d| d.node == nodes[k])
            .map(|d| d.joint)
    };
    let mut legs: Vec<Leg> = Vec::new();
    for contact in contacts {
        let Some(k) = drive
            .driven
            .iter()
            .find(|d| d.joint == contact)
            .and_then(|d| nodes.iter().position(|&n| n == d.node))
        else {
            continue;
        };
        let Some(chain) = leg_chain(skeleton, &offsets, k) else {
            continue;
        };
        let [.., hip, knee, ankle] = chain.joints[..] else {
            continue;
        };
        // Only a leg whose three joints all follow the clip's.
        let (Some(_), Some(_), Some(follows)) = (joint_of(hip), joint_of(knee), joint_of(ankle))
        else {
            continue;
        };
        if chain.joints.len() >= 3 && !legs.iter().any(|l| l.ankle == ankle) {
            legs.push(Leg {
                hip,
                knee,
                ankle,
                follows,
            });
        }
    }
    legs
}

/// Bends `leg` at the knee and turns it at the hip so its ankle reaches `want` (or comes
/// nearest, the leg straight or folded), the ankle keeping its global rotation; the joints'
/// global rotations and positions are updated, everything below the ankle moving with it.
fn reach(leg: &Leg, want: Vec3, skeleton: &Skeleton, global: &mut [Mat3], position: &mut [Vec3]) {
    let (h, k, a) = (position[leg.hip], position[leg.knee], position[leg.ankle]);
    if (a - want).norm() <= 1e-9 * (k - h).norm().max(f64::MIN_POSITIVE) {
        return;
    }
    let (upper, lower) = (k - h, a - k);
    let (la, lb) = (upper.norm(), lower.norm());
    if la < 1e-12 || lb < 1e-12 {
        return;
    }
    let d = (want - h)
        .norm()
        .clamp((la - lb).abs() * (1.0 + 1e-9), (la + lb) * (1.0 - 1e-9));
    // 1. The knee bent about the leg's own bending axis so the ankle is d from the hip.
    let axis = upper.cross(lower);
    let axis = if axis.norm() > 1e-9 * la * lb {
        axis * (1.0 / axis.norm())
    } else {
        // A straight leg bends about the knee's own sideways axis.
        global[leg.knee] * Vec3::new(1.0, 0.0, 0.0)
    };
    let bend = |angle: f64| rotation_about(axis, angle);
    let current = (a - h).norm();
    let target_cos = ((la * la + lb * lb - d * d) / (2.0 * la * lb)).clamp(-1.0, 1.0);
    let current_cos = ((la * la + lb * lb - current * current) / (2.0 * la * lb)).clamp(-1.0, 1.0);
    let delta = current_cos.acos() - target_cos.acos();
    let bent = [bend(delta), bend(-delta)]
        .into_iter()
        .min_by(|r, s| {
            let reach = |r: &Mat3| ((k + *r * lower) - h).norm();
            (reach(r) - d).abs().total_cmp(&(reach(s) - d).abs())
        })
        .unwrap_or(sinmdm::motion::math::IDENTITY);
    let ankle_turn = global[leg.ankle];
    let lower_bent = bent * lower;
    // 2. The whole leg turned about the hip so the ankle points at `want`.
    let swing = shortest_rotation(upper + lower_bent, want - h);
    global[leg.hip] = swing * global[leg.hip];
    global[leg.knee] = swing * bent * global[leg.knee];
    position[leg.knee] = h + swing * upper;
    position[leg.ankle] = position[leg.knee] + swing * lower_bent;
    global[leg.ankle] = ankle_turn;
    // 3. Everything below the ankle moves with it.
    for j in (leg.ankle + 1)..skeleton.len() {
        if let Some(p) = skeleton.joints[j].parent
            && p >= leg.ankle
            && below(skeleton, leg.ankle, j)
        {
            position[j] = position[p] + global[p] * skeleton.joints[j].offset;
        }
    }
}

/// Whether joint `j` is below joint `top`.
fn below(skeleton: &Skeleton, top: usize, j: usize) -> bool {
    let mut at = skeleton.joints[j].parent;
    while let Some(p) = at {
        if p == top {
            return true;
        }
        at = skeleton.joints[p].parent;
    }
    false
}

/// The rotation by `angle` radians about unit `axis`.
fn rotation_about(axis: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = axis.to_array();
    Mat3([
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ])
}
