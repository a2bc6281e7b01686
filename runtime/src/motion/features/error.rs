//! Why a clip could not become features, or features a clip.

use thiserror::Error;

use crate::motion::up::UpAxis;

/// Errors while turning a clip into features or features into a clip.
#[derive(Debug, Error, PartialEq)]
pub enum MotionError {
    /// The clip has no frames.
    #[error("the clip has no frames")]
    NoFrames,
    /// The heading-relative root was asked for a clip it cannot describe.
    #[error(
        "the heading-relative root cannot describe this clip: {0}; train with root_layout: world"
    )]
    Heading(String),
    /// A contact joint named in the configuration is not in the skeleton.
    #[error("contact joint '{name}' is not in the skeleton (joints: {available})")]
    UnknownContactJoint {
        /// The name that was asked for.
        name: String,
        /// The skeleton's joint names, comma-separated.
        available: String,
    },
    /// A contact threshold or ground fraction that is negative or not a number.
    #[error("contact {what} must be a finite number >= 0, got {value}")]
    BadContactSetting {
        /// Which setting.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A target frame rate that is zero, negative or not a number.
    #[error("frame rate must be a positive number, got {0}")]
    BadFrameRate(f64),
    /// A feature array whose row count does not match the layout.
    #[error("features have {got} rows but the layout describes {expected}")]
    WidthMismatch {
        /// Rows the layout expects.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// Resampling would make an absurdly long clip (a frame time of minutes, say).
    #[error(
        "resampling {frames} frames from {from_fps} fps to {to_fps} fps would give more than {limit} frames; check the clip's Frame Time"
    )]
    TooManyFrames {
        /// Frames in the clip.
        frames: usize,
        /// The clip's rate.
        from_fps: f64,
        /// The target rate.
        to_fps: f64,
        /// The largest clip accepted.
        limit: usize,
    },
    /// A clip whose skeleton is not the one the features are laid out for.
    #[error("the clip's skeleton differs from the model's: {0}")]
    SkeletonMismatch(String),
    /// A clip in another up convention than the model's that cannot be turned.
    #[error("up axis {clip_up}, the model's is {model_up}, and {problem}")]
    CannotReorient {
        /// The clip's up axis.
        clip_up: UpAxis,
        /// The model's.
        model_up: UpAxis,
        /// Why the clip cannot be turned.
        problem: String,
    },
    /// A sample index past the end of a batch.
    #[error("there is no sample {index} in a batch of {count}")]
    NoSuchSample {
        /// The index asked for.
        index: usize,
        /// Samples in the batch.
        count: usize,
    },
    /// A feature array holding NaN or infinity.
    #[error("features contain a non-finite value at row {row}, frame {frame}")]
    NonFinite {
        /// Feature row.
        row: usize,
        /// Frame.
        frame: usize,
    },
    /// Contact labels that do not match the layout's contact joints or the motion's frames.
    #[error(
        "planting feet needs one label series per contact joint ({contacts}), each {frames} frames long"
    )]
    ContactLabels {
        /// Contact joints in the layout.
        contacts: usize,
        /// Frames in the motion.
        frames: usize,
    },
    /// Engine poses that do not fit the skeleton, or hold non-finite numbers.
    #[error("pose {frame}: {problem}")]
    BadPose {
        /// The frame (index into the poses given).
        frame: usize,
        /// What is wrong.
        problem: String,
    },
    /// No poses were given where some are needed.
    #[error("no poses were given")]
    NoPoses,
}
