//! The ground a motion stands on: the joint that carries its travel, the body that joint carries
//! (every point but the static containers above it), and the level where its contact points rest.

use crate::motion::fk::{GlobalPose, mean_vertical_extent};
use crate::motion::math::Vec3;
use crate::motion::skeleton::Skeleton;
use crate::motion::up::height_of;

/// The ground is this percentile of the per-frame lowest contact point (SPEC section 9): low
/// enough to be the floor, robust to a few frames of a foot through it.
pub const GROUND_PERCENTILE: f64 = 5.0;

/// The points of a skeleton that belong to the body: every joint and End Site but the static
/// containers above the joint that carries the motion. A rig's root bone left at the world
/// origin while the hips walk away (Bandai's `joint_Root`) is no part of what stands on the floor.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Body {
    /// The joint that carries the body's motion.
    carrier: usize,
    /// Per joint, whether it is a container above the body.
    container: Vec<bool>,
}

impl Body {
    /// The body of `skeleton` whose motion `carrier` carries: that joint and all but its
    /// ancestors.
    pub fn carried_by(skeleton: &Skeleton, carrier: usize) -> Body {
        let mut container = vec![false; skeleton.len()];
        for above in skeleton.ancestors(carrier) {
            container[above] = true;
        }
        Body { carrier, container }
    }

    /// The body of a motion's canonical-frame `poses`: the one its [`travelling_root`] carries.
    pub fn travelling(skeleton: &Skeleton, poses: &[GlobalPose]) -> Body {
        Body::carried_by(skeleton, travelling_root(skeleton, poses))
    }

    /// The joint that carries the body's motion.
    pub fn carrier(&self) -> usize {
        self.carrier
    }

    /// Whether `joint` (and an End Site it carries) is part of the body.
    pub fn has(&self, joint: usize) -> bool {
        !self.container.get(joint).copied().unwrap_or(false)
    }

    /// The height of a canonical-frame pose's lowest point of the body (every joint and End Site
    /// but the containers'); infinity for none.
    pub fn lowest_point(&self, pose: &GlobalPose) -> f64 {
        self.points(pose)
            .map(height_of)
            .fold(f64::INFINITY, f64::min)
    }

    /// The body's height: the mean over frames of the vertical extent of its points (as
    /// [`skeleton_height`](crate::motion::fk::skeleton_height) over the whole skeleton); 0 for
    /// no frames.
    pub fn height(&self, poses: &[GlobalPose]) -> f64 {
        mean_vertical_extent(poses, |pose| self.points(pose))
    }

    /// The body's points of a canonical-frame pose, joints first, then End Sites.
    pub fn points<'a>(&'a self, pose: &'a GlobalPose) -> impl Iterator<Item = Vec3> + 'a {
        let joints = pose.joints.iter().enumerate();
        joints
            .chain(pose.end_sites.iter().map(|(j, p)| (*j, p)))
            .filter(|&(j, _)| self.has(j))
            .map(|(_, p)| *p)
    }
}

/// The joint that carries a clip's travel, from poses alone: the top joint, or, while it stays
/// put and has exactly one child, that child (some rigs have a static container above the hips).
/// Works in any frame: staying put is judged in all three dimensions.
pub fn travelling_root(skeleton: &Skeleton, poses: &[GlobalPose]) -> usize {
    let mut joint = 0;
    loop {
        let Some(first) = poses.first().map(|p| p.joints[joint]) else {
            return joint;
        };
        let still = poses
            .iter()
            .all(|p| (p.joints[joint] - first).norm() <= 1e-9 * (1.0 + first.norm()));
        match skeleton.children(joint).as_slice() {
            [only] if still => joint = *only,
            _ => return joint,
        }
    }
}

/// The ground level of canonical-frame `poses`: the [`GROUND_PERCENTILE`]th percentile of each
/// frame's lowest contact point of `contact_joints`, or of the body's lowest point when there
/// are no contact joints. 0 for no frames.
pub fn ground_level(contact_joints: &[usize], body: &Body, poses: &[GlobalPose]) -> f64 {
    let mut lowest: Vec<f64> = poses
        .iter()
        .map(|pose| {
            if contact_joints.is_empty() {
                body.lowest_point(pose)
            } else {
                contact_joints
                    .iter()
                    .map(|&j| height_of(pose.contact_point(j)))
                    .fold(f64::INFINITY, f64::min)
            }
        })
        .collect();
    lowest.sort_by(f64::total_cmp);
    percentile(&lowest, GROUND_PERCENTILE)
}

/// The `p`-th percentile of sorted values, linearly interpolated (numpy's default); 0 for none.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = p / 100.0 * (sorted.len() - 1) as f64;
    let (lo, hi) = (rank.floor() as usize, rank.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (rank - lo as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_matches_numpy_linear() {
        // numpy.percentile([1, 2, 3, 4, 10], 5) = 1.2
        assert!((percentile(&[1.0, 2.0, 3.0, 4.0, 10.0], 5.0) - 1.2).abs() < 1e-12);
        assert_eq!(percentile(&[7.0], 5.0), 7.0);
        assert_eq!(percentile(&[], 5.0), 0.0);
    }
}
