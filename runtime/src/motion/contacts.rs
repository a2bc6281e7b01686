//! Foot-contact labels: a joint is in contact while its contact point (its End Site when it has
//! one, else the joint) moves slower than a threshold.
//!
//! Thresholds are relative to the skeleton's height, so the same settings work for a clip in
//! metres, centimetres or CMU units.

use serde::{Deserialize, Serialize};

use super::fk::GlobalPose;
use super::math::{self, Vec3};
use super::skeleton::Skeleton;

/// How contact joints are chosen and labelled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactConfig {
    /// Joint names to label. `None` chooses automatically: the chain ends (joints without
    /// child joints) whose contact point comes within `ground_fraction` of the skeleton height
    /// of the lowest point of the whole clip.
    pub joints: Option<Vec<String>>,
    /// A joint is in contact while its speed is below this many skeleton heights per second.
    pub speed_threshold: f64,
    /// See `joints`.
    pub ground_fraction: f64,
}

impl Default for ContactConfig {
    fn default() -> Self {
        ContactConfig {
            joints: None,
            speed_threshold: 0.2,
            ground_fraction: 0.05,
        }
    }
}

/// The chain-end joints whose contact point comes within `ground_fraction * height` of the
/// clip's lowest point.
pub fn choose_contact_joints(
    skeleton: &Skeleton,
    poses: &[GlobalPose],
    height: f64,
    ground_fraction: f64,
) -> Vec<usize> {
    let lowest_of = |joint: usize| {
        poses
            .iter()
            .map(|p| p.contact_point(joint)[1])
            .fold(f64::INFINITY, f64::min)
    };
    let ground = poses
        .iter()
        .flat_map(|p| p.points())
        .map(|p| p[1])
        .fold(f64::INFINITY, f64::min);
    skeleton
        .leaves()
        .into_iter()
        .filter(|&j| lowest_of(j) - ground <= ground_fraction * height)
        .collect()
}

/// Speed of one joint at every frame (units per second), by central differences (one-sided at
/// the ends).
pub fn joint_speeds(positions: &[Vec3], fps: f64) -> Vec<f64> {
    let n = positions.len();
    if n < 2 {
        return vec![0.0; n];
    }
    (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            math::norm(math::sub(positions[b], positions[a])) * fps / (b - a) as f64
        })
        .collect()
}

/// Contact labels (1 = in contact) of `joint` over the clip.
pub fn contact_labels(
    poses: &[GlobalPose],
    joint: usize,
    fps: f64,
    height: f64,
    speed_threshold: f64,
) -> Vec<f32> {
    let positions: Vec<Vec3> = poses.iter().map(|p| p.contact_point(joint)).collect();
    joint_speeds(&positions, fps)
        .into_iter()
        .map(|s| {
            if s < speed_threshold * height {
                1.0
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math::IDENTITY;

    fn pose(points: &[Vec3]) -> GlobalPose {
        GlobalPose {
            joints: points.to_vec(),
            rotations: vec![IDENTITY; points.len()],
            end_sites: vec![],
        }
    }

    #[test]
    fn a_foot_that_stops_and_moves_is_labelled_by_its_speed() {
        // 30 fps. The foot steps forward between frames 9 and 19 (ten steps at 2 heights/s) and
        // rests before and after. With central differences frames 9 and 19 see one step over two
        // frames, 1 height/s: still above the 0.15 threshold; frames 8 and 20 see no step.
        let height = 1.8;
        let mut x = 0.0;
        let mut points = Vec::new();
        for f in 0..30 {
            if (10..20).contains(&f) {
                x += 2.0 * height / 30.0;
            }
            points.push(pose(&[[x, 0.0, 0.0]]));
        }
        let labels = contact_labels(&points, 0, 30.0, height, 0.15);
        let expected: Vec<f32> = (0..30)
            .map(|f| if (9..=19).contains(&f) { 0.0 } else { 1.0 })
            .collect();
        assert_eq!(labels, expected);
    }

    #[test]
    fn speeds_use_central_differences() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]];
        assert_eq!(joint_speeds(&positions, 10.0), vec![10.0, 15.0, 20.0]);
    }

    #[test]
    fn automatic_choice_takes_chain_ends_near_the_ground() {
        use crate::motion::skeleton::{Joint, Skeleton};
        let joint = |name: &str, parent| Joint {
            name: name.into(),
            parent,
            offset: [0.0; 3],
            channels: vec![],
            end_site: None,
        };
        // root -> foot (leaf, at the ground) and root -> hand (leaf, high up).
        let skeleton = Skeleton {
            joints: vec![
                joint("root", None),
                joint("foot", Some(0)),
                joint("hand", Some(0)),
            ],
        };
        let poses = vec![pose(&[[0.0, 1.0, 0.0], [0.0, 0.02, 0.0], [0.0, 1.4, 0.0]])];
        assert_eq!(choose_contact_joints(&skeleton, &poses, 1.4, 0.05), vec![1]);
    }
}
