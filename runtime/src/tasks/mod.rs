//! The applications of SPEC section 5, each a [`Task`]: plain generation (one sample or a
//! crowd), in-betweening, expansion, joint composition and harmonization.
//!
//! A [`Request`] (task, count, seed, steps) is checked against the model first ([`plan`]), so
//! bad spans, joints, lengths or crowd sizes fail before any network call; the checked [`Plan`]
//! then runs on any [`Denoiser`](crate::diffusion::Denoiser) and gives a [`Generated`] batch in
//! the model's feature layout.

mod dance;
mod generated;
mod guidance;
mod joints;
pub mod mask;
mod plan;
mod run;

use std::convert::Infallible;

use thiserror::Error;

use crate::diffusion::sampler::{SamplerError, StepError};
use crate::diffusion::{Method, ScheduleError};
use crate::model::ModelError;
use crate::motion::feet::Feet;
use crate::motion::{FeatureMatrix, MotionError};
pub use dance::{
    BeatLevel, DANCE_HOLD, DANCE_ORDER_STREAM, DANCE_RAMP, DANCE_TEMPO_RANGE, DanceBeats, KeyOrder,
    Keyframe, Placement, keyframe_order, place_keyframes,
};
pub use generated::Generated;
pub use joints::{joints_by_name, subtree};
pub use mask::Span;
pub use plan::{Plan, plan, run, run_values_per_frame};
pub use run::{Progress, Run};

pub use crate::limits::{MAX_RUN_VALUES, MAX_SAMPLE_FRAMES, MAX_SAMPLES};
/// Default soft border of in-betweening and composition spans, in frames.
pub const INBETWEEN_RAMP: usize = 10;
/// Default soft border of expansion, in frames.
pub const EXPAND_RAMP: usize = 6;
/// Default share of final steps that harmonization leaves free.
pub const HARMONIZE_FREE_SHARE: f64 = 0.02;
/// Default down-sampling factor of harmonization's low-pass.
pub const HARMONIZE_FACTOR: usize = 2;

/// Why a task could not run.
#[derive(Debug, Error)]
pub enum TaskError {
    /// The model failed to run.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A sampling run that does not fit its denoiser.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// The progress callback stopped the run.
    #[error("the run was cancelled after {done} of {steps} steps")]
    Cancelled {
        /// Steps taken.
        done: usize,
        /// Steps in the run.
        steps: usize,
    },
    /// A run finished before its first step: there is no motion to show yet.
    #[error("the run has taken none of its {steps} steps, so there is no motion yet")]
    NotStarted {
        /// Steps in the run.
        steps: usize,
    },
    /// Features that could not be turned into motion.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// A bad number of sampling steps.
    #[error(transparent)]
    Steps(#[from] ScheduleError),
    /// A sample length of zero or beyond the limit.
    #[error("a sample of {frames} frames is not possible: {reason}")]
    Length {
        /// The frames asked for.
        frames: usize,
        /// Why not.
        reason: String,
    },
    /// A crowd of zero or beyond the limit.
    #[error("the number of samples must be between 1 and {MAX_SAMPLES}, got {0}")]
    Count(usize),
    /// A batch too large to hold.
    #[error(
        "{count} samples of {frames} frames of this model ({features} features) need about {gib:.1} GiB; ask for fewer or shorter samples"
    )]
    TooLarge {
        /// Samples.
        count: usize,
        /// Frames each.
        frames: usize,
        /// Feature rows.
        features: usize,
        /// The memory the batch would take.
        gib: f64,
    },
    /// Steering that this model or these commands cannot do.
    #[error("cannot steer: {0}")]
    Steer(String),
    /// A span with no frames.
    #[error("span {0} is empty (its end must come after its start)")]
    EmptySpan(Span),
    /// A span beyond the reference.
    #[error("span {span} reaches past the reference's {frames} frames (frames are 0..{frames})")]
    SpanOutOfRange {
        /// The span.
        span: Span,
        /// Frames in the reference.
        frames: usize,
    },
    /// Two spans that share frames.
    #[error("spans {0} and {1} overlap")]
    SpansOverlap(Span, Span),
    /// A task that needs spans got none.
    #[error("{0}")]
    NothingToDo(String),
    /// A joint name not in the model's skeleton.
    #[error("joint '{name}' is not in the model's skeleton (joints: {available})")]
    UnknownJoint {
        /// The name given.
        name: String,
        /// The skeleton's joints.
        available: String,
    },
    /// A joint index past the end of the model's skeleton.
    #[error("joint index {index} is not in the model's skeleton of {joints} joints")]
    JointIndex {
        /// The index given.
        index: usize,
        /// Joints in the skeleton.
        joints: usize,
    },
    /// A reference of the wrong width.
    #[error("the reference has {got} feature rows, the model {expected}")]
    ReferenceWidth {
        /// F of the model.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// A soft border wider than any sample can be.
    #[error(
        "a soft border (ramp) of {0} frames is wider than the longest sample, {MAX_SAMPLE_FRAMES} frames"
    )]
    Ramp(usize),
    /// A harmonization factor or free share out of range.
    #[error("{0}")]
    Harmonization(String),
    /// Stream options that cannot work together.
    #[error("{0}")]
    Stream(String),
    /// Dance beats that cannot be placed.
    #[error("{0}")]
    Dance(String),
    /// What went wrong with one character of a crowd.
    #[error("character {id}: {source}")]
    Character {
        /// The character ([`crate::CharacterId`]'s number).
        id: u64,
        /// What went wrong.
        source: Box<TaskError>,
    },
}

