//! The diffusion process shared by training and sampling: the schedule, the portable noise, the
//! guidance of the tasks and the sampler.

mod error;
mod guidance;
pub mod method;
pub mod noise;
mod noise_worker;
pub mod sampler;
pub mod schedule;

pub use method::Method;

/// Respaced sampling steps used unless told otherwise (the command line's, the streams' and the
/// C ABI's default). With the default training configuration, 50 ancestral steps score within
/// 5 % of all 1 000 on coverage and global diversity (`docs/SAMPLERS.md`) at half the cost of 100.
pub const DEFAULT_STEPS: usize = 50;
pub use sampler::{
    Denoiser, Guidance, Harmonization, Inpainting, Sampler, SamplerError, StepError,
};
pub use schedule::{DEFAULT_DIFFUSION_STEPS, Schedule, ScheduleError};
