//! Kinematic fidelity: whether samples move like their clip, at its speeds and accelerations,
//! rather than freezing, drifting slowly ("floaty") or shaking. Coverage, diversity and replay
//! cannot see this: a model that outputs the clip's mean pose with a little noise covers a calm
//! clip, copies nothing and is smooth.
//!
//! Every joint below the root is placed relative to the root joint, in the root's own frame (the
//! body's motion, without travel or turning), divided by the skeleton height H and resampled to
//! [`KINEMATIC_FPS`] (linearly), so figures compare across clips and frame rates. The root is
//! the joint that carries the body ([`travelling_root`]): a still ground joint above the hips,
//! as some rigs have, would otherwise count the body's travel as its motion. A frame
//! pair's *speed* is the mean over those joints of the distance moved times the rate (H/s); a
//! frame's *acceleration* the mean length of the second difference times the rate squared
//! (H/s²). Samples are pooled and compared with the clip by:
//! - the share of nearly still frames: slower than [`NEARLY_STILL`] times the clip's median
//!   speed, against the clip's own share;
//! - the ratios of the speeds' 25th, 50th and 90th percentiles to the clip's;
//! - the 1-Wasserstein distance between the pooled speeds and the clip's (accelerations and the
//!   clip's), divided by the clip's mean speed (acceleration): 0 is the same distribution, 1 is
//!   as far as a motion that never moves.

use serde::{Deserialize, Serialize};
use sinmdm::motion::LocalMotion;
use sinmdm::motion::ground::percentile;
use sinmdm::motion::ground::travelling_root;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::{GlobalPose, global_poses};

/// The rate the figures are measured at, frames per second: speeds and accelerations of finite
/// differences depend on the step, so every motion is resampled to one.
pub const KINEMATIC_FPS: f64 = 30.0;
/// A frame is nearly still when its speed is under this share of the clip's median speed.
pub const NEARLY_STILL: f64 = 0.25;
/// The percentiles of speed compared with the clip's.
pub const SPEED_PERCENTILES: [f64; 3] = [25.0, 50.0, 90.0];

/// The bounds a model's samples must meet to move like their clip.
pub mod goals {
    /// Nearly still frames: at most the clip's share plus this (a share, 0..=1).
    pub const STILL_SHARE_MARGIN: f64 = 0.05;
    /// Each speed percentile at least this multiple of the clip's ...
    pub const LEAST_SPEED_RATIO: f64 = 0.8;
    /// ... and at most this multiple.
    pub const MOST_SPEED_RATIO: f64 = 1.25;
    /// The speed distributions' distance, in the clip's mean speeds.
    pub const SPEED_DISTANCE: f64 = 0.2;
    /// The acceleration distributions' distance, in the clip's mean accelerations.
    pub const ACCELERATION_DISTANCE: f64 = 0.5;
}

/// Per-frame speeds and accelerations of one motion or several pooled (see the module
/// documentation).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Kinematics {
    /// Mean joint speed of each frame pair, in H per second.
    pub speeds: Vec<f64>,
    /// Mean joint acceleration of each inner frame, in H per second squared.
    pub accelerations: Vec<f64>,
}

impl Kinematics {
    /// The figures of `motion`, whose skeleton is `height` tall (file units).
    pub fn of_motion(motion: &LocalMotion, height: f64) -> Kinematics {
        let body = resampled(
            &root_relative(motion, &global_poses(motion), height),
            motion.fps,
            KINEMATIC_FPS,
            |a, b, t| lerp_points(a, b, t),
        );
        Kinematics::of_positions(&body, KINEMATIC_FPS)
    }

    /// The figures of several motions, pooled.
    pub fn of_motions(motions: &[LocalMotion], height: f64) -> Kinematics {
        let mut pooled = Kinematics::default();
        for motion in motions {
            let one = Kinematics::of_motion(motion, height);
            pooled.speeds.extend(one.speeds);
            pooled.accelerations.extend(one.accelerations);
        }
        pooled
    }

