//! Errors of the training crate; each names the file, key or setting at fault.

use std::path::PathBuf;

/// Everything that can stop a training run.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    /// A file could not be read or written. The reasons of this and the other file errors are
    /// said in the message and not chained as sources, so a printer of causes says them once.
    #[error("could not {what} '{}': {reason}", path.display())]
    Io {
        /// What was being done.
        what: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// The system's reason, or the limit the file broke.
        reason: std::io::Error,
    },
    /// The configuration is malformed or holds a bad value.
    #[error("{}: {message}", path.display())]
    Config {
        /// The config file.
        path: PathBuf,
        /// What is wrong (names the key).
        message: String,
    },
    /// A run was started with a configuration that leaves settings to the rule that reads the
    /// clip: the policy applies that rule before a run starts, and the run trains final numbers.
    #[error(
        "the configuration's from_clip section leaves settings to the rule that reads the clip; start the run through choose::start_run (as sinmdm-train does), or turn from_clip off"
    )]
    RuleNotApplied,
    /// The clip could not be read.
    #[error(transparent)]
    Bvh(#[from] sinmdm::bvh::BvhError),
    /// A clip in another format could not be read.
    #[error(transparent)]
    Format(#[from] sinmdm_formats::FormatError),
    /// The clip (or the animation of it read) does not move, so there is nothing to learn.
    #[error(
        "{}: {what} does not move (no channel's standard deviation is above {tolerance}); pick one that does (data.animation, --clip-anim)",
        path.display()
    )]
    StillClip {
        /// The clip.
        path: PathBuf,
        /// What was read (`animation 'Take 001' (#0)`, or `the clip`).
        what: String,
        /// The tolerance it is held to.
        tolerance: f64,
    },
    /// The clip could not be turned into features.
    #[error("{}: {reason}", path.display())]
    Motion {
        /// The clip.
        path: PathBuf,
        /// The reason.
        reason: sinmdm::motion::MotionError,
    },
    /// A time budget leaves no time for one step.
    #[error(
        "--minutes {minutes} leaves no time to train: one step takes {seconds_per_step:.3} s here"
    )]
    NoTimeToTrain {
        /// The budget, in minutes.
        minutes: f64,
        /// Seconds one step took in the probe.
        seconds_per_step: f64,
    },
    /// The clip is shorter than what the network sees at once.
    #[error(
        "{}: the clip has {frames} frames at {fps} fps, fewer than the model's receptive field of {receptive_field} frames; use a longer clip or a higher data.fps",
        path.display()
    )]
    ClipTooShort {
        /// The clip.
        path: PathBuf,
        /// Frames after resampling.
        frames: usize,
        /// The training frame rate.
        fps: f64,
        /// The receptive field.
        receptive_field: usize,
    },
    /// A checkpoint cannot be used for this run.
    #[error("{}: {message}", path.display())]
    Checkpoint {
        /// The checkpoint or run folder.
        path: PathBuf,
        /// What does not fit.
        message: String,
    },
    /// A rung of the step ladder could not be sampled or scored ([`crate::choose::step_ladder`]).
    #[error("could not check the samples of '{}' (a rung of the step ladder that chooses a calm clip's steps): {message}", model.display())]
    Check {
        /// The rung's model file.
        model: PathBuf,
        /// Why.
        message: String,
    },
    /// The model could not be exported.
    #[error("export failed: {0}")]
    Export(String),
    /// Steps kept going non-finite after every recovery the trainer tries.
    #[error(
        "the loss or its gradients kept going non-finite: at step {step}, after {tried}, the run had already gone back to step {to} {rollbacks} times; stopped. The last good checkpoint is {}; a smaller training.learning_rate or another training.seed may get past it",
        last_checkpoint.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "none (no checkpoint was written yet)".into())
    )]
    Unrecoverable {
        /// The step that failed last.
        step: u64,
        /// The step the run kept going back to.
        to: u64,
        /// How many times it went back there (the most the trainer allows).
        rollbacks: u32,
        /// What was tried (skipped steps, roll-backs, the learning rate's factor).
        tried: String,
        /// The newest checkpoint on disk.
        last_checkpoint: Option<PathBuf>,
    },
}

/// A closure turning an I/O error into [`TrainError::Io`] about `path`.
pub(crate) fn io<'a>(
    what: &'static str,
    path: &'a std::path::Path,
) -> impl FnOnce(std::io::Error) -> TrainError + 'a {
    move |source| TrainError::Io {
        what,
        path: path.to_path_buf(),
        reason: source,
    }
}
