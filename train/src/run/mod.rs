//! A training run in its folder: the trainer and its optimiser step, checkpoints, recovery from
//! non-finite steps, the weight average, the loss log and its plot.
//!
//! A run trains the final configuration it is given; what the rule that reads the clip chose,
//! and why, reaches it as a [`crate::chosen::Choices`] record that it keeps and prints. Nothing
//! here imports the policy (`choose`), which sits above the run.

pub mod checkpoint;
pub mod folder;
pub mod loss;
pub mod loss_log;
pub mod loss_plot;
pub mod pace;
pub mod recovery;
mod shards;
pub mod step;
pub mod trainer;
pub mod weight_average;

pub use trainer::{RunEnd, StepReport, Trainer};