    /// The figures of positions `[frames][points]` (already in H) at `fps`.
    pub fn of_positions(frames: &[Vec<Vec3>], fps: f64) -> Kinematics {
        let mean_length = |vectors: &mut dyn Iterator<Item = Vec3>| {
            let (sum, n) = vectors.fold((0.0, 0usize), |(s, n), v| (s + v.norm(), n + 1));
            if n == 0 { 0.0 } else { sum / n as f64 }
        };
        let speeds = frames
            .windows(2)
            .map(|w| {
                let mut moved = w[0].iter().zip(&w[1]).map(|(&a, &b)| b - a);
                mean_length(&mut moved) * fps
            })
            .collect();
        let accelerations = frames
            .windows(3)
            .map(|w| {
                let mut second = (0..w[1].len()).map(|j| (w[2][j] - w[1][j]) + (w[0][j] - w[1][j]));
                mean_length(&mut second) * fps * fps
            })
            .collect();
        Kinematics {
            speeds,
            accelerations,
        }
    }
}

/// Every joint but the travelling root and the still joints above it, relative to the
/// travelling root in its own frame, divided by `height`: `[frames][joints]`.
fn root_relative(motion: &LocalMotion, poses: &[GlobalPose], height: f64) -> Vec<Vec<Vec3>> {
    let h = height.max(f64::MIN_POSITIVE);
    let joints = &motion.skeleton.joints;
    if joints.is_empty() || poses.is_empty() {
        return vec![Vec::new(); poses.len()];
    }
    let root = travelling_root(&motion.skeleton, poses);
    let mut above = vec![false; joints.len()];
    let mut chain = Some(root);
    while let Some(j) = chain {
        above[j] = true;
        chain = joints[j].parent;
    }
    poses
        .iter()
        .map(|pose| {
            let origin = pose.joints[root];
            let into_root = pose.rotations[root].transpose();
            joints
                .iter()
                .enumerate()
                .filter(|&(j, joint)| !above[j] && joint.parent.is_some())
                .map(|(j, _)| (into_root * (pose.joints[j] - origin)) * (1.0 / h))
                .collect()
        })
        .collect()
}

/// `frames` taken at `from` frames per second, linearly interpolated at `to` frames per second
/// over the same span (the last frame at or before the source's end), `lerp(a, b, t)` giving
/// the frame a share `t` of the way from `a` to `b`.
pub(crate) fn resampled<T: Clone>(
    frames: &[T],
    from: f64,
    to: f64,
    lerp: impl Fn(&T, &T, f64) -> T,
) -> Vec<T> {
    if frames.len() < 2 || (from - to).abs() < 1e-9 || !(from > 0.0 && to > 0.0) {
        return frames.to_vec();
    }
    let last = (frames.len() - 1) as f64;
    let count = (last * to / from + 1e-9).floor() as usize + 1;
    (0..count)
        .map(|k| {
            let at = (k as f64 * from / to).min(last);
            let lo = at.floor() as usize;
            let hi = (lo + 1).min(frames.len() - 1);
            lerp(&frames[lo], &frames[hi], at - lo as f64)
        })
        .collect()
}

/// Points `a` a share `t` of the way to `b`, point by point.
fn lerp_points(a: &[Vec3], b: &[Vec3], t: f64) -> Vec<Vec3> {
    a.iter().zip(b).map(|(&a, &b)| a + (b - a) * t).collect()
}

/// The 1-Wasserstein distance between the empirical distributions of `a` and `b`: the area
/// between their cumulative distribution functions. 0 when either is empty.
pub fn wasserstein_1(a: &[f64], b: &[f64]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let (a, b) = (sorted(a), sorted(b));
    let (mut i, mut j) = (0usize, 0usize);
    let mut area = 0.0;
    let mut x = a[0].min(b[0]);
    while i < a.len() || j < b.len() {
        // The next point where either distribution function steps.
        let next = match (a.get(i), b.get(j)) {
            (Some(&p), Some(&q)) => p.min(q),
            (Some(&p), None) => p,
            (None, Some(&q)) => q,
            (None, None) => break,
        };
        let gap = i as f64 / a.len() as f64 - j as f64 / b.len() as f64;
        area += gap.abs() * (next - x);
        x = next;
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
    }
    area
}

