//! The diffusion process shared by training and sampling: the schedule and the portable noise.

pub mod noise;
pub mod sampler;
pub mod schedule;

pub use schedule::{DEFAULT_DIFFUSION_STEPS, Schedule, ScheduleError};
