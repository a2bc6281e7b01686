//! # sinmdm
//!
//! The engine runtime of sinmdm-rs: a model trained on one motion clip (a `.onnx` file written
//! by `sinmdm-export`) generates new motion of any length, crowds, in-betweens, expansions,
//! body-part composition and style transfer, through onnxruntime. Its dependencies are `ort`,
//! `libloading` (ort's own loader), `ndarray`, `serde`, `serde_json` and `thiserror`; BVH reading
//! and writing is the default feature `bvh`.
//!
//! The engine path is the items on this page: open a [`Model`], look at its [`Skeleton`], make
//! a [`Request`] of a [`Task`], [`run`] it (or [`plan`] it and step a [`Sampler`] yourself),
//! and read [`Pose`]s from the [`Generated`] batch.
//!
//! ```
//! use std::ops::ControlFlow;
//! use sinmdm::{Feet, Model, ModelOptions, Request, Task};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../onnx-models/human_walk_cmu.onnx");
//! let mut model = Model::open(path, &ModelOptions::default())?;
//! println!("{} joints at {} fps", model.skeleton().len(), model.fps());
//! let request = Request {
//!     task: Task::Generate { frames: 60 },
//!     count: 2,
//!     seed: 7,
//!     steps: Some(10),
//!     feet: Feet::Planted, // contact points held still on the ground; Feet::Raw leaves them
//!     method: Default::default(), // ancestral; Method::DpmSolver2M needs fewer steps
//! };
//! let generated = sinmdm::run(&mut model, &request, &mut |_done, _steps| ControlFlow::Continue(()))?;
//! let poses = generated.poses(0)?; // per frame: root position, local rotations, translations
//! assert_eq!(poses.len(), 60);
//! assert_eq!(poses[0].rotations.len(), model.skeleton().len());
//! # Ok(())
//! # }
//! ```
//!
//! Besides this page: [`bvh`] (BVH files in and out), [`model_file`] (the metadata a model file
//! carries) and [`limits`] (every bound on what the engine is given).

#![warn(missing_docs)]

// The documented surface is this page, [`bvh`], [`limits`] and [`model_file`]. The other
// modules are the plumbing that the project's other crates (training, export, formats, the
// command line, the C ABI) and its tests build on: public so they can, hidden from the
// documentation so an engine programmer is not asked to read them.
pub mod batched;
#[cfg(feature = "bvh")]
pub mod bvh;
#[doc(hidden)]
pub mod diffusion;
#[doc(hidden)]
pub mod features_file;
#[doc(hidden)]
pub mod files;
pub mod limits;
mod model;
pub mod model_file;
#[doc(hidden)]
pub mod motion;
#[doc(hidden)]
pub mod network;
mod onnxruntime;
mod onnxruntime_version;
#[doc(hidden)]
pub mod soft_border;
#[doc(hidden)]
pub mod steer;
#[doc(hidden)]
pub mod stream;
#[doc(hidden)]
pub mod tasks;

pub use batched::OneCallPerThread;
pub use diffusion::{DEFAULT_STEPS, Denoiser, Method, Sampler, SamplerError, StepError};
pub use model::{Model, ModelError, ModelOptions};
pub use model_file::ModelMetadata;
pub use motion::{
    Channel, FeatureLayout, Feet, Joint, LocalMotion, Pose, Quaternion, Skeleton, UpAxis,
    features_from_poses, motion_from_poses,
};
pub use onnxruntime::{
    ONNXRUNTIME_VERSION, OnnxRuntime, RuntimeLibraryError, init as init_onnxruntime,
    load_onnxruntime,
};
pub use stream::{
    CharacterId, Crowd, CrowdProgress, DEFAULT_STREAM_STEPS, Stream, StreamChunk, StreamCompose,
    StreamOptions,
};
pub use tasks::{Generated, Plan, Progress, Request, Run, Span, Task, TaskError, plan, run};
