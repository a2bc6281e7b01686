//! # sinmdm-train
//!
//! Fits the QnA-UNet denoiser of single-motion diffusion on one BVH clip with burn (CPU `flex`
//! backend by default; `cuda` and `wgpu` features for GPUs), and saves checkpoints that the
//! export step turns into the `.onnx` file the runtime ships with.

pub mod checkpoint;
pub mod clip_data;
pub mod clip_rule;
pub mod clock;
pub mod config;
pub mod data;
pub mod error;
pub mod export;
pub mod ladder_settings;
pub mod library_task;
pub mod loss;
pub mod loss_log;
pub mod loss_plot;
pub mod memory;
pub mod model;
pub mod motion_span;
pub mod pace;
pub mod recovery;
pub mod run_folder;
mod shards;
pub mod step;
pub mod step_ladder;
pub mod trainer;
pub mod weight_average;

pub use config::TrainConfig;
pub use error::TrainError;
pub use model::QnaUnet;
pub use trainer::{RunEnd, StepReport, Trainer};

/// Tests that seed or draw from the CPU device's random generator, which every test thread
/// shares, hold this lock, so that one test's draws never fall between another's seed and draw.
#[cfg(test)]
pub(crate) fn device_random_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}
