//! How fast the whole body turns: the rate at which the travelling root's heading turns about
//! the up axis, which the body's speeds (measured in the root's own frame) cannot see. A model
//! whose stretches of motion settle on different headings joins them with a swing faster than
//! the clip ever turns (lab/EXPERIMENTS.md, *A loss on frame changes, the normaliser's floor
//! and the dance's turns*). Reported beside the body's figures; not a goal.
//!
//! The heading is the root axis that lies flattest on the ground over the motion, projected on
//! the ground; a frame pair's rate is the angle between its two headings times the rate of
//! [`KINEMATIC_FPS`] (the unwrapped heading resampled linearly to it), in degrees per second.

use serde::{Deserialize, Serialize};
use sinmdm::motion::ground::percentile;
use sinmdm::motion::ground::travelling_root;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::up::UpAxis;
use sinmdm::motion::{LocalMotion, global_poses};

use crate::kinematics::{KINEMATIC_FPS, resampled, sorted};

/// The percentile of the turn rate compared with the clip's: the fastest turns, where a swing
/// shows, without the single fastest frame.
pub const TURN_PERCENTILE: f64 = 99.0;

/// Turns slower than this, in degrees per second (a whole turn in six minutes), are never
/// counted as faster than the clip: a clip that never turns would count its samples' rounding.
pub const LEAST_TURN: f64 = 1.0;

/// The clip's turn rates, which the samples' are measured against.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ClipTurning {
    /// Median turn rate, degrees per second.
    pub median: f64,
    /// Turn rate at [`TURN_PERCENTILE`], degrees per second.
    pub fast: f64,
    /// The fastest frame pair's turn rate, degrees per second.
    pub most: f64,
}

/// How fast samples turn against their clip.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TurnScores {
    /// The samples' turn rate at [`TURN_PERCENTILE`], degrees per second.
    pub fast: f64,
    /// Share (0..=1) of the samples' frame pairs turning faster than the clip's fastest (and
    /// than [`LEAST_TURN`]).
    pub faster_than_clip: f64,
}

/// Turn rates of the travelling root's heading, one per frame pair at [`KINEMATIC_FPS`], in
/// degrees per second; empty for a motion of fewer than two frames.
pub fn turn_rates(motion: &LocalMotion, up: UpAxis) -> Vec<f64> {
    let poses = global_poses(motion);
    if poses.len() < 2 || motion.skeleton.is_empty() {
        return Vec::new();
    }
    let root = travelling_root(&motion.skeleton, &poses);
    let up = up.direction();
    let flat = |v: Vec3| v - up * v.dot(up);
    let lying: [f64; 3] = std::array::from_fn(|k| {
        poses
            .iter()
            .map(|p| flat(p.rotations[root].column(k)).norm())
            .sum()
    });
    let axis = (0..3)
        .max_by(|&a, &b| lying[a].total_cmp(&lying[b]))
        .unwrap_or(0);
    let headings: Vec<Vec3> = poses
        .iter()
        .map(|p| flat(p.rotations[root].column(axis)))
        .collect();
    let mut angle = vec![0.0];
    for pair in headings.windows(2) {
        let turn = pair[0].cross(pair[1]).dot(up).atan2(pair[0].dot(pair[1]));
        angle.push(angle[angle.len() - 1] + turn);
    }
    resampled(&angle, motion.fps, KINEMATIC_FPS, |&a, &b, t| {
        a + (b - a) * t
    })
    .windows(2)
    .map(|w| (w[1] - w[0]).abs().to_degrees() * KINEMATIC_FPS)
    .collect()
}

impl ClipTurning {
    /// The figures of the clip's turn rates.
    pub fn new(rates: &[f64]) -> ClipTurning {
        let rates = sorted(rates);
        ClipTurning {
            median: percentile(&rates, 50.0),
            fast: percentile(&rates, TURN_PERCENTILE),
            most: rates.last().copied().unwrap_or(0.0),
        }
    }