/// The clip's own figures, which the samples' are measured against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipKinematics {
    /// The speeds at [`SPEED_PERCENTILES`], in H per second.
    pub speed_percentiles: [f64; 3],
    /// Under this speed a frame is nearly still: [`NEARLY_STILL`] times the median.
    pub still_speed: f64,
    /// Share (0..=1) of the clip's frames that are nearly still.
    pub still_share: f64,
    /// Mean speed, H per second.
    pub mean_speed: f64,
    /// Mean acceleration, H per second squared.
    pub mean_acceleration: f64,
}

/// How samples move against their clip (see the module documentation).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct KinematicScores {
    /// Share (0..=1) of the samples' frames that are nearly still.
    pub still_share: f64,
    /// The samples' speeds at [`SPEED_PERCENTILES`], in H per second.
    pub speed_percentiles: [f64; 3],
    /// Each of those over the clip's.
    pub speed_ratios: [f64; 3],
    /// Distance of the speed distributions, in the clip's mean speeds.
    pub speed_distance: f64,
    /// Distance of the acceleration distributions, in the clip's mean accelerations.
    pub acceleration_distance: f64,
}

/// One bound of [`goals`] that samples miss, and by how much.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicMiss {
    /// What is measured, as a reader would name it.
    pub figure: &'static str,
    /// The samples' value.
    pub value: f64,
    /// The bound it misses.
    pub bound: f64,
}

impl std::fmt::Display for KinematicMiss {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {:.3} against the bound {:.3}",
            self.figure, self.value, self.bound
        )
    }
}

impl ClipKinematics {
    /// The clip's figures.
    pub fn new(clip: &Kinematics) -> ClipKinematics {
        let speeds = sorted(&clip.speeds);
        let still_speed = NEARLY_STILL * percentile(&speeds, 50.0);
        ClipKinematics {
            speed_percentiles: SPEED_PERCENTILES.map(|p| percentile(&speeds, p)),
            still_speed,
            still_share: still_share(&speeds, still_speed),
            mean_speed: crate::mean(&clip.speeds),
            mean_acceleration: crate::mean(&clip.accelerations),
        }
    }

    /// How `samples` (pooled) move against the clip `clip`, whose figures these are.
    pub fn score(&self, clip: &Kinematics, samples: &Kinematics) -> KinematicScores {
        let speeds = sorted(&samples.speeds);
        let speed_percentiles = SPEED_PERCENTILES.map(|p| percentile(&speeds, p));
        let mut speed_ratios = [0.0; 3];
        for (ratio, (&made, &wanted)) in speed_ratios
            .iter_mut()
            .zip(speed_percentiles.iter().zip(&self.speed_percentiles))
        {
            *ratio = ratio_to(made, wanted);
        }
        KinematicScores {
            still_share: still_share(&speeds, self.still_speed),
            speed_percentiles,
            speed_ratios,
            speed_distance: ratio_to(
                wasserstein_1(&samples.speeds, &clip.speeds),
                self.mean_speed,
            ),
            acceleration_distance: ratio_to(
                wasserstein_1(&samples.accelerations, &clip.accelerations),
                self.mean_acceleration,
            ),
        }
    }
}

