//! # sinmdm
//!
//! The runtime of sinmdm-rs: single-motion diffusion for any skeleton. This crate holds the motion
//! representation (skeletons, rotations, forward kinematics, the feature vector a model learns),
//! BVH input and output (feature `bvh`), the onnxruntime loader, and the `sinmdm` command line
//! (feature `cli`). With default features off it depends only on `ort` and `ndarray` (plus
//! `serde` for the model metadata), for embedding in a game engine.
//!
//! ```no_run
//! # #[cfg(feature = "bvh")] {
//! use sinmdm::motion::{EncodeOptions, encode, decode, poses};
//! let clip = sinmdm::bvh::read_bvh("tests/data/bvh/human_walk_cmu_131_01.bvh")?;
//! let encoded = encode(&clip, &EncodeOptions::default())?; // 30 fps features [F, N]
//! let motion = decode(&encoded.layout, encoded.features.view())?;
//! let frames = poses(&motion); // per frame: root position + local quaternions
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#[cfg(feature = "bvh")]
pub mod bvh;
#[cfg(feature = "cli")]
pub mod cli;
pub mod diffusion;
pub mod eval;
pub mod features_file;
pub mod files;
pub mod model;
pub mod model_file;
pub mod motion;
pub mod onnxruntime;
#[cfg(feature = "render")]
pub mod render;
pub mod tasks;
