//! The beat sequence: dynamic programming over envelope frames (Ellis 2007).
//!
//! Each frame's local score is the envelope (divided by its standard deviation) smoothed by a
//! Gaussian of standard deviation period / 32. A beat at frame `i` follows the best previous beat
//! `j` between half a period and two periods earlier, scored by the previous beat's cumulative
//! score less `tightness * ln((i - j) / period)^2`. The sequence is read back from the last
//! strong cumulative peak; weak beats at its ends (silence before the music starts or after it
//! stops) are trimmed.

use crate::window::convolve_same;

/// Beat frames of an onset envelope with beat period `period` (envelope frames).
pub fn beat_frames(onset: &[f32], period: f64, tightness: f64) -> Vec<usize> {
    let n = onset.len();
    if n == 0 || period < 1.0 {
        return Vec::new();
    }
    let local = local_score(onset, period);
    let peak = local.iter().cloned().fold(0.0f64, f64::max);
    if peak <= 0.0 {
        return Vec::new();
    }
    let nearest = ((period / 2.0).round() as usize).max(1);
    let farthest = ((2.0 * period).round() as usize).max(nearest);
    let mut cumulative = vec![0.0f64; n];
    let mut back: Vec<Option<usize>> = vec![None; n];
    let mut started = false;
    for i in 0..n {
        let mut best: Option<(usize, f64)> = None;
        if i >= nearest {
            let lo = i.saturating_sub(farthest);
            for (j, &before) in cumulative.iter().enumerate().take(i - nearest + 1).skip(lo) {
                let gap = (i - j) as f64 / period;
                let score = before - tightness * gap.ln().powi(2);
                if best.is_none_or(|(_, s)| score > s) {
                    best = Some((j, score));
                }
            }
        }
        match best {
            // A beat may also open a new sequence, when every predecessor would cost more
            // than it brings.
            Some((j, score)) if score > 0.0 && (started || local[i] >= 0.01 * peak) => {
                cumulative[i] = local[i] + score;
                back[i] = Some(j);
                started = true;
            }
            _ => cumulative[i] = local[i],
        }
    }
    let Some(last) = last_beat(&cumulative, &local, peak) else {
        return Vec::new();
    };
    let mut beats = vec![last];
    let mut at = last;
    while let Some(j) = back[at] {
        beats.push(j);
        at = j;
    }
    beats.reverse();
    trim_weak_ends(&beats, &local)
}

/// The envelope over its standard deviation, smoothed by a Gaussian of `period / 32` frames
/// (cut at one period each side).
fn local_score(onset: &[f32], period: f64) -> Vec<f64> {
    let n = onset.len();
    let mean = onset.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let variance = onset
        .iter()
        .map(|&v| (v as f64 - mean).powi(2))
        .sum::<f64>()
        / (n.max(2) - 1) as f64;
    let scale = if variance > 0.0 {
        1.0 / variance.sqrt()
    } else {
        1.0
    };
    let reach = period.round() as isize;
    let kernel: Vec<f64> = (-reach..=reach)
        .map(|k| (-0.5 * (k as f64 * 32.0 / period).powi(2)).exp())
        .collect();
    let scaled: Vec<f64> = onset.iter().map(|&v| v as f64 * scale).collect();
    convolve_same(&scaled, &kernel)
}

/// The last local peak of the cumulative score that reaches half the median peak, among frames
/// whose own local score is at least a tenth of the largest (so the sequence does not end on the
/// silence after the last onset).
fn last_beat(cumulative: &[f64], local: &[f64], local_peak: f64) -> Option<usize> {
    let n = cumulative.len();
    let peaks: Vec<usize> = (0..n)
        .filter(|&i| {
            if local[i] < 0.1 * local_peak {
                return false;
            }
            let left = if i > 0 { cumulative[i - 1] } else { f64::MIN };
            let right = if i + 1 < n {
                cumulative[i + 1]
            } else {
                f64::MIN
            };
            cumulative[i] > left && cumulative[i] >= right
        })
        .collect();
    if peaks.is_empty() {
        return None;
    }
    let mut values: Vec<f64> = peaks.iter().map(|&i| cumulative[i]).collect();
    values.sort_by(f64::total_cmp);
    let median = values[values.len() / 2];
    peaks
        .iter()
        .rev()
        .copied()
        .find(|&i| cumulative[i] >= 0.5 * median)
}

/// Drops leading and trailing beats whose smoothed local score is under half the root mean
/// square of all beats' smoothed scores.
fn trim_weak_ends(beats: &[usize], local: &[f64]) -> Vec<usize> {
    let raw: Vec<f64> = beats.iter().map(|&b| local[b]).collect();
    let smooth = convolve_same(&raw, &[0.25, 0.75, 1.0, 0.75, 0.25]);
    if smooth.is_empty() {
        return Vec::new();
    }
    let rms = (smooth.iter().map(|v| v * v).sum::<f64>() / smooth.len() as f64).sqrt();
    let threshold = 0.5 * rms;
    let first = smooth.iter().position(|&v| v > threshold);
    let last = smooth.iter().rposition(|&v| v > threshold);
    match (first, last) {
        (Some(a), Some(b)) => beats[a..=b].to_vec(),
        _ => Vec::new(),
    }
}

/// `1 - mean / at_beats`: how much stronger the envelope is at the beats (its largest value
/// within two frames of each) than on average; 0 to 1.
pub fn confidence(onset: &[f32], beats: &[usize]) -> f64 {
    if onset.is_empty() || beats.is_empty() {
        return 0.0;
    }
    let mean = onset.iter().map(|&v| v as f64).sum::<f64>() / onset.len() as f64;
    let at_beats = beats
        .iter()
        .map(|&b| {
            onset[b.saturating_sub(2)..(b + 3).min(onset.len())]
                .iter()
                .fold(0.0f64, |m, &v| m.max(v as f64))
        })
        .sum::<f64>()
        / beats.len() as f64;
    if at_beats <= 0.0 {
        return 0.0;
    }
    (1.0 - mean / at_beats).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pulse_train_is_tracked_pulse_for_pulse() {
        let period = 37.0;
        let mut onset = vec![0.05f32; 1200];
        let truth: Vec<usize> = (0..)
            .map(|k| 20 + k * 37)
            .take_while(|&f| f < 1200)
            .collect();
        for &t in &truth {
            onset[t] = 1.0;
        }
        let found = beat_frames(&onset, period, 100.0);
        assert_eq!(found, truth);
    }

    #[test]
    fn a_missing_pulse_is_filled_in_on_the_grid() {
        let mut onset = vec![0.0f32; 600];
        let truth: Vec<usize> = (0..15).map(|k| 10 + k * 40).collect();
        for (k, &t) in truth.iter().enumerate() {
            if k != 7 {
                onset[t] = 1.0;
            }
        }
        assert_eq!(beat_frames(&onset, 40.0, 100.0), truth);
    }

    #[test]
    fn confidence_is_high_on_clean_pulses_and_low_on_flat_noise() {
        let mut onset = vec![0.01f32; 400];
        let beats: Vec<usize> = (0..10).map(|k| 5 + 40 * k).collect();
        for &b in &beats {
            onset[b] = 1.0;
        }
        assert!(confidence(&onset, &beats) > 0.9);
        assert!(confidence(&[0.5f32; 400], &beats) < 1e-9);
    }
}