impl KinematicScores {
    /// The bounds of [`goals`] these scores miss, against a clip whose nearly still share is
    /// `clip_still_share`; empty when the samples move like the clip.
    pub fn misses(&self, clip_still_share: f64) -> Vec<KinematicMiss> {
        let mut misses = Vec::new();
        let still_bound = clip_still_share + goals::STILL_SHARE_MARGIN;
        if self.still_share > still_bound {
            misses.push(KinematicMiss {
                figure: "nearly still share",
                value: self.still_share,
                bound: still_bound,
            });
        }
        for (ratio, p) in self.speed_ratios.iter().zip(SPEED_PERCENTILES) {
            let figure = match p as u32 {
                25 => "speed p25 / clip's",
                50 => "speed p50 / clip's",
                _ => "speed p90 / clip's",
            };
            if *ratio < goals::LEAST_SPEED_RATIO {
                misses.push(KinematicMiss {
                    figure,
                    value: *ratio,
                    bound: goals::LEAST_SPEED_RATIO,
                });
            } else if *ratio > goals::MOST_SPEED_RATIO {
                misses.push(KinematicMiss {
                    figure,
                    value: *ratio,
                    bound: goals::MOST_SPEED_RATIO,
                });
            }
        }
        for (figure, value, bound) in [
            ("speed distance", self.speed_distance, goals::SPEED_DISTANCE),
            (
                "acceleration distance",
                self.acceleration_distance,
                goals::ACCELERATION_DISTANCE,
            ),
        ] {
            if value > bound {
                misses.push(KinematicMiss {
                    figure,
                    value,
                    bound,
                });
            }
        }
        misses
    }
}

