//! Kinematic beats: the moments a dancer's body comes (nearly) to rest, which dancers put on the
//! music's beats. Defined as in the AIST++ and Bailando benchmarks: the local minima of the
//! joints' mean speed after light Gaussian smoothing. The dance task places keyframes around
//! them, and the beat metrics of `sinmdm eval` read them from the output.

use super::clip::LocalMotion;
use super::fk::global_poses;
use super::smooth::gaussian_smooth;

/// Standard deviation of the speed curve's Gaussian smoothing, in seconds (5 frames at 60 fps,
/// the benchmarks' setting).
pub const BEAT_SMOOTHING_SECONDS: f64 = 1.0 / 12.0;

/// The kinematic beats of a motion.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicBeats {
    /// Frames of the smoothed speed's local minima, increasing. (A dance rests between its beats
    /// too, so the gaps between minima do not give its tempo: `sinmdm-beats`'
    /// `pulses::motion_beats` finds the beat among them.)
    pub frames: Vec<usize>,
    /// The smoothed mean joint speed per frame (file units per second).
    pub speed: Vec<f64>,
}

/// Mean speed of the joints per frame (central differences inside, one-sided at the ends), in
/// the motion's units per second.
pub fn joint_speed(motion: &LocalMotion) -> Vec<f64> {
    let poses = global_poses(motion);
    let n = poses.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let joints = motion.skeleton.len().max(1);
    (0..n)
        .map(|t| {
            let (a, b) = (t.saturating_sub(1), (t + 1).min(n - 1));
            let dt = (b - a) as f64 / motion.fps;
            let total: f64 = poses[a]
                .joints
                .iter()
                .zip(&poses[b].joints)
                .map(|(p, q)| {
                    ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt()
                })
                .sum();
            total / joints as f64 / dt
        })
        .collect()
}

/// Strict local minima: frames lower than the one before and no higher than the one after
/// (the first and last frame never count).
pub fn local_minima(values: &[f64]) -> Vec<usize> {
    (1..values.len().saturating_sub(1))
        .filter(|&t| values[t] < values[t - 1] && values[t] <= values[t + 1])
        .collect()
}

/// The kinematic beats of `motion` (see the module documentation).
pub fn kinematic_beats(motion: &LocalMotion) -> KinematicBeats {
    let speed = gaussian_smooth(&joint_speed(motion), BEAT_SMOOTHING_SECONDS * motion.fps);
    KinematicBeats {
        frames: local_minima(&speed),
        speed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minima_of_a_cosine_are_its_troughs() {
        // Period 20 frames, troughs at 10, 30, 50, 70.
        let v: Vec<f64> = (0..80)
            .map(|t| (2.0 * std::f64::consts::PI * t as f64 / 20.0).cos())
            .collect();
        assert_eq!(local_minima(&v), vec![10, 30, 50, 70]);
    }
}
