//! The chain of joints above a contact joint that foot planting may turn: the limb from just
//! below the joint where it branches off the body (the hip, the shoulder) down to the foot.

use crate::motion::math::Vec3;
use crate::motion::skeleton::Skeleton;

/// The most bones a chain has: a quadruped's leg (hip, knee, hock, paw) is three or four.
pub const MAX_CHAIN_BONES: usize = 4;
/// A last bone shorter than this share of the one above it is a foot: it keeps its global
/// rotation with the contact point, and the chain ends at the ankle (a human's hip-knee-ankle
/// is then solved analytically).
pub const FOOT_BONE_RATIO: f64 = 0.5;

/// The joints foot planting turns to put one contact point on its target.
#[derive(Debug, Clone, PartialEq)]
pub struct LegChain {
    /// The contact joint (its End Site, when it has one, is the contact point).
    pub contact: usize,
    /// The chain from its top (fixed in place, turned) to its effector (moved, keeping its
    /// global rotation so that everything below it, contact point included, moves rigidly).
    pub joints: Vec<usize>,
}

impl LegChain {
    /// The last joint of the chain, placed by the solver.
    pub fn effector(&self) -> usize {
        self.joints[self.joints.len() - 1]
    }

    /// Bones in the chain.
    pub fn bones(&self) -> usize {
        self.joints.len() - 1
    }
}

/// The chain above `contact`: walk up while the parent has no other child (a limb does not
/// branch), stop below the joint where it does; drop tops that sit on their parent (a zero
/// OFFSET, such as the CMU rigs' `LHipJoint`: turning them would swing the pelvis); keep at most
/// [`MAX_CHAIN_BONES`] bones; end at the ankle when the last bone is a foot
/// ([`FOOT_BONE_RATIO`]). `rest` holds each joint's offset from its parent (the layout's rest
/// translations). `None` when fewer than one bone is left (a contact joint on the root).
pub fn leg_chain(skeleton: &Skeleton, rest: &[Vec3], contact: usize) -> Option<LegChain> {
    let joints = &skeleton.joints;
    let children = |j: usize| joints.iter().filter(|c| c.parent == Some(j)).count();
    let mut limb = vec![contact];
    let mut j = contact;
    while let Some(parent) = joints.get(j).and_then(|joint| joint.parent) {
        if joints[parent].parent.is_none() || children(parent) != 1 {
            // `parent` is the root or a branching joint: `j` is the limb's top.
            break;
        }
        limb.push(parent);
        j = parent;
    }
    limb.reverse();
    let length = |j: usize| rest.get(j).map_or(0.0, |&o| o.norm());
    let total: f64 = limb.iter().skip(1).map(|&j| length(j)).sum();
    // A top whose own offset is nothing sits on its parent; its child's offset is a pelvis bone.
    while limb.len() > 2 && length(limb[0]) <= 1e-6 * total.max(f64::MIN_POSITIVE) {
        limb.remove(0);
    }
    if limb.len() > MAX_CHAIN_BONES + 1 {
        limb.drain(..limb.len() - MAX_CHAIN_BONES - 1);
    }
    if limb.len() > 3 {
        let last = length(limb[limb.len() - 1]);
        let before = length(limb[limb.len() - 2]);
        if last < FOOT_BONE_RATIO * before {
            limb.pop();
        }
    }
    (limb.len() >= 2).then_some(LegChain {
        contact,
        joints: limb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::skeleton::Joint;

    fn skeleton(spec: &[(&str, Option<usize>, Vec3)]) -> (Skeleton, Vec<Vec3>) {
        let joints = spec
            .iter()
            .map(|(name, parent, offset)| Joint {
                name: (*name).into(),
                parent: *parent,
                offset: *offset,
                channels: vec![],
                end_site: None,
            })
            .collect();
        (Skeleton { joints }, spec.iter().map(|s| s.2).collect())
    }

    #[test]
    fn a_human_leg_ends_at_the_ankle_below_a_zero_offset_hip_joint() {
        // Hips -> LHipJoint (on the hips) -> Hip -> Knee -> Ankle -> Toe; Hips -> Spine.
        let (s, rest) = skeleton(&[
            ("Hips", None, Vec3([0.0; 3])),
            ("LHipJoint", Some(0), Vec3([0.0; 3])),
            ("Hip", Some(1), Vec3([1.2, -1.6, 0.7])),
            ("Knee", Some(2), Vec3([2.5, -6.9, 0.0])),
            ("Ankle", Some(3), Vec3([2.4, -6.5, 0.0])),
            ("Toe", Some(4), Vec3([0.1, -0.4, 2.2])),
            ("Spine", Some(0), Vec3([0.0, 2.0, 0.0])),
        ]);
        let chain = leg_chain(&s, &rest, 5).unwrap();
        assert_eq!(chain.joints, vec![2, 3, 4]);
        assert_eq!(chain.effector(), 4);
    }

    #[test]
    fn a_quadruped_leg_keeps_its_three_bones() {
        // Hip -> Leg01 -> Leg02 -> Foot01 -> Foot02 (paw); Hip -> Tail.
        let (s, rest) = skeleton(&[
            ("Hip", None, Vec3([0.0; 3])),
            ("Leg01", Some(0), Vec3([4.8, 5.2, -7.0])),
            ("Leg02", Some(1), Vec3([18.9, 0.0, 0.0])),
            ("Foot01", Some(2), Vec3([17.9, 0.0, 0.0])),
            ("Foot02", Some(3), Vec3([15.8, 0.0, 0.0])),
            ("Tail", Some(0), Vec3([4.0, 16.0, 0.0])),
        ]);
        let chain = leg_chain(&s, &rest, 4).unwrap();
        assert_eq!(chain.joints, vec![1, 2, 3, 4]);
        assert_eq!(chain.bones(), 3);
        // A contact on the root has no chain.
        assert!(leg_chain(&s, &rest, 0).is_none());
    }
}
