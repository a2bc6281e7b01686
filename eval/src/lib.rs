//! sinmdm-eval: quality metrics of generated motion against the training clip (the single-motion benchmark
//! of GANimator and SinMDM).
//!
//! Every metric compares frames by the Euclidean distance of their *metric features*: all 6D
//! joint rotations and the contact labels, unnormalised (root motion and position channels are
//! left out, as in the published benchmark). With the default window sizes:
//!
//! | metric | what it measures | better |
//! |---|---|---|
//! | coverage (%) | share of the clip's 30-frame windows whose nearest window in a sample is closer than 2.0 per frame | higher |
//! | global diversity | cost per frame of the cheapest cut of a sample into >= 30-frame pieces of the clip ([`patched_nearest_neighbour`]) | higher |
//! | local diversity | mean over a sample's 15-frame windows of the per-frame distance to the nearest clip window | higher |
//! | inter diversity | Frobenius distance between consecutive samples, divided by their frames | higher |
//! | intra diversity difference | \|mean Frobenius distance / 15 between two 15-frame windows of a sample, minus the same for the clip\| | lower |
//! | replay (s) | mean over samples of the longest run of frames copying consecutive clip frames ([`ReplayReport`]) | lower |
//!
//! Two choices differ from the published scripts, both to remove noise rather than change what is
//! measured: coverage counts every window of the clip (the scripts skip the last one), and the
//! intra diversity is the mean over *all* pairs of window positions (its expectation) instead of
//! one random pair per sample.
//!
//! The harmonic mean folds the five into one number. Each score is mapped to `[0, 1]` by a
//! maximum that means "as far as the coverage threshold": coverage by 100, global and local
//! diversity by the threshold 2.0 (a per-frame distance), inter diversity by
//! `2.0 / sqrt(frames)` and the intra difference by `2.0 / sqrt(15)` (a Frobenius distance over
//! `n` frames is the root-mean-square per-frame distance divided by `sqrt(n)`). Scores above
//! their maximum count as the maximum; the lower-is-better intra difference counts as
//! `1 - difference / maximum`.

#![warn(missing_docs)]

pub mod beat_align;
mod feet;
mod kinematic_report;
pub mod kinematics;
mod model_eval;
mod patched_nn;
mod replay;
mod report;
#[cfg(test)]
mod test_data;
pub mod turning;
mod window_match;

use ndarray::{Array2, ArrayView2, Axis};
use thiserror::Error;

use sinmdm::motion::{Column, ColumnKind, FeatureLayout, LocalMotion, encode_motion};

pub use report::{RarelyMade, Report, SampleScores, Stat, harmonic_mean, normalised_scores};

pub use beat_align::{BeatScores, beat_scores, mean_beat_scores};
pub use feet::{
    FeetReference, FeetReport, FeetScores, GROUND_BAND, PENETRATION_TOLERANCE, SKATING_SPEED,
    SPEED_WINDOW, SampleFeet, mean_scores,
};
pub use kinematic_report::KinematicReport;
pub use kinematics::{ClipKinematics, KinematicMiss, KinematicScores, Kinematics, wasserstein_1};
pub use model_eval::{
    GoalScores, ModelEvalError, ModelEvaluation, evaluate_generated, evaluate_model, goal_scores,
};
pub use patched_nn::patched_nearest_neighbour;
pub use replay::{
    REPLAY_TOLERANCE, ReplayReport, longest_backwards, longest_hold, longest_replay, rotation_rows,
};
pub use turning::{ClipTurning, TurnScores, turn_rates};
pub use window_match::DiagonalSums;

/// Window of the coverage metric and shortest piece of the global diversity, in frames.
pub const COVERAGE_WINDOW: usize = 30;
/// Per-frame distance under which a clip window counts as covered.
pub const COVERAGE_THRESHOLD: f64 = 2.0;
/// Window of the local and intra diversity, in frames.
pub const LOCAL_WINDOW: usize = 15;