/// `values` in ascending order.
pub(crate) fn sorted(values: &[f64]) -> Vec<f64> {
    let mut s = values.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// Share of sorted `speeds` under `threshold`; 0 for none.
fn still_share(speeds: &[f64], threshold: f64) -> f64 {
    if speeds.is_empty() {
        return 0.0;
    }
    speeds.partition_point(|&s| s < threshold) as f64 / speeds.len() as f64
}

/// `made / wanted`, with 1 where both are 0 and a large finite number where only `wanted` is
/// (JSON has no infinity).
fn ratio_to(made: f64, wanted: f64) -> f64 {
    if wanted > 0.0 {
        made / wanted
    } else if made > 0.0 {
        1e9
    } else if made == 0.0 {
        1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wasserstein_of_known_distributions() {
        // A shift moves every quantile by the same amount.
        assert!((wasserstein_1(&[0.0, 1.0, 3.0], &[2.0, 3.0, 5.0]) - 2.0).abs() < 1e-12);
        // scipy.stats.wasserstein_distance([0, 1, 3], [5, 6, 8, 9]) = 17 / 3
        assert!(
            (wasserstein_1(&[0.0, 1.0, 3.0], &[5.0, 6.0, 8.0, 9.0]) - 17.0 / 3.0).abs() < 1e-12
        );
        // Against all zeros: the mean of the non-negative values.
        assert!((wasserstein_1(&[1.0, 2.0, 6.0], &[0.0; 5]) - 3.0).abs() < 1e-12);
        assert_eq!(wasserstein_1(&[2.0, 1.0], &[1.0, 2.0]), 0.0);
        assert_eq!(wasserstein_1(&[], &[1.0]), 0.0);
    }

    /// A point on a circle of radius 1 turning at `omega` radians per frame, `frames` frames.
    fn circle(frames: usize, omega: f64) -> Vec<Vec<Vec3>> {
        (0..frames)
            .map(|i| {
                let a = omega * i as f64;
                vec![Vec3([a.cos(), a.sin(), 0.0])]
            })
            .collect()
    }

    #[test]
    fn a_circle_has_its_chord_speed_and_centripetal_acceleration() {
        let omega = 0.1;
        let k = Kinematics::of_positions(&circle(40, omega), 30.0);
        let chord = 2.0 * (omega / 2.0).sin() * 30.0;
        let second = 2.0 * (1.0 - omega.cos()) * 900.0;
        assert!(k.speeds.iter().all(|s| (s - chord).abs() < 1e-12));
        assert!(k.accelerations.iter().all(|a| (a - second).abs() < 1e-9));
        assert_eq!((k.speeds.len(), k.accelerations.len()), (39, 38));
    }

    #[test]
    fn resampling_to_half_the_rate_keeps_a_straight_lines_speed() {
        let line: Vec<Vec<Vec3>> = (0..61).map(|i| vec![Vec3([i as f64, 0.0, 0.0])]).collect();
        let half = resampled(&line, 60.0, 30.0, |a, b, t| lerp_points(a, b, t));
        assert_eq!(half.len(), 31);
        let k = Kinematics::of_positions(&half, 30.0);
        assert!(k.speeds.iter().all(|s| (s - 60.0).abs() < 1e-9));
        // 1 frame per 2 at 60 fps, 2 at 30 fps: the other way interpolates.
        let double = resampled(&half, 30.0, 60.0, |a, b, t| lerp_points(a, b, t));
        assert_eq!(double.len(), 61);
        assert!((double[7][0][0] - 7.0).abs() < 1e-12);
    }

    fn scores(clip: &Kinematics, samples: &Kinematics) -> (ClipKinematics, KinematicScores) {
        let figures = ClipKinematics::new(clip);
        let s = figures.score(clip, samples);
        (figures, s)
    }

    #[test]
    fn the_clip_against_itself_is_faithful() {
        let varied: Vec<Vec<Vec3>> = (0..90)
            .map(|i| {
                let a = 0.02 * (i as f64) * (i as f64) / 10.0;
                vec![Vec3([a.cos(), a.sin(), 0.1 * (i as f64 * 0.3).sin()])]
            })
            .collect();
        let clip = Kinematics::of_positions(&varied, 30.0);
        let (figures, s) = scores(&clip, &clip);
        assert_eq!(s.speed_ratios, [1.0; 3]);
        assert_eq!((s.speed_distance, s.acceleration_distance), (0.0, 0.0));
        assert_eq!(s.still_share, figures.still_share);
        assert!(s.misses(figures.still_share).is_empty());
    }

    #[test]
    fn a_held_pose_is_still_throughout_and_one_mean_away() {
        let clip = Kinematics::of_positions(&circle(60, 0.1), 30.0);
        let held = Kinematics::of_positions(&vec![vec![Vec3([1.0, 0.0, 0.0])]; 60], 30.0);
        let (figures, s) = scores(&clip, &held);
        assert_eq!(figures.still_share, 0.0);
        assert_eq!(s.still_share, 1.0);
        assert_eq!(s.speed_ratios, [0.0; 3]);
        assert!((s.speed_distance - 1.0).abs() < 1e-12);
        assert!((s.acceleration_distance - 1.0).abs() < 1e-9);
        let missed: Vec<&str> = s.misses(0.0).iter().map(|m| m.figure).collect();
        assert_eq!(
            missed,
            [
                "nearly still share",
                "speed p25 / clip's",
                "speed p50 / clip's",
                "speed p90 / clip's",
                "speed distance",
                "acceleration distance"
            ]
        );
    }

    #[test]
    fn half_the_pace_halves_the_speeds_and_quarters_the_accelerations() {
        let clip = Kinematics::of_positions(&circle(120, 0.1), 30.0);
        let slow = Kinematics::of_positions(&circle(240, 0.05), 30.0);
        let (_, s) = scores(&clip, &slow);
        for r in s.speed_ratios {
            // Chords of half the angle: sin(0.025) / sin(0.05) ~ 0.5.
            assert!((r - 0.5).abs() < 1e-3, "{r}");
        }
        assert!((s.speed_distance - 0.5).abs() < 1e-3);
        assert!((s.acceleration_distance - 0.75).abs() < 1e-3);
        assert!(!s.misses(0.0).is_empty());
    }

    #[test]
    fn still_share_counts_frames_under_a_quarter_of_the_median() {
        // Speeds 0..9 pooled: median 4.5, threshold 1.125: 0 and 1 are still.
        let clip = Kinematics {
            speeds: (0..10).map(f64::from).collect(),
            accelerations: vec![1.0],
        };
        let (figures, _) = scores(&clip, &clip);
        assert!((figures.still_speed - 1.125).abs() < 1e-12);
        assert!((figures.still_share - 0.2).abs() < 1e-12);
    }
}
