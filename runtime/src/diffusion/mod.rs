//! The diffusion process shared by training and sampling: the schedule, the portable noise, the
//! guidance of the tasks and the sampler.

mod guidance;
pub mod method;
pub mod noise;
mod noise_worker;
pub mod sampler;
pub mod schedule;

pub use method::Method;
pub use sampler::{
    Denoiser, Guidance, Harmonization, Inpainting, Sampler, SamplerError, StepError, sample,
};
pub use schedule::{DEFAULT_DIFFUSION_STEPS, Schedule, ScheduleError};
