//! Why a sampling run cannot be set up: shared by the sampler and the guidance it checks.

use thiserror::Error;

/// A sampling run that cannot be set up as asked.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum SamplerError {
    /// No samples or no frames.
    #[error(
        "a sampling run needs at least one sample of at least one frame, got {batch} x {frames}"
    )]
    Empty {
        /// Samples asked for.
        batch: usize,
        /// Frames asked for.
        frames: usize,
    },
    /// A guidance array whose shape is not the sample's `[F, N]`.
    #[error("the {what} is {got:?}, the samples are [{features}, {frames}] (feature rows, frames)")]
    Shape {
        /// Which array.
        what: &'static str,
        /// Its `[rows, frames]`.
        got: (usize, usize),
        /// F of the run.
        features: usize,
        /// N of the run.
        frames: usize,
    },
    /// A harmonization low-pass factor of 0.
    #[error("the harmonization down-sampling factor must be at least 1")]
    ZeroFactor,
    /// A sampling method with a setting out of range.
    #[error("{0}")]
    Method(String),
    /// A step finished that was not begun.
    #[error("a step was finished without being begun (call begin_step first)")]
    StepNotBegun,
    /// A denoiser whose feature rows are not the run's.
    #[error("the denoiser has {denoiser} feature rows, the run {run}")]
    Features {
        /// F of the denoiser.
        denoiser: usize,
        /// F of the run.
        run: usize,
    },
}
