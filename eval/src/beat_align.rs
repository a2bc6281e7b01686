//! How well a motion's kinematic beats (its speed minima, `sinmdm::motion::kinematic_beats`)
//! land on a piece of music's beats.
//!
//! - **Beat-hit rate**: the share of music beats with a motion beat within
//!   [`HIT_TOLERANCE_SECONDS`] (2 frames at 30 fps).
//! - **Beat Align Score** in Bailando's form: the mean over music beats of
//!   `exp(-d^2 / (2 sigma^2))`, `d` the distance in seconds to the nearest motion beat,
//!   `sigma` = [`BAS_SIGMA_SECONDS`].
//!
//! Both have a chance level (a motion with a beat every half second scores well against any
//! beats), so each comes with a control: the same beats shifted by a random share of their
//! interval, averaged over [`CONTROL_DRAWS`] shifts drawn from the portable noise words.

use serde::Serialize;
use sinmdm::diffusion::noise;

/// Largest distance from a music beat to a motion beat that counts as a hit, seconds.
pub const HIT_TOLERANCE_SECONDS: f64 = 2.0 / 30.0;
/// The Beat Align Score's sigma, seconds.
pub const BAS_SIGMA_SECONDS: f64 = 0.05;
/// Random-phase shifts averaged for the control scores.
pub const CONTROL_DRAWS: usize = 16;
/// Noise stream of the control's phase shifts.
pub const CONTROL_STREAM: u64 = 4_000_000;

/// Beat alignment of one motion against one set of music beats.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BeatScores {
    /// Share of music beats hit.
    pub hit_rate: f64,
    /// Beat Align Score.
    pub bas: f64,
    /// The hit rate against randomly shifted beats (mean over the draws).
    pub hit_rate_control: f64,
    /// The Beat Align Score against randomly shifted beats (mean over the draws).
    pub bas_control: f64,
}

fn nearest_distance(sorted: &[f64], t: f64) -> f64 {
    let i = sorted.partition_point(|&m| m < t);
    let after = sorted.get(i).map_or(f64::INFINITY, |m| m - t);
    let before = if i > 0 {
        t - sorted[i - 1]
    } else {
        f64::INFINITY
    };
    after.min(before)
}

/// Hit rate and Beat Align Score of motion beats `motion` against music beats `music` (both in
/// seconds, increasing).
pub fn hit_and_bas(motion: &[f64], music: &[f64]) -> (f64, f64) {
    if music.is_empty() {
        return (0.0, 0.0);
    }
    let (mut hits, mut bas) = (0usize, 0.0f64);
    for &t in music {
        let d = nearest_distance(motion, t);
        if d <= HIT_TOLERANCE_SECONDS + 1e-9 {
            hits += 1;
        }
        bas += (-d * d / (2.0 * BAS_SIGMA_SECONDS * BAS_SIGMA_SECONDS)).exp();
    }
    (hits as f64 / music.len() as f64, bas / music.len() as f64)
}

/// Scores of motion beats against music beats, and the random-phase control (`seed` picks the
/// shifts; music beats shifted past the last motion frame `duration` are dropped).
pub fn beat_scores(motion: &[f64], music: &[f64], duration: f64, seed: u64) -> BeatScores {
    let (hit_rate, bas) = hit_and_bas(motion, music);
    let interval = if music.len() >= 2 {
        (music[music.len() - 1] - music[0]) / (music.len() - 1) as f64
    } else {
        1.0
    };
    let (mut hit_sum, mut bas_sum, mut draws) = (0.0, 0.0, 0usize);
    for k in 0..CONTROL_DRAWS {
        let shift = noise::uniform(noise::word(seed, CONTROL_STREAM, k as u64)) * interval;
        let shifted: Vec<f64> = music
            .iter()
            .map(|t| t + shift)
            .filter(|&t| t <= duration)
            .collect();
        if shifted.is_empty() {
            continue;
        }
        let (h, b) = hit_and_bas(motion, &shifted);
        hit_sum += h;
        bas_sum += b;
        draws += 1;
    }
    let draws = draws.max(1) as f64;
    BeatScores {
        hit_rate,
        bas,
        hit_rate_control: hit_sum / draws,
        bas_control: bas_sum / draws,
    }
}

/// The mean of several motions' scores.
pub fn mean_beat_scores(scores: &[BeatScores]) -> BeatScores {
    let n = scores.len().max(1) as f64;
    let sum = |f: fn(&BeatScores) -> f64| scores.iter().map(f).sum::<f64>() / n;
    BeatScores {
        hit_rate: sum(|s| s.hit_rate),
        bas: sum(|s| s.bas),
        hit_rate_control: sum(|s| s.hit_rate_control),
        bas_control: sum(|s| s.bas_control),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beats_on_the_beat_score_one_and_a_known_offset_its_gaussian() {
        let music = [1.0, 1.5, 2.0, 2.5];
        assert_eq!(hit_and_bas(&music, &music), (1.0, 1.0));
        let late: Vec<f64> = music.iter().map(|t| t + 0.05).collect();
        let (hit, bas) = hit_and_bas(&late, &music);
        assert_eq!(hit, 1.0);
        assert!((bas - (-0.5f64).exp()).abs() < 1e-12);
        let off: Vec<f64> = music.iter().map(|t| t + 0.25).collect();
        let (hit, bas) = hit_and_bas(&off, &music);
        assert_eq!(hit, 0.0);
        assert!(bas < 1e-5);
    }

    #[test]
    fn the_control_of_aligned_beats_is_lower_than_the_score() {
        let music: Vec<f64> = (0..20).map(|k| 0.5 + 0.5 * k as f64).collect();
        let s = beat_scores(&music, &music, 11.0, 0);
        assert_eq!((s.hit_rate, s.bas), (1.0, 1.0));
        // Shifts are uniform over the interval: about a quarter of them land within the hit
        // tolerance of a beat on either side.
        assert!(s.bas_control < 0.5 && s.hit_rate_control < 0.6, "{s:?}");
        assert_eq!(s, beat_scores(&music, &music, 11.0, 0));
    }
}
