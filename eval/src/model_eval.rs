//! Scoring a model: sample a request on any denoiser and score the samples against the clip.

use std::fmt::Write as _;
use std::ops::ControlFlow;
use std::time::Instant;

use ndarray::{Array2, ArrayView2};
use sinmdm::motion::{LocalMotion, MotionError, decode};
use sinmdm::{Denoiser, Generated, ModelMetadata, Request, TaskError};
use thiserror::Error;

use crate::{
    COVERAGE_WINDOW, ClipKinematics, EvalError, FeetReport, KinematicReport, KinematicScores,
    Kinematics, REPLAY_TOLERANCE, ReplayReport, Report, body_metric_features, evaluate,
    metric_features, motion_metric_features,
};

/// Why a model could not be scored.
#[derive(Debug, Error)]
pub enum ModelEvalError {
    /// The samples could not be made.
    #[error(transparent)]
    Task(#[from] TaskError),
    /// The samples or the clip could not be scored.
    #[error(transparent)]
    Metrics(#[from] EvalError),
    /// The samples or the clip could not be decoded into motion.
    #[error(transparent)]
    Motion(#[from] MotionError),
}

/// Samples, their scores, and how long each part took.
#[derive(Debug)]
pub struct ModelEvaluation {
    /// The samples.
    pub generated: Generated,
    /// Their scores against the clip, as the network made them.
    pub report: Report,
    /// The same scores on the body alone ([`body_metric_features`]: no root rotation), which
    /// compare models of one clip with different root layouts.
    pub body_report: Report,
    /// The same scores of the raw motion as `--feet raw` writes it: decoded and re-encoded,
    /// as the planted motion is (the network's 6D values are not exact rotations, so decoding
    /// alone moves the scores a little). Planting's cost is `planted_report` against this.
    pub raw_motion_report: Report,
    /// The same scores with the samples' feet planted (the motion a user gets by default).
    pub planted_report: Report,
    /// Their feet and smoothness figures, raw and planted, beside the clip's.
    pub feet: FeetReport,
    /// How they move against the clip (speeds, stillness), raw and planted.
    pub kinematics: KinematicReport,
    /// The samples' motion with their feet planted, as `planted_report` scored it (what
    /// `Generated::planted_motion` gives), for further scores without planting again.
    pub planted: Vec<LocalMotion>,
    /// How long the samples, as the network made them, copy the clip verbatim.
    pub replay: ReplayReport,
    /// Seconds spent sampling.
    pub sampling_seconds: f64,
    /// Seconds spent scoring.
    pub scoring_seconds: f64,
}

/// Runs `request` on `denoiser` (a model with `metadata`) and scores the samples against
/// `clip`, raw features `[F, N]` in the model's layout, with `threads` threads: the benchmark's
/// coverage and diversity, and the feet and smoothness figures (SPEC section 9).
pub fn evaluate_model<D: Denoiser>(
    denoiser: &mut D,
    metadata: &ModelMetadata,
    request: &Request,
    clip: ArrayView2<'_, f32>,
    threads: usize,
    progress: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
) -> Result<ModelEvaluation, ModelEvalError>
where
    TaskError: From<D::Error>,
{
    let plan = sinmdm::plan(metadata, request)?;
    check_sample_length(plan.frames())?;
    let started = Instant::now();
    let generated = plan.run(denoiser, progress)?;
    evaluate_generated(generated, clip, threads, started.elapsed().as_secs_f64())
}

/// The benchmark's scores of the samples as the network made them, against the clip's metric
/// features.
fn network_report(
    generated: &Generated,
    clip_metric: ArrayView2<'_, f64>,
    threads: usize,
) -> Result<Report, EvalError> {
    let layout = generated.layout();
    let samples: Vec<Array2<f64>> = generated
        .features
        .outer_iter()
        .map(|sample| metric_features(layout, sample))
        .collect();
    evaluate(clip_metric, &samples, threads.max(1))
}

/// The figures a model's goals are set on, and only those: a quarter of
/// [`evaluate_generated`]'s work (one benchmark report instead of four, no planting).
#[derive(Debug)]
pub struct GoalScores {
    /// The benchmark's scores of the samples as the network made them (coverage, global
    /// diversity...), as [`ModelEvaluation::report`].
    pub report: Report,
    /// How long the samples copy the clip verbatim, as [`ModelEvaluation::replay`].
    pub replay: ReplayReport,
    /// The raw samples' jitter as a multiple of the clip's, as
    /// `ModelEvaluation::feet.raw.jitter_ratio`.
    pub raw_jitter_ratio: f64,
    /// How the raw samples move against the clip, as `ModelEvaluation::kinematics.raw`.
    pub kinematics: KinematicScores,
    /// The clip's own share of nearly still frames (the stillness goal's base).
    pub clip_still_share: f64,
}

/// Scores `generated` against `clip` (raw features `[F, N]` in the samples' layout) for the
/// figures of [`GoalScores`], each equal to the one [`evaluate_generated`] gives.
pub fn goal_scores(
    generated: &Generated,
    clip: ArrayView2<'_, f32>,
    threads: usize,
) -> Result<GoalScores, ModelEvalError> {
    check_sample_length(generated.frames())?;
    let layout = generated.layout();
    let report = network_report(generated, metric_features(layout, clip).view(), threads)?;
    let replay =
        ReplayReport::of_features(layout, clip, generated.features.view(), REPLAY_TOLERANCE);
    let raw = (0..generated.count())
        .map(|i| generated.raw_motion(i))
        .collect::<Result<Vec<_>, _>>()?;
    let clip_motion = decode(layout, clip)?;
    let feet = FeetReport::new(layout, &clip_motion, &raw, &raw);
    let height = layout.skeleton_height;
    let clip_kinematics = Kinematics::of_motion(&clip_motion, height);
    let clip_figures = ClipKinematics::new(&clip_kinematics);
    Ok(GoalScores {
        report,
        replay,
        raw_jitter_ratio: feet.raw.jitter_ratio,
        kinematics: clip_figures.score(&clip_kinematics, &Kinematics::of_motions(&raw, height)),
        clip_still_share: clip_figures.still_share,
    })
}

/// Samples shorter than the coverage window cannot be scored; said before any work.
fn check_sample_length(frames: usize) -> Result<(), EvalError> {
    if frames < COVERAGE_WINDOW {
        return Err(EvalError::TooShort {
            what: "sample length".into(),
            frames,
            needed: COVERAGE_WINDOW,
        });
    }
    Ok(())
}

/// Scores samples made elsewhere (a stream's, say) against `clip`, raw features `[F, N]` in the
/// samples' layout: as [`evaluate_model`] after its sampling. Planted figures plant each sample
/// whole, with nothing kept.
pub fn evaluate_generated(
    generated: Generated,
    clip: ArrayView2<'_, f32>,
    threads: usize,
    sampling_seconds: f64,
) -> Result<ModelEvaluation, ModelEvalError> {
    check_sample_length(generated.frames())?;
    let started = Instant::now();
    let layout = generated.layout();
    let clip_metric = metric_features(layout, clip);
    let report = network_report(&generated, clip_metric.view(), threads)?;
    let body_samples: Vec<Array2<f64>> = generated
        .features
        .outer_iter()
        .map(|sample| body_metric_features(layout, sample))
        .collect();
    let body_clip = body_metric_features(layout, clip);
    let body_report = evaluate(body_clip.view(), &body_samples, threads.max(1))?;
    let replay =
        ReplayReport::of_features(layout, clip, generated.features.view(), REPLAY_TOLERANCE);
    let raw = (0..generated.count())
        .map(|i| generated.raw_motion(i))
        .collect::<Result<Vec<_>, _>>()?;
    let planted = (0..generated.count())
        .map(|i| Ok(generated.planted_motion(i)?.0))
        .collect::<Result<Vec<_>, MotionError>>()?;
    // Decoded motions are scored re-encoded, with the labels the model predicted.
    let score_motions = |motions: &[LocalMotion]| {
        let rows: Vec<Array2<f64>> = motions
            .iter()
            .zip(generated.features.outer_iter())
            .map(|(motion, made)| motion_metric_features(layout, motion, made))
            .collect();
        evaluate(clip_metric.view(), &rows, threads.max(1))
    };
    let raw_motion_report = score_motions(&raw)?;
    let planted_report = score_motions(&planted)?;
    let clip_motion = decode(layout, clip)?;
    let feet = FeetReport::new(layout, &clip_motion, &raw, &planted);
    let kinematics = KinematicReport::new(
        &clip_motion,
        &raw,
        &planted,
        layout.skeleton_height,
        layout.up,
    );
    Ok(ModelEvaluation {
        generated,
        report,
        body_report,
        raw_motion_report,
        planted_report,
        feet,
        kinematics,
        planted,
        replay,
        sampling_seconds,
        scoring_seconds: started.elapsed().as_secs_f64(),
    })
}

impl Report {
    /// The scores as a Markdown table, with the paper's figures on its own benchmark beside
    /// them (ready for a model card).
    pub fn markdown_table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "| metric | mean | std | SinMDM paper (Mixamo) |");
        let _ = writeln!(s, "|---|---|---|---|");
        let rows = [
            ("coverage (%) ↑", self.coverage, 1, "94.3"),
            ("global diversity ↑", self.global_diversity, 3, "1.42"),
            ("local diversity ↑", self.local_diversity, 3, "1.00"),
            ("inter diversity ↑", self.inter_diversity, 3, "0.13"),
        ];
        for (name, stat, digits, paper) in rows {
            let _ = writeln!(
                s,
                "| {name} | {:.digits$} | {:.digits$} | {paper} |",
                stat.mean, stat.std
            );
        }
        let _ = writeln!(
            s,
            "| intra diversity diff ↓ | {:.3} | | 0.03 |",
            self.intra_diversity_diff
        );
        let _ = writeln!(s, "| harmonic mean ↑ | {:.3} | | |", self.harmonic_mean);
        s
    }
}