/// Problems that keep metrics from being computed.
#[derive(Debug, Error, PartialEq)]
pub enum EvalError {
    /// No samples were given.
    #[error("no samples to evaluate")]
    NoSamples,
    /// A motion is shorter than a metric's window.
    #[error("the {what} has {frames} frames; the metrics need at least {needed}")]
    TooShort {
        /// Which motion.
        what: String,
        /// Its frames.
        frames: usize,
        /// The least accepted.
        needed: usize,
    },
    /// Samples of different lengths.
    #[error(
        "sample {index} has {got} frames, sample 0 has {expected}; score samples of one length"
    )]
    LengthMismatch {
        /// The sample.
        index: usize,
        /// Frames of sample 0.
        expected: usize,
        /// Its frames.
        got: usize,
    },
    /// Motions of different feature widths.
    #[error("sample {index} has {got} metric features per frame, the clip {expected}")]
    WidthMismatch {
        /// The sample.
        index: usize,
        /// The clip's width.
        expected: usize,
        /// The sample's width.
        got: usize,
    },
}

/// Metric features of one motion, laid out `[N, D]`: one row per frame (the transpose of the
/// model's `[F, N]` features, since every metric compares frames).
pub type FrameRows = Array2<f64>;

/// The metric features of a motion: rows are frames, columns every 6D rotation component and
/// every contact label of `layout`, from features `[F, N]` in file units.
pub fn metric_features(layout: &FeatureLayout, features: ArrayView2<'_, f32>) -> FrameRows {
    frame_rows(layout, features, |column| {
        matches!(column.kind, ColumnKind::Rotation6d(_) | ColumnKind::Contact)
    })
}

/// The metric features of the body alone: as [`metric_features`] without the rotations of the
/// top joints and of the joint that carries the root's travel, the columns whose meaning the
/// root layout changes (a world rotation, or one relative to the facing). Two models of one
/// clip with different root layouts are compared on these.
pub fn body_metric_features(layout: &FeatureLayout, features: ArrayView2<'_, f32>) -> FrameRows {
    let root = layout.root.as_ref().map(|r| r.joint);
    let skeleton = &layout.skeleton;
    frame_rows(layout, features, |column| match column.kind {
        ColumnKind::Rotation6d(_) => {
            skeleton.joints[column.joint].parent.is_some() && Some(column.joint) != root
        }
        ColumnKind::Contact => true,
        _ => false,
    })
}

/// The columns of `layout` that `keep` accepts, as frame rows `[N, D]` (f64) of
/// features `[F, N]`.
pub(crate) fn frame_rows(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
    keep: impl Fn(&Column) -> bool,
) -> FrameRows {
    let columns: Vec<usize> = layout
        .columns()
        .iter()
        .enumerate()
        .filter(|(_, c)| keep(c))
        .map(|(i, _)| i)
        .collect();
    let frames = features.len_of(Axis(1));
    Array2::from_shape_fn((frames, columns.len()), |(n, c)| {
        f64::from(features[[columns[c], n]])
    })
}

/// The metric features of decoded `motion` (planted feet, say), re-encoded in `layout`, with
/// the contact labels of `made`, the features `[F, N]` it came from: planting changes rotations
/// and the root, never the labels the model predicted.
pub fn motion_metric_features(
    layout: &FeatureLayout,
    motion: &LocalMotion,
    made: ArrayView2<'_, f32>,
) -> FrameRows {
    let mut features = encode_motion(layout, motion);
    for row in layout.contact_rows() {
        features.row_mut(row).assign(&made.row(row));
    }
    metric_features(layout, features.view())
}

/// Share (0..=1) of the clip's `window`-frame windows whose best match in `sample` is closer
/// than `threshold` per frame.
pub fn coverage(sample_vs_clip: &DiagonalSums, window: usize, threshold: f64) -> f64 {
    covered_share(&covered_clip_windows(sample_vs_clip, window, threshold))
}

/// Share (0..=1) of the windows marked covered; 0 when there are none.
fn covered_share(covered: &[bool]) -> f64 {
    if covered.is_empty() {
        return 0.0;
    }
    covered.iter().filter(|&&c| c).count() as f64 / covered.len() as f64
}

