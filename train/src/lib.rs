//! # sinmdm-train
//!
//! Fits the QnA-UNet denoiser of single-motion diffusion on one BVH clip with burn (CPU `flex`
//! backend by default; `cuda` and `wgpu` features for GPUs), and saves checkpoints that the
//! export step turns into the `.onnx` file the runtime ships with.
//!
//! The crate has three wings, each importing only the ones below it:
//! - [`choose`]: the policy. What a new run trains, read from the clip (the rule, the step
//!   ladder, a time budget), handed down as a final configuration and a [`chosen::Choices`]
//!   record of what was chosen and why.
//! - [`run`]: a training run in its folder. The trainer, the optimiser step, checkpoints,
//!   recovery, the weight average and the loss log; it trains the configuration it is given and
//!   imports nothing from [`choose`].
//! - [`clip`]: the clip a model learns, read and encoded, and the noised batches drawn from it.
//!
//! Below them all: [`config`], [`model`], [`chosen`] (the record's types and its text), and
//! [`error`].

pub mod choose;
pub mod chosen;
pub mod clip;
pub mod clock;
pub mod config;
pub mod error;
pub mod export;
pub mod library_task;
pub mod memory;
pub mod model;
pub mod run;

pub use config::TrainConfig;
pub use error::TrainError;
pub use model::QnaUnet;
pub use run::{RunEnd, StepReport, Trainer};

/// Tests that seed or draw from the CPU device's random generator, which every test thread
/// shares, hold this lock, so that one test's draws never fall between another's seed and draw.
#[cfg(test)]
pub(crate) fn device_random_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}