    /// How the pooled turn rates of samples compare with the clip's.
    pub fn score(&self, samples: &[f64]) -> TurnScores {
        let bound = self.most.max(LEAST_TURN);
        let faster = samples.iter().filter(|&&r| r > bound).count();
        TurnScores {
            fast: percentile(&sorted(samples), TURN_PERCENTILE),
            faster_than_clip: if samples.is_empty() {
                0.0
            } else {
                faster as f64 / samples.len() as f64
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sinmdm::motion::math::{IDENTITY, axis_rotation};
    use sinmdm::motion::up::rotate_motion;
    use sinmdm::motion::{Joint, Skeleton};

    /// A two-joint body whose root turns about +Y by `degrees_per_frame[f]` between frames.
    fn turning(degrees_per_frame: &[f64], fps: f64) -> LocalMotion {
        let skeleton = Skeleton {
            joints: vec![
                Joint {
                    name: "hips".into(),
                    parent: None,
                    offset: Vec3([0.0, 1.0, 0.0]),
                    channels: Vec::new(),
                    end_site: None,
                },
                Joint {
                    name: "head".into(),
                    parent: Some(0),
                    offset: Vec3([0.0, 0.5, 0.0]),
                    channels: Vec::new(),
                    end_site: None,
                },
            ],
        };
        let mut heading = 0.0f64;
        let mut rotations = Vec::new();
        let mut translations = Vec::new();
        for f in 0..=degrees_per_frame.len() {
            if f > 0 {
                heading += degrees_per_frame[f - 1].to_radians();
            }
            rotations.push(axis_rotation(1, heading));
            rotations.push(IDENTITY);
            translations.push(Vec3([0.1 * f as f64, 1.0, 0.0]));
            translations.push(Vec3([0.0, 0.5, 0.0]));
        }
        LocalMotion {
            skeleton,
            fps,
            rotations,
            translations,
        }
    }

    #[test]
    fn a_steady_turn_has_its_rate_on_every_frame() {
        // 3 degrees a frame at 30 fps is 90 degrees a second, either way round.
        for sign in [1.0, -1.0] {
            let rates = turn_rates(&turning(&[3.0 * sign; 20], 30.0), UpAxis::PosY);
            assert_eq!(rates.len(), 20);
            for r in rates {
                assert!((r - 90.0).abs() < 1e-9, "{r}");
            }
        }
    }

    #[test]
    fn rates_are_per_second_whatever_the_frame_rate() {
        // 1.5 degrees a frame at 60 fps, read at 30 fps: 3 degrees a frame, 90 a second.
        let rates = turn_rates(&turning(&[1.5; 40], 60.0), UpAxis::PosY);
        assert_eq!(rates.len(), 20);
        assert!(rates.iter().all(|r| (r - 90.0).abs() < 1e-9), "{rates:?}");
    }

    #[test]
    fn a_z_up_file_turns_as_its_y_up_twin() {
        let y_up = turning(&[1.0, 4.0, -2.0, 0.5, 3.0], 30.0);
        let z_up = rotate_motion(&y_up, &UpAxis::PosZ.file_from_canonical());
        let (a, b) = (
            turn_rates(&y_up, UpAxis::PosY),
            turn_rates(&z_up, UpAxis::PosZ),
        );
        assert_eq!(a.len(), 5);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-9, "{a:?} {b:?}");
        }
        assert!((a[1] - 120.0).abs() < 1e-9, "{a:?}");
    }

    #[test]
    fn a_swing_is_counted_against_the_clips_fastest_turn() {
        let clip = ClipTurning::new(&turn_rates(&turning(&[2.0; 30], 30.0), UpAxis::PosY));
        assert!((clip.most - 60.0).abs() < 1e-9 && (clip.median - 60.0).abs() < 1e-9);
        // Held, then a swing of 10 degrees a frame over 3 frames, then held.
        let mut swing = vec![0.0; 30];
        swing[10..13].fill(10.0);
        let scores = clip.score(&turn_rates(&turning(&swing, 30.0), UpAxis::PosY));
        assert!((scores.faster_than_clip - 0.1).abs() < 1e-9, "{scores:?}");
        assert!((scores.fast - 300.0).abs() < 1e-9, "{scores:?}");
        // The clip against itself: nothing faster.
        let same = clip.score(&turn_rates(&turning(&[2.0; 30], 30.0), UpAxis::PosY));
        assert_eq!(same.faster_than_clip, 0.0);
        // Against a clip that never turns, a drift under LEAST_TURN is not turning; a turn is.
        let still = ClipTurning::new(&turn_rates(&turning(&[0.0; 30], 30.0), UpAxis::PosY));
        assert_eq!(still.most, 0.0);
        let drift = still.score(&turn_rates(&turning(&[0.01; 30], 30.0), UpAxis::PosY));
        assert_eq!(drift.faster_than_clip, 0.0);
        assert!(
            (still
                .score(&turn_rates(&turning(&swing, 30.0), UpAxis::PosY))
                .faster_than_clip
                - 0.1)
                .abs()
                < 1e-9
        );
    }
}