/// For each `window`-frame window of the clip, by its first frame: whether `sample` has a
/// window closer than `threshold` per frame (the windows [`coverage`] counts).
pub fn covered_clip_windows(
    sample_vs_clip: &DiagonalSums,
    window: usize,
    threshold: f64,
) -> Vec<bool> {
    sample_vs_clip
        .nearest_b_windows(window)
        .into_iter()
        .map(|d| d < threshold)
        .collect()
}

/// Mean over the sample's `window`-frame windows of the per-frame distance to the nearest clip
/// window.
pub fn local_diversity(sample_vs_clip: &DiagonalSums, window: usize) -> f64 {
    mean(&sample_vs_clip.nearest_a_windows(window))
}

/// Frobenius distance between two motions of the same size, divided by their frames.
pub fn inter_diversity(a: ArrayView2<'_, f64>, b: ArrayView2<'_, f64>) -> f64 {
    assert_eq!(a.dim(), b.dim(), "motions of different sizes");
    let sq: f64 = a.iter().zip(b.iter()).map(|(p, q)| (p - q) * (p - q)).sum();
    sq.sqrt() / a.nrows() as f64
}

/// Mean over all ordered pairs of `window`-frame windows of a motion of their Frobenius distance
/// divided by `window`.
pub fn intra_diversity(motion: ArrayView2<'_, f64>, window: usize) -> f64 {
    let frames = motion.nrows();
    if window == 0 || frames < window {
        return 0.0;
    }
    let squared = DiagonalSums::new(motion, motion, true);
    let starts = frames - window + 1;
    let mut total = 0.0;
    for p in 0..starts {
        for q in 0..starts {
            total += squared.window(p, q, window).max(0.0).sqrt();
        }
    }
    total / (starts * starts) as f64 / window as f64
}

pub(crate) fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

pub(crate) fn std_dev(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let m = mean(values);
    (values.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / values.len() as f64).sqrt()
}

/// Scores of one sample against the clip (without the inter diversity), and which of the
/// clip's windows it makes.
fn score_sample(
    sample: ArrayView2<'_, f64>,
    clip: ArrayView2<'_, f64>,
) -> (SampleScores, Vec<bool>) {
    let sums = DiagonalSums::new(sample, clip, false);
    let covered = covered_clip_windows(&sums, COVERAGE_WINDOW, COVERAGE_THRESHOLD);
    let scores = SampleScores {
        coverage: 100.0 * covered_share(&covered),
        global_diversity: patched_nearest_neighbour(&sums, COVERAGE_WINDOW).unwrap_or(f64::NAN),
        local_diversity: local_diversity(&sums, LOCAL_WINDOW),
        inter_diversity: 0.0,
        intra_diversity: intra_diversity(sample, LOCAL_WINDOW),
    };
    (scores, covered)
}

