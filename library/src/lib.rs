//! # sinmdm-library
//!
//! A motion library (hundreds of clips, a model each) run as one array job on the schedulers
//! teams already have: Slurm's job arrays or a Kubernetes Indexed Job. The unit of work is one
//! clip: task `N` trains, exports and evaluates clip `N` of the [`manifest`] into a folder of its
//! own ([`task`]), and is idempotent (a [`fingerprint`] of the clip, its settings and the code
//! decides whether the model is current), resumable (the run folder keeps checkpoints) and
//! atomic (files appear whole; no two tasks share a file). [`report`] reads every folder back:
//! which clips are done, running, failed or stale, and one table and contact sheet of them all.

#![warn(missing_docs)]

pub mod error;
pub mod fingerprint;
pub mod manifest;
pub mod report;
pub mod status;
pub mod task;

pub use error::LibraryError;
pub use manifest::{ClipEntry, Manifest, task_index};
pub use status::{State, TaskStatus};
pub use task::TaskFolder;
