//! Kinematic beats: the moments a dancer's body comes (nearly) to rest, which dancers put on the
//! music's beats. Defined as in the AIST++ and Bailando benchmarks: the local minima of the
//! joints' mean speed after light Gaussian smoothing. The dance task places keyframes around
//! them, and the beat metrics of `sinmdm eval` read them from the output.

use super::clip::LocalMotion;
use super::fk::global_poses;

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

/// `values` smoothed by a Gaussian of `sigma` samples (cut at 4 sigma; edges mirrored).
pub fn gaussian_smooth(values: &[f64], sigma: f64) -> Vec<f64> {
    let n = values.len() as isize;
    if n == 0 || sigma <= 0.0 {
        return values.to_vec();
    }
    // The kernel never needs to reach past the input (an absurd frame rate would ask for more).
    let reach = (4.0 * sigma).ceil().min(n as f64) as isize;
    let kernel: Vec<f64> = (-reach..=reach)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let norm: f64 = kernel.iter().sum();
    let mirror = |mut i: isize| -> usize {
        // Reflect about the ends (…2 1 0 | 0 1 2…), repeatedly for short inputs.
        loop {
            if i < 0 {
                i = -i - 1;
            } else if i >= n {
                i = 2 * n - i - 1;
            } else {
                return i as usize;
            }
        }
    };
    (0..n)
        .map(|t| {
            kernel
                .iter()
                .enumerate()
                .map(|(k, w)| w * values[mirror(t + k as isize - reach)])
                .sum::<f64>()
                / norm
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
    fn smoothing_keeps_a_constant_and_a_mean() {
        let flat = gaussian_smooth(&[2.0; 9], 1.5);
        assert!(flat.iter().all(|v| (v - 2.0).abs() < 1e-12));
        let spike = gaussian_smooth(&[0.0, 0.0, 0.0, 0.0, 7.0, 0.0, 0.0, 0.0, 0.0], 1.0);
        assert!((spike.iter().sum::<f64>() - 7.0).abs() < 1e-9);
        assert!(spike[4] > spike[3] && spike[3] > spike[2] && (spike[3] - spike[5]).abs() < 1e-12);
    }

    #[test]
    fn minima_of_a_cosine_are_its_troughs() {
        // Period 20 frames, troughs at 10, 30, 50, 70.
        let v: Vec<f64> = (0..80)
            .map(|t| (2.0 * std::f64::consts::PI * t as f64 / 20.0).cos())
            .collect();
        assert_eq!(local_minima(&v), vec![10, 30, 50, 70]);
    }
}
