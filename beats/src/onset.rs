//! The onset-strength envelope: how much new sound starts at each moment.
//!
//! Short-time spectra (Hann window of about 46 ms, hop of a quarter window: about 86 envelope
//! frames a second at any common sample rate) are pooled into 128 mel bands, compressed to
//! decibels (floored 80 dB under the loudest), and differenced frame to frame; the envelope is
//! the mean over bands of the rises (falls count 0). Frame `t`'s value measures the change from
//! the spectrum centred `hop` samples earlier to the one centred at `t * hop`, and is dated half a
//! hop after the later centre: a sound raises the decibels while it is still entering the
//! window, so the largest rise comes about a hop and a half before the sound reaches a window's
//! centre (calibrated on clicks, drum one-shots and breakbeat loops: within 5 ms of each).

use realfft::RealFftPlanner;

use crate::window::hann;
use crate::{Audio, BeatsError};

/// Mel bands of the spectrogram.
pub const MEL_BANDS: usize = 128;
/// Dynamic range kept by the decibel compression.
pub const TOP_DB: f64 = 80.0;
/// Window length aimed at, in seconds (rounded to a power of two of samples).
pub const WINDOW_SECONDS: f64 = 0.046;

/// Onset strength per envelope frame.
#[derive(Debug, Clone, PartialEq)]
pub struct OnsetEnvelope {
    /// Strength per frame (non-negative).
    pub values: Vec<f32>,
    /// Envelope frames per second.
    pub frame_rate: f64,
    /// Time in seconds of frame 0.
    pub start: f64,
}

impl OnsetEnvelope {
    /// The envelope of `audio`.
    pub fn of(audio: &Audio) -> Result<OnsetEnvelope, BeatsError> {
        if audio.seconds() < 2.0 {
            return Err(BeatsError::TooShort {
                seconds: audio.seconds(),
            });
        }
        let rate = audio.rate as f64;
        let window = (rate * WINDOW_SECONDS).round().max(64.0) as usize;
        let window = window.next_power_of_two();
        let hop = window / 4;
        let spectra = log_mel_spectrogram(&audio.samples, rate, window, hop);
        let mut values = vec![0.0f32; spectra.len()];
        for t in 1..spectra.len() {
            let rise: f64 = spectra[t]
                .iter()
                .zip(&spectra[t - 1])
                .map(|(now, before)| (now - before).max(0.0))
                .sum();
            values[t] = (rise / MEL_BANDS as f64) as f32;
        }
        Ok(OnsetEnvelope {
            values,
            frame_rate: rate / hop as f64,
            start: 0.5 * hop as f64 / rate,
        })
    }

    /// Time in seconds of frame `frame`.
    pub fn time_of(&self, frame: usize) -> f64 {
        self.start + frame as f64 / self.frame_rate
    }
}

/// Log-mel spectra, one per hop, of windows centred on `t * hop` (the signal padded with
/// zeros at both ends).
fn log_mel_spectrogram(samples: &[f32], rate: f64, window: usize, hop: usize) -> Vec<Vec<f64>> {
    let hann = hann(window);
    let filters = mel_filters(rate, window, MEL_BANDS);
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(window);
    let mut input = fft.make_input_vec();
    let mut output = fft.make_output_vec();
    let frames = samples.len() / hop + 1;
    let half = window as isize / 2;
    let mut spectra = Vec::with_capacity(frames);
    let mut power = vec![0.0f64; window / 2 + 1];
    for t in 0..frames {
        let centre = (t * hop) as isize;
        for (i, slot) in input.iter_mut().enumerate() {
            let at = centre - half + i as isize;
            let s = if at >= 0 && (at as usize) < samples.len() {
                samples[at as usize] as f64
            } else {
                0.0
            };
            *slot = s * hann[i];
        }
        fft.process(&mut input, &mut output)
            .expect("buffers made by the same plan");
        for (p, c) in power.iter_mut().zip(&output) {
            *p = c.norm_sqr();
        }
        let bands: Vec<f64> = filters
            .iter()
            .map(|(first, weights)| {
                weights
                    .iter()
                    .zip(&power[*first..])
                    .map(|(w, p)| w * p)
                    .sum()
            })
            .collect();
        spectra.push(bands);
    }
    let loudest = spectra.iter().flatten().fold(1e-10f64, |m, &v| m.max(v));
    let floor = 10.0 * loudest.log10() - TOP_DB;
    for frame in &mut spectra {
        for v in frame.iter_mut() {
            *v = (10.0 * v.max(1e-10).log10()).max(floor);
        }
    }
    spectra
}

