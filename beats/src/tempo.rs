//! The tempo of an onset envelope: the period whose windowed autocorrelation, weighted by a
//! log-normal prior around 120 BPM, is strongest.
//!
//! The envelope is cut into windows of [`AUTOCORRELATION_SECONDS`] (every [`WINDOW_STRIDE`]
//! frames), each less its mean (so a steady background of small onsets does not favour the
//! shorter lags, which overlap more), Hann-weighted and autocorrelated, normalised by its value at lag 0; the mean
//! over windows, times the prior, is maximised over lags and refined by a parabola through the
//! peak. Windowing favours the shorter of two periods that fit equally well, as a listener does.

use realfft::RealFftPlanner;

use crate::onset::OnsetEnvelope;
use crate::window::hann;
use crate::{BeatsError, TrackerOptions};

/// Length of each autocorrelation window, in seconds.
pub const AUTOCORRELATION_SECONDS: f64 = 8.0;
/// Envelope frames between the starts of consecutive windows.
pub const WINDOW_STRIDE: usize = 4;

/// The mean normalised windowed autocorrelation of `values`, lags `0..window`.
pub fn mean_autocorrelation(values: &[f32], window: usize) -> Vec<f64> {
    let size = (2 * window).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(size);
    let inverse = planner.plan_fft_inverse(size);
    let mut input = forward.make_input_vec();
    let mut spectrum = forward.make_output_vec();
    let mut back = inverse.make_output_vec();
    let hann = hann(window);
    let mut sum = vec![0.0f64; window];
    let mut count = 0usize;
    let half = window as isize / 2;
    let mut centre = 0isize;
    while (centre as usize) < values.len() {
        input.iter_mut().for_each(|v| *v = 0.0);
        let inside = |i: usize| {
            let at = centre - half + i as isize;
            (at >= 0 && (at as usize) < values.len()).then(|| values[at as usize] as f64)
        };
        let (total, count_inside) = (0..window)
            .filter_map(inside)
            .fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
        let mean = total / count_inside.max(1) as f64;
        for (i, w) in hann.iter().enumerate() {
            if let Some(v) = inside(i) {
                input[i] = (v - mean) * w;
            }
        }
        forward
            .process(&mut input, &mut spectrum)
            .expect("buffers made by the same plan");
        for c in spectrum.iter_mut() {
            *c = realfft::num_complex::Complex::new(c.norm_sqr(), 0.0);
        }
        inverse
            .process(&mut spectrum, &mut back)
            .expect("buffers made by the same plan");
        let zero = back[0];
        if zero > 0.0 {
            for (s, v) in sum.iter_mut().zip(&back) {
                *s += v / zero;
            }
            count += 1;
        }
        centre += WINDOW_STRIDE as isize;
    }
    if count > 0 {
        sum.iter_mut().for_each(|s| *s /= count as f64);
    }
    sum
}

/// The beat period of `envelope` in envelope frames (fractional).
pub fn estimate_period(
    envelope: &OnsetEnvelope,
    options: &TrackerOptions,
) -> Result<f64, BeatsError> {
    let seconds = envelope.values.len() as f64 / envelope.frame_rate;
    let window = ((AUTOCORRELATION_SECONDS * envelope.frame_rate).round() as usize)
        .min(envelope.values.len())
        .max(8);
    let ac = mean_autocorrelation(&envelope.values, window);
    let to_bpm = |lag: f64| 60.0 * envelope.frame_rate / lag;
    let weighted: Vec<f64> = ac
        .iter()
        .enumerate()
        .map(|(lag, &a)| {
            if lag == 0 {
                return 0.0;
            }
            let bpm = to_bpm(lag as f64);
            if bpm < options.min_bpm || bpm > options.max_bpm {
                return 0.0;
            }
            let octaves = (bpm / options.prior_bpm).log2() / options.prior_octaves;
            a.max(0.0) * (-0.5 * octaves * octaves).exp()
        })
        .collect();
    let (best, peak) = weighted
        .iter()
        .enumerate()
        .fold((0, 0.0), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
    if peak <= 0.0 {
        return Err(BeatsError::NoBeats { seconds });
    }
    let mut lag = best as f64;
    if best > 0 && best + 1 < weighted.len() {
        let (a, b, c) = (weighted[best - 1], weighted[best], weighted[best + 1]);
        let curvature = a - 2.0 * b + c;
        if curvature < 0.0 {
            lag += (0.5 * (a - c) / curvature).clamp(-0.5, 0.5);
        }
    }
    Ok(lag)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pulses(period: f64, frames: usize) -> Vec<f32> {
        let mut v = vec![0.0f32; frames];
        let mut t = 3.0f64;
        while (t as usize) < frames {
            v[t.round() as usize] = 1.0;
            t += period;
        }
        v
    }

    #[test]
    fn a_pulse_train_gives_its_own_period() {
        for period in [43.0, 28.7, 61.5] {
            let envelope = OnsetEnvelope {
                values: pulses(period, 2000),
                frame_rate: 86.0,
                start: 0.0,
            };
            let found = estimate_period(&envelope, &TrackerOptions::default()).unwrap();
            assert!(
                (found - period).abs() / period < 0.02,
                "{period} frames found as {found}"
            );
        }
    }

    #[test]
    fn silence_has_no_tempo() {
        let envelope = OnsetEnvelope {
            values: vec![0.0; 1000],
            frame_rate: 86.0,
            start: 0.0,
        };
        assert!(matches!(
            estimate_period(&envelope, &TrackerOptions::default()),
            Err(BeatsError::NoBeats { .. })
        ));
    }
}
