//! Forward kinematics: local transforms to global joint positions.

use super::clip::LocalMotion;
use super::math::{Mat3, Vec3};
use super::up::height_of;

/// Global positions of one frame: every joint, then every End Site (in joint order).
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalPose {
    /// Position of each joint.
    pub joints: Vec<Vec3>,
    /// Global rotation of each joint.
    pub rotations: Vec<Mat3>,
    /// Position of each End Site, paired with the index of the joint that carries it.
    pub end_sites: Vec<(usize, Vec3)>,
}

impl GlobalPose {
    /// Where a joint touches the ground: its End Site when it has one (the toe tip beyond a
    /// toe joint, the paw beyond a dog's wrist), else the joint itself.
    pub fn contact_point(&self, joint: usize) -> Vec3 {
        self.end_sites
            .iter()
            .find(|(j, _)| *j == joint)
            .map_or(self.joints[joint], |(_, p)| *p)
    }

    /// All points: joints first, then End Sites.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.joints
            .iter()
            .copied()
            .chain(self.end_sites.iter().map(|(_, p)| *p))
    }
}

/// Global joint positions and rotations of frame `frame`.
pub fn global_pose(motion: &LocalMotion, frame: usize) -> GlobalPose {
    let joints = &motion.skeleton.joints;
    let base = frame * joints.len();
    let mut positions: Vec<Vec3> = Vec::with_capacity(joints.len());
    let mut rotations: Vec<Mat3> = Vec::with_capacity(joints.len());
    let mut end_sites = Vec::new();
    for (j, joint) in joints.iter().enumerate() {
        let local_rotation = &motion.rotations[base + j];
        let local_translation = motion.translations[base + j];
        let (position, rotation) = match joint.parent {
            None => (local_translation, *local_rotation),
            Some(p) => (
                (positions[p] + (rotations[p] * local_translation)),
                (rotations[p] * local_rotation),
            ),
        };
        if let Some(end) = joint.end_site {
            end_sites.push((j, (position + (rotation * end))));
        }
        positions.push(position);
        rotations.push(rotation);
    }
    GlobalPose {
        joints: positions,
        rotations,
        end_sites,
    }
}

/// Global poses of every frame.
pub fn global_poses(motion: &LocalMotion) -> Vec<GlobalPose> {
    (0..motion.frame_count())
        .map(|f| global_pose(motion, f))
        .collect()
}

/// The skeleton's height: the mean over frames of the vertical extent of all joints and End
/// Sites, from canonical-frame poses ([`super::up`]). Measured on the posed clip rather than the
/// rest pose, because some rigs (the MANN dog) lie along +X at rest.
pub fn skeleton_height(poses: &[GlobalPose]) -> f64 {
    mean_vertical_extent(poses, GlobalPose::points)
}

/// The mean over `poses` of the vertical extent of the points `points` gives of each (the
/// body's alone, as the ground module's `Body` measures it); 0 for no poses.
pub fn mean_vertical_extent<'a, I: Iterator<Item = Vec3>>(
    poses: &'a [GlobalPose],
    points: impl Fn(&'a GlobalPose) -> I,
) -> f64 {
    if poses.is_empty() {
        return 0.0;
    }
    let total: f64 = poses
        .iter()
        .map(|pose| {
            let (lo, hi) = points(pose).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(height_of(p)), hi.max(height_of(p)))
            });
            hi - lo
        })
        .sum();
    total / poses.len() as f64
}

/// The largest distance between the same joint of two motions of one skeleton, over every
/// frame (how far a round trip moved anything); `None` when their frame or joint counts differ.
pub fn max_position_error(a: &LocalMotion, b: &LocalMotion) -> Option<f64> {
    if a.frame_count() != b.frame_count() || a.skeleton.len() != b.skeleton.len() {
        return None;
    }
    let worst = global_poses(a)
        .iter()
        .zip(&global_poses(b))
        .flat_map(|(p, q)| p.points().zip(q.points()))
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    Some(worst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math::axis_rotation;
    use crate::motion::skeleton::{Axis, Channel, Joint, Skeleton};
    use std::f64::consts::FRAC_PI_2;

    fn two_bone() -> Skeleton {
        let rot = vec![
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::X),
            Channel::Rotation(Axis::Y),
        ];
        let mut root_channels = vec![
            Channel::Position(Axis::X),
            Channel::Position(Axis::Y),
            Channel::Position(Axis::Z),
        ];
        root_channels.extend(rot.clone());
        Skeleton {
            joints: vec![
                Joint {
                    name: "root".into(),
                    parent: None,
                    offset: Vec3([0.0; 3]),
                    channels: root_channels,
                    end_site: None,
                },
                Joint {
                    name: "upper".into(),
                    parent: Some(0),
                    offset: Vec3([0.0, 2.0, 0.0]),
                    channels: rot.clone(),
                    end_site: None,
                },
                Joint {
                    name: "lower".into(),
                    parent: Some(1),
                    offset: Vec3([0.0, 3.0, 0.0]),
                    channels: rot,
                    end_site: Some(Vec3([0.0, 1.0, 0.0])),
                },
            ],
        }
    }

    #[test]
    fn two_bone_chain_matches_hand_computed_positions() {
        // Root at (1, 0, 0) turned +90 about Z; the upper bone turned +90 about X.
        // Root Z+90 maps local +Y to global -X: upper joint = (1,0,0) + (-2,0,0) = (-1,0,0).
        // Upper's global rotation = Rz(90) Rx(90); the lower offset (0,3,0) goes by Rx(90) to
        // (0,0,3), then by Rz(90) stays (0,0,3): lower = (-1, 0, 3). The End Site (0,1,0) with the
        // lower joint unrotated relative to upper goes the same way: (-1, 0, 4).
        let skeleton = two_bone();
        let motion = LocalMotion {
            skeleton,
            fps: 30.0,
            rotations: vec![
                axis_rotation(2, FRAC_PI_2),
                axis_rotation(0, FRAC_PI_2),
                crate::motion::math::IDENTITY,
            ],
            translations: vec![
                Vec3([1.0, 0.0, 0.0]),
                Vec3([0.0, 2.0, 0.0]),
                Vec3([0.0, 3.0, 0.0]),
            ],
        };
        let pose = global_pose(&motion, 0);
        let expect = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, 0.0, 3.0]];
        for (got, want) in pose.joints.iter().zip(expect) {
            assert!(((*got) - Vec3(want)).norm() < 1e-12, "{got:?} vs {want:?}");
        }
        assert_eq!(pose.end_sites.len(), 1);
        assert!((pose.end_sites[0].1 - Vec3([-1.0, 0.0, 4.0])).norm() < 1e-12);
    }

    #[test]
    fn height_of_an_upright_chain_is_its_length() {
        let skeleton = two_bone();
        let motion = LocalMotion {
            skeleton,
            fps: 30.0,
            rotations: vec![crate::motion::math::IDENTITY; 3],
            translations: vec![
                Vec3([0.0, 0.0, 0.0]),
                Vec3([0.0, 2.0, 0.0]),
                Vec3([0.0, 3.0, 0.0]),
            ],
        };
        assert!((skeleton_height(&global_poses(&motion)) - 6.0).abs() < 1e-12);
    }
}