/// Slaney's mel scale (his auditory toolbox): linear below [`MEL_KNEE_HZ`] in steps of
/// [`MEL_LINEAR_STEP_HZ`] per mel, logarithmic above with 27 mels per factor of 6.4.
const MEL_KNEE_HZ: f64 = 1000.0;
const MEL_LINEAR_STEP_HZ: f64 = 200.0 / 3.0;
const MEL_KNEE: f64 = MEL_KNEE_HZ / MEL_LINEAR_STEP_HZ;

fn mel_log_step() -> f64 {
    6.4f64.ln() / 27.0
}

fn hz_to_mel(hz: f64) -> f64 {
    if hz < MEL_KNEE_HZ {
        hz / MEL_LINEAR_STEP_HZ
    } else {
        MEL_KNEE + (hz / MEL_KNEE_HZ).ln() / mel_log_step()
    }
}

fn mel_to_hz(mel: f64) -> f64 {
    if mel < MEL_KNEE {
        mel * MEL_LINEAR_STEP_HZ
    } else {
        MEL_KNEE_HZ * (mel_log_step() * (mel - MEL_KNEE)).exp()
    }
}

/// Triangular filters with area-normalised weights, each as (first FFT bin, weights from it).
fn mel_filters(rate: f64, window: usize, bands: usize) -> Vec<(usize, Vec<f64>)> {
    let bins = window / 2 + 1;
    let top = hz_to_mel(rate / 2.0);
    let edges: Vec<f64> = (0..bands + 2)
        .map(|i| mel_to_hz(top * i as f64 / (bands + 1) as f64))
        .collect();
    (0..bands)
        .map(|b| {
            let (lo, mid, hi) = (edges[b], edges[b + 1], edges[b + 2]);
            let norm = 2.0 / (hi - lo);
            let weights: Vec<f64> = (0..bins)
                .map(|k| {
                    let hz = k as f64 * rate / window as f64;
                    let rise = (hz - lo) / (mid - lo);
                    let fall = (hi - hz) / (hi - mid);
                    rise.min(fall).max(0.0) * norm
                })
                .collect();
            let first = weights.iter().position(|&w| w > 0.0).unwrap_or(0);
            let last = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0);
            (first, weights[first..=last.max(first)].to_vec())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mel_scale_round_trips_and_is_linear_below_a_kilohertz() {
        for hz in [0.0, 100.0, 999.0, 1000.0, 4000.0, 11025.0] {
            assert!((mel_to_hz(hz_to_mel(hz)) - hz).abs() < 1e-6 * hz.max(1.0));
        }
        assert!((hz_to_mel(500.0) - 7.5).abs() < 1e-12);
        assert!((hz_to_mel(1000.0) - 15.0).abs() < 1e-12);
    }

    #[test]
    fn a_click_makes_one_peak_at_its_time() {
        let rate = 22050;
        let mut samples = vec![0.0f32; rate as usize * 3];
        let at = (1.5 * rate as f64) as usize;
        for (i, s) in samples[at..at + 200].iter_mut().enumerate() {
            *s = (i as f32 * 0.3).sin() * (-(i as f32) / 40.0).exp();
        }
        let envelope = OnsetEnvelope::of(&Audio { samples, rate }).unwrap();
        let peak = envelope
            .values
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        let error = envelope.time_of(peak) - 1.5;
        assert!(error.abs() < 0.03, "peak {error:+.4} s from the click");
    }
}
