//! How long a clip's motion stays correlated, read from its features before training, and the
//! wider QnA window that a clip of long, slow motifs may want.
//!
//! The network sees a fixed number of frames at once. A clip whose motion stays correlated for
//! much longer than that (a long mix of walking, turning and stopping) is covered better with a
//! wider field. The trainer does not widen the window by itself, as too few clips need it to fit
//! a rule (lab/EXPERIMENTS.md, "The dog: half windows, wider windows, more channels"); it tells
//! the user, who may train with `--window` (or set `model.window` in a `--config`).

use ndarray::ArrayView2;

use crate::config::ModelConfig;

/// The longest lag searched, in seconds: motifs longer than this are left to the clip's length.
const LONGEST_LAG_SECONDS: f64 = 10.0;

/// The first lag, in frames, at which the mean autocorrelation of the feature rows (each
/// standardised over the clip; constant rows left out) falls below zero, searched up to half the
/// clip and [`LONGEST_LAG_SECONDS`]. `None` when it stays positive that long, or when no row
/// varies.
pub fn decorrelation_frames(features: ArrayView2<'_, f32>, fps: f64) -> Option<usize> {
    let frames = features.ncols();
    let rows: Vec<Vec<f64>> = features
        .rows()
        .into_iter()
        .filter_map(|row| {
            let n = row.len() as f64;
            let mean = row.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
            let var = row
                .iter()
                .map(|&v| (f64::from(v) - mean).powi(2))
                .sum::<f64>()
                / n;
            (var > 1e-12).then(|| {
                let sd = var.sqrt();
                row.iter().map(|&v| (f64::from(v) - mean) / sd).collect()
            })
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let longest = (frames / 2).min((LONGEST_LAG_SECONDS * fps) as usize);
    (1..=longest).find(|&lag| {
        let mean: f64 = rows
            .iter()
            .map(|z| {
                let products: f64 = z[..frames - lag]
                    .iter()
                    .zip(&z[lag..])
                    .map(|(a, b)| a * b)
                    .sum();
                products / (frames - lag) as f64
            })
            .sum::<f64>()
            / rows.len() as f64;
        mean < 0.0
    })
}

/// `model` with the narrowest QnA window whose receptive field spans half of `decorrelation`
/// frames, when that window is wider than the window of `model` (already resolved for the
/// clip's frame rate).
pub fn wider_window(model: &ModelConfig, decorrelation: usize) -> Option<ModelConfig> {
    let wanted = decorrelation.div_ceil(2);
    let mut candidate = model.clone();
    while candidate.receptive_field() < wanted {
        candidate.window += 2;
    }
    (candidate.window > model.window).then_some(candidate)
}

/// A line for the user when a clip whose features decorrelate after `frames` frames
/// ([`decorrelation_frames`]) stays correlated longer than twice the receptive field of `model`
/// at `fps`; `None` otherwise.
pub fn wider_window_hint(frames: usize, fps: f64, model: &ModelConfig) -> Option<String> {
    let wider = wider_window(model, frames)?;
    Some(format!(
        "this clip's motion stays correlated for {:.2} s and the network sees {:.2} s at once \
         (QnA window {}). Long, slow motifs like these were covered better with a wider field \
         (the MANN dog walk at 30 fps: 80 % coverage with window 3, 94 % with 11, somewhat \
         less varied); to try it, train with --window {} ({:.2} s; each step costs more)",
        frames as f64 / fps,
        model.receptive_field() as f64 / fps,
        model.window,
        wider.window,
        wider.receptive_field() as f64 / fps,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TrainConfig;
    use ndarray::Array2;

    fn default_model() -> ModelConfig {
        TrainConfig::parse(include_str!("../../../configs/default.yaml"))
            .unwrap()
            .model
    }

    /// Rows `sin(2 pi n / period + phase)`: a sinusoid's autocorrelation is `cos(2 pi lag /
    /// period)`, first below zero just past a quarter period.
    fn sinusoids(period: f64, frames: usize) -> Array2<f32> {
        Array2::from_shape_fn((4, frames), |(row, n)| {
            let phase = row as f64 * 0.7;
            (std::f64::consts::TAU * n as f64 / period + phase).sin() as f32
        })
    }

    #[test]
    fn a_sinusoid_decorrelates_a_quarter_period_on() {
        for period in [24.0, 120.0, 174.0] {
            let lag = decorrelation_frames(sinusoids(period, 1200).view(), 30.0).unwrap();
            let quarter = period / 4.0;
            assert!(
                (lag as f64 - quarter).abs() <= 1.5,
                "period {period}: lag {lag}, quarter period {quarter}"
            );
        }
    }

    #[test]
    fn alternating_frames_decorrelate_at_once_and_constant_rows_say_nothing() {
        let alternating =
            Array2::from_shape_fn((2, 100), |(_, n)| if n % 2 == 0 { 1.0 } else { -1.0 });
        assert_eq!(decorrelation_frames(alternating.view(), 30.0), Some(1));
        let constant = Array2::<f32>::from_elem((3, 100), 0.5);
        assert_eq!(decorrelation_frames(constant.view(), 30.0), None);
    }

    #[test]
    fn a_ramp_decorrelates_at_the_analytic_lag() {
        // Standardised ramp z[n] ~ n - c, c = (N - 1) / 2: the mean of z[n] z[n + L] turns
        // negative once (c - L/2)^2 / 3 < L^2 / 4, at L = 2c / (1 + sqrt 3): 109.4 for N = 300.
        let ramp = Array2::from_shape_fn((1, 300), |(_, n)| n as f32);
        let lag = decorrelation_frames(ramp.view(), 30.0).unwrap();
        let analytic = 2.0 * 149.5 / (1.0 + 3f64.sqrt());
        assert!(
            (lag as f64 - analytic).abs() <= 2.0,
            "lag {lag}, analytic {analytic:.1}"
        );
    }

    #[test]
    fn motifs_longer_than_the_search_say_nothing() {
        // A quarter period of 500 frames is past the 10 s (300 frames) searched at 30 fps.
        let slow = sinusoids(2000.0, 3000);
        assert_eq!(decorrelation_frames(slow.view(), 30.0), None);
    }

    #[test]
    fn the_window_grows_until_its_field_spans_half_the_decorrelation() {
        let model = default_model();
        // Window 3 sees 23 frames: a span up to 46 frames asks for nothing wider.
        assert!(wider_window(&model, 42).is_none());
        assert!(wider_window(&model, 46).is_none());
        // The dog at 30 fps (2.90 s, 87 frames): half is 44 frames, window 11 sees 47, 9 sees 41.
        assert_eq!(wider_window(&model, 87).map(|m| m.window), Some(11));
        // The same span at 60 fps (174 frames) with the window resolved for 60 fps (11):
        // half is 87 frames; window 25 sees 89, 23 sees 83.
        let at_60 = model.at_fps(60.0);
        assert_eq!(at_60.window, 11);
        assert_eq!(wider_window(&at_60, 174).map(|m| m.window), Some(25));
        for (span, window) in [(87usize, 11), (174, 25)] {
            let m = ModelConfig {
                window,
                ..model.clone()
            };
            let narrower = ModelConfig {
                window: window - 2,
                ..model.clone()
            };
            assert!(m.receptive_field() >= span.div_ceil(2));
            assert!(narrower.receptive_field() < span.div_ceil(2));
        }
    }

    #[test]
    fn the_hint_names_the_span_and_the_window() {
        let model = default_model();
        // A period of 348 frames at 30 fps decorrelates after about 87 frames, 2.90 s.
        let slow = sinusoids(348.0, 1000);
        let span = decorrelation_frames(slow.view(), 30.0).unwrap();
        assert!((86..=89).contains(&span), "{span}");
        let hint = wider_window_hint(span, 30.0, &model).unwrap();
        assert!(
            hint.contains(&format!("{:.2} s", span as f64 / 30.0)),
            "{hint}"
        );
        assert!(hint.contains("--window 11 (1.57 s"), "{hint}");
        let fast = decorrelation_frames(sinusoids(60.0, 1000).view(), 30.0).unwrap();
        assert_eq!(wider_window_hint(fast, 30.0, &model), None);
    }
}
