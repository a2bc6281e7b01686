//! # sinmdm-train
//!
//! Fits the single-motion QnA-UNet denoiser on one BVH clip with burn, reading the clip through
//! the runtime crate's motion representation. The model and training loop are not built yet;
//! this crate reserves its place in the workspace.