/// Evaluates samples (metric features, rows = frames, all the same length) against the clip,
/// spreading the samples over `threads` threads.
pub fn evaluate(
    clip: ArrayView2<'_, f64>,
    samples: &[FrameRows],
    threads: usize,
) -> Result<Report, EvalError> {
    if samples.is_empty() {
        return Err(EvalError::NoSamples);
    }
    if clip.nrows() < COVERAGE_WINDOW {
        return Err(EvalError::TooShort {
            what: "clip".into(),
            frames: clip.nrows(),
            needed: COVERAGE_WINDOW,
        });
    }
    for (index, sample) in samples.iter().enumerate() {
        if sample.ncols() != clip.ncols() {
            return Err(EvalError::WidthMismatch {
                index,
                expected: clip.ncols(),
                got: sample.ncols(),
            });
        }
        if sample.nrows() != samples[0].nrows() {
            return Err(EvalError::LengthMismatch {
                index,
                expected: samples[0].nrows(),
                got: sample.nrows(),
            });
        }
        if sample.nrows() < COVERAGE_WINDOW {
            return Err(EvalError::TooShort {
                what: format!("sample {index}"),
                frames: sample.nrows(),
                needed: COVERAGE_WINDOW,
            });
        }
    }

    let count = samples.len();
    let threads = threads.clamp(1, count);
    let mut per_sample = vec![None; count];
    std::thread::scope(|scope| {
        let chunk = count.div_ceil(threads);
        for (block, out) in samples.chunks(chunk).zip(per_sample.chunks_mut(chunk)) {
            scope.spawn(move || {
                for (sample, slot) in block.iter().zip(out.iter_mut()) {
                    *slot = Some(score_sample(sample.view(), clip));
                }
            });
        }
    });
    let (mut per_sample, covered): (Vec<SampleScores>, Vec<Vec<bool>>) = per_sample
        .into_iter()
        .map(|s| s.expect("every sample scored"))
        .unzip();
    let clip_window_coverage = (0..=clip.nrows() - COVERAGE_WINDOW)
        .map(|w| {
            let making = covered.iter().filter(|c| c[w]).count();
            100.0 * making as f64 / count as f64
        })
        .collect();
    for i in 0..count {
        let previous = &samples[(i + count - 1) % count];
        per_sample[i].inter_diversity = inter_diversity(samples[i].view(), previous.view());
    }

    let pick = |f: fn(&SampleScores) -> f64| per_sample.iter().map(f).collect::<Vec<f64>>();
    let clip_intra = intra_diversity(clip, LOCAL_WINDOW);
    let mut report = Report {
        coverage: Stat::of(&pick(|s| s.coverage)),
        global_diversity: Stat::of(&pick(|s| s.global_diversity)),
        local_diversity: Stat::of(&pick(|s| s.local_diversity)),
        inter_diversity: Stat::of(&pick(|s| s.inter_diversity)),
        intra_diversity_diff: (mean(&pick(|s| s.intra_diversity)) - clip_intra).abs(),
        clip_intra_diversity: clip_intra,
        harmonic_mean: 0.0,
        sample_frames: samples[0].nrows(),
        clip_frames: clip.nrows(),
        per_sample,
        clip_window_coverage,
    };
    report.harmonic_mean = harmonic_mean(&normalised_scores(&report));
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use test_data::random_motion as motion;

    #[test]
    fn intra_diversity_matches_every_pair_written_out() {
        let m = motion(24, 3, 1);
        let w = 5;
        let mut total = 0.0;
        let mut pairs = 0;
        for p in 0..=24 - w {
            for q in 0..=24 - w {
                let a = m.slice(ndarray::s![p..p + w, ..]);
                let b = m.slice(ndarray::s![q..q + w, ..]);
                total += inter_diversity(a, b);
                pairs += 1;
            }
        }
        assert!((intra_diversity(m.view(), w) - total / pairs as f64).abs() < 1e-12);
    }

    #[test]
    fn inter_diversity_is_frobenius_over_frames() {
        let a = Array2::zeros((4, 2));
        let b = Array2::from_elem((4, 2), 1.0);
        // sqrt(8) / 4
        assert!((inter_diversity(a.view(), b.view()) - 8f64.sqrt() / 4.0).abs() < 1e-15);
        assert_eq!(inter_diversity(b.view(), b.view()), 0.0);
    }

    #[test]
    fn harmonic_mean_of_known_values() {
        assert!((harmonic_mean(&[1.0, 0.5]) - 2.0 / 3.0).abs() < 1e-15);
        assert_eq!(harmonic_mean(&[1.0, 0.0, 1.0]), 0.0);
        assert_eq!(harmonic_mean(&[0.25; 5]), 0.25);
    }

    #[test]
    fn coverage_counts_windows_under_the_threshold() {
        // Clip: 40 frames at 0. Sample: 40 frames, the first 35 at 0, the rest far away.
        let clip = Array2::zeros((40, 1));
        let mut sample = Array2::zeros((40, 1));
        sample.slice_mut(ndarray::s![35.., ..]).fill(100.0);
        let sums = DiagonalSums::new(sample.view(), clip.view(), false);
        assert_eq!(coverage(&sums, 30, 2.0), 1.0);
        // A sample far from every clip frame covers nothing.
        let far = Array2::from_elem((40, 1), 3.0);
        let sums = DiagonalSums::new(far.view(), clip.view(), false);
        assert_eq!(coverage(&sums, 30, 2.0), 0.0);
        // 1.9 per frame is under 2.0.
        let near = Array2::from_elem((40, 1), 1.9);
        let sums = DiagonalSums::new(near.view(), clip.view(), false);
        assert_eq!(coverage(&sums, 30, 2.0), 1.0);
    }

    #[test]
    fn clip_window_coverage_counts_the_samples_that_make_each_window() {
        // Clip: a ramp of 60 frames, 1.0 apart, so a window matched s frames off lies s per
        // frame away. Sample A is the clip's first 45 frames, then far away: it makes the clip
        // windows starting at 0..=15 exactly and 16 one frame off (1.0 < 2.0), not 17 and on
        // (2.0 is not under the threshold). Sample B is the whole clip; C is far from it all.
        let clip = Array2::from_shape_fn((60, 1), |(f, _)| f as f64);
        let mut a = Array2::from_elem((60, 1), 500.0);
        a.slice_mut(ndarray::s![..45, ..])
            .assign(&clip.slice(ndarray::s![..45, ..]));
        let b = clip.clone();
        let c = Array2::from_elem((60, 1), -500.0);
        let report = evaluate(clip.view(), &[a, b, c], 2).unwrap();
        assert_eq!(report.clip_window_coverage.len(), 31);
        for (start, &share) in report.clip_window_coverage.iter().enumerate() {
            let makers = if start <= 16 { 2.0 } else { 1.0 };
            let expected = 100.0 * makers / 3.0;
            assert!(
                (share - expected).abs() < 1e-9,
                "window {start}: {share} against {expected}"
            );
        }
        let mean = report.clip_window_coverage.iter().sum::<f64>() / 31.0;
        assert!((mean - report.coverage.mean).abs() < 1e-9);
        // Under half of the samples make the windows 17..=30: frames 17..=59.
        assert_eq!(
            report.rarely_made(50.0),
            vec![RarelyMade {
                first_frame: 17,
                last_frame: 59,
                least_share: 100.0 / 3.0
            }]
        );
        assert!(report.rarely_made(100.0 / 3.0).is_empty());
    }

    #[test]
    fn rarely_made_stretches_are_runs_of_low_windows() {
        let mut report = evaluate(
            motion(40, 2, 1).view(),
            std::slice::from_ref(&motion(40, 2, 2)),
            1,
        )
        .unwrap();
        // Windows 1, 2, 4 and 6 are low and share frames, and window 36 starts right after
        // window 6's last frame: one stretch, frames 1..=65. Window 67 is low too, but a frame
        // lies between them (a second stretch).
        let mut shares = vec![90.0; 68];
        for (window, share) in [
            (1, 10.0),
            (2, 20.0),
            (4, 5.0),
            (6, 7.0),
            (36, 30.0),
            (67, 49.0),
        ] {
            shares[window] = share;
        }
        report.clip_window_coverage = shares;
        let stretches: Vec<(usize, usize, f64)> = report
            .rarely_made(50.0)
            .iter()
            .map(|r| (r.first_frame, r.last_frame, r.least_share))
            .collect();
        assert_eq!(stretches, vec![(1, 65, 5.0), (67, 96, 49.0)]);
        assert!(report.rarely_made(5.0).is_empty());
    }

    #[test]
    fn errors_name_the_problem() {
        let clip = motion(50, 2, 1);
        assert_eq!(evaluate(clip.view(), &[], 1), Err(EvalError::NoSamples));
        let short = motion(10, 2, 2);
        assert!(matches!(
            evaluate(short.view(), std::slice::from_ref(&clip), 1),
            Err(EvalError::TooShort { .. })
        ));
        let longer = motion(60, 2, 4);
        assert_eq!(
            evaluate(clip.view(), &[clip.clone(), longer], 1),
            Err(EvalError::LengthMismatch {
                index: 1,
                expected: 50,
                got: 60
            })
        );
        let wide = motion(50, 3, 3);
        assert!(matches!(
            evaluate(clip.view(), &[wide], 1),
            Err(EvalError::WidthMismatch { index: 0, .. })
        ));
    }
}
