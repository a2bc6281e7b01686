//! # sinmdm-c
//!
//! The C ABI of the sinmdm runtime, for engines in C, C++, C# and anything else that calls C:
//! the header `include/sinmdm.h` is generated from this crate by cbindgen. Built as a shared
//! library (`libsinmdm_c.so`, `sinmdm_c.dll`, `libsinmdm_c.dylib`) and a static one.
//!
//! Conventions, the same at every entry point:
//! - Every function returns a [`SinmdmStatus`]; on failure [`sinmdm_last_error`] (per thread)
//!   says why. A panic inside the library is caught and returned as `SINMDM_INTERNAL`: nothing
//!   unwinds into the caller.
//! - Handles are opaque and freed with their `_free` function (NULL is accepted there).
//! - Output buffers belong to the caller, with their capacity given in elements; a buffer too
//!   small gives `SINMDM_BUFFER_TOO_SMALL` and writes nothing. Strings are UTF-8 and
//!   NUL-terminated; passing a NULL buffer asks for the size only.
//! - Poses are in the model file's frame: right-handed, its up axis (`sinmdm_model_info`) and
//!   its units; quaternions are `x, y, z, w`. See the README's Embedding section for Unity and
//!   Unreal.
//! - Threads: a handle may move between threads but must be used by one thread at a time; a
//!   model and the streams that run on it count as one. Different models may run at once on
//!   different threads. `sinmdm_load_onnxruntime` and `sinmdm_last_error` may be called from
//!   any thread.

#![warn(missing_docs)]

mod model;
mod poses;
mod run;
mod status;
mod stream;
mod text;

pub use model::{
    SinmdmModel, SinmdmModelInfo, sinmdm_load_onnxruntime, sinmdm_model_contact_joints,
    sinmdm_model_find_joint, sinmdm_model_free, sinmdm_model_info, sinmdm_model_joint_name,
    sinmdm_model_open, sinmdm_model_open_bytes, sinmdm_model_parents, sinmdm_model_rest_offsets,
    sinmdm_version,
};
pub use poses::{SinmdmPoseBuffers, SinmdmPoses, sinmdm_write_bvh};
pub use run::{
    SINMDM_ALL_STEPS, SINMDM_DEFAULT_STEPS, SINMDM_FEET_PLANTED, SINMDM_FEET_RAW,
    SINMDM_METHOD_ANCESTRAL, SINMDM_METHOD_DDIM, SINMDM_METHOD_DPM2M, SinmdmResult, SinmdmSampling,
    SinmdmSpan, sinmdm_compose, sinmdm_expand, sinmdm_generate, sinmdm_harmonize, sinmdm_inbetween,
    sinmdm_result_count, sinmdm_result_frames, sinmdm_result_free, sinmdm_result_poses,
};
pub use status::{SinmdmStatus, sinmdm_last_error};
pub use stream::{
    SinmdmStream, SinmdmStreamOptions, sinmdm_stream_free, sinmdm_stream_new, sinmdm_stream_next,
    sinmdm_stream_supply,
};