impl From<Infallible> for TaskError {
    fn from(never: Infallible) -> TaskError {
        match never {}
    }
}

impl<E> From<StepError<E>> for TaskError
where
    TaskError: From<E>,
{
    fn from(e: StepError<E>) -> TaskError {
        match e {
            StepError::Setup(e) => TaskError::Sampler(e),
            StepError::Denoiser(e) => TaskError::from(e),
        }
    }
}

/// What to make.
#[derive(Debug, Clone, PartialEq)]
pub enum Task {
    /// New motion of `frames` frames.
    Generate {
        /// Frames per sample.
        frames: usize,
    },
    /// Keep `keep` spans of the reference, generate the gaps; soft borders of `ramp` frames.
    Inbetween {
        /// Raw (unnormalised) reference features `[F, N]` in the model's layout.
        reference: FeatureMatrix,
        /// Frame spans to keep.
        keep: Vec<Span>,
        /// Soft border on the kept side, in frames.
        ramp: usize,
    },
    /// The reference in the middle, `prefix` new frames before and `suffix` after.
    Expand {
        /// Raw reference features `[F, N]`.
        reference: FeatureMatrix,
        /// New frames before the reference.
        prefix: usize,
        /// New frames after it.
        suffix: usize,
        /// Soft border on the reference's side, in frames.
        ramp: usize,
    },
    /// Take the chosen joints (and/or the root motion) from the reference on `spans` (all frames
    /// when empty); generate the rest of the body.
    Compose {
        /// Raw reference features `[F, N]`.
        reference: FeatureMatrix,
        /// Joints whose columns come from the reference (indices into the model's skeleton).
        joints: Vec<usize>,
        /// Whether the root's travel and height come from the reference.
        root: bool,
        /// Frame spans where they do; empty means every frame.
        spans: Vec<Span>,
        /// Soft border at span ends, in frames.
        ramp: usize,
    },
    /// Dance: windows of the reference around its beats placed on the music's beats (see
    /// [`place_keyframes`]), the motion between them generated.
    Dance {
        /// Raw reference features `[F, N]`.
        reference: FeatureMatrix,
        /// The beats on both sides and how keyframes are placed on them.
        beats: DanceBeats,
        /// Whether the root's travel and height in each window come from the reference (its
        /// heading stays with the top joint's rotation either way).
        root: bool,
    },
    /// New motion of `frames` frames whose root goes where `commands` say, frame by frame
    /// (a path on the ground, or forward speed and turn rate; [`crate::steer`]), from the
    /// model's start position and facing. Needs a heading-relative model.
    Steer {
        /// Frames per sample.
        frames: usize,
        /// One command per frame from frame 0 (shorter lists leave the later frames free;
        /// commands past `frames` are not used).
        commands: Vec<crate::steer::SteerFrame>,
        /// Soft border at the ends of each span of commands, in frames.
        ramp: usize,
    },
    /// Style transfer: the content's low frequencies in the model's style.
    Harmonize {
        /// Raw content features `[F, N]`.
        content: FeatureMatrix,
        /// Down-sampling factor of the low-pass.
        factor: usize,
        /// Share of final steps left free.
        free_share: f64,
    },
}

/// A task with its sampling settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// What to make.
    pub task: Task,
    /// Samples in the batch (a crowd when more than 1).
    pub count: usize,
    /// Seed of the portable noise.
    pub seed: u64,
    /// Sampling steps S (respaced); `None` runs all T steps.
    pub steps: Option<usize>,
    /// What the motion and poses of the result do to the feet: planted (the default) or raw.
    /// A post-process of decoded motion: the features are the same either way.
    pub feet: Feet,
    /// The update rule of each step: ancestral (the default), DDIM or DPM-Solver++(2M).
    pub method: Method,
}
