//! Endless streamed motion over the C ABI.

use sinmdm::{Stream, StreamCompose, StreamOptions};

use crate::model::{SinmdmModel, model_arg};
use crate::poses::{SinmdmPoseBuffers, SinmdmPoses, pose_slices, poses_in, poses_out};
use crate::run::{feet_arg, method_arg, steps_arg};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::text::{give, handle, slice_arg};

/// A stream (opaque): motion handed out a chunk at a time, forever, in flat memory.
pub struct SinmdmStream {
    stream: Stream,
}

/// How a stream makes its motion; zeros give the defaults.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmStreamOptions {
    /// Seed of the portable noise.
    pub seed: u64,
    /// Respaced denoising steps per block; 0 for `SINMDM_DEFAULT_STEPS`, `SINMDM_ALL_STEPS` for
    /// all of the model's T.
    pub steps: u32,
    /// Frames each block makes final; 0 for the length of the model's training clip.
    pub block_frames: u32,
    /// `SINMDM_FEET_PLANTED` or `SINMDM_FEET_RAW`.
    pub feet: u32,
    /// Joints taken from poses supplied with `sinmdm_stream_supply` (NULL with count 0: none).
    pub compose_joints: *const usize,
    /// Entries of `compose_joints`.
    pub compose_joint_count: usize,
    /// Not 0: the root's travel and height also come from the supplied poses.
    pub compose_root: i32,
    /// `SINMDM_METHOD_ANCESTRAL` (0, the default), `SINMDM_METHOD_DDIM` or `SINMDM_METHOD_DPM2M`.
    pub method: u32,
    /// DDIM's share of the ancestral noise, 0 to 1.
    pub eta: f64,
}

/// Makes a stream of `model`'s motion with `options` and writes its handle to `out`.
///
/// # Safety
/// `model` is a live handle; `options` readable (its joint array as it says); `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_new(
    model: *const SinmdmModel,
    options: *const SinmdmStreamOptions,
    out: *mut *mut SinmdmStream,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let o = *unsafe { handle(options.cast_mut(), "options") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let joints =
            unsafe { slice_arg(o.compose_joints, o.compose_joint_count, "compose_joints") }?;
        let compose = (!joints.is_empty() || o.compose_root != 0).then(|| StreamCompose {
            joints: joints.to_vec(),
            root: o.compose_root != 0,
        });
        let options = StreamOptions {
            seed: o.seed,
            steps: steps_arg(o.steps),
            block_frames: (o.block_frames > 0).then_some(o.block_frames as usize),
            feet: feet_arg(o.feet)?,
            compose,
            method: method_arg(o.method, o.eta)?,
            ..StreamOptions::default()
        };
        let stream = Stream::new(model.metadata(), options)?;
        unsafe { give(out, SinmdmStream { stream }) };
        Ok(())
    })
}

/// Supplies poses for the frames after the last supplied ones (the first call supplies frame
/// 0 on), for a stream with composed joints. Poses supplied at least
/// `2 x block_frames + 10` frames ahead of what has been handed out make the stream's motion
/// independent of chunk sizes.
///
/// # Safety
/// `stream` and `model` are live handles (the stream's model); `poses` as its documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_supply(
    stream: *mut SinmdmStream,
    model: *const SinmdmModel,
    poses: *const SinmdmPoses,
) -> SinmdmStatus {
    guard(|| {
        let stream = unsafe { handle(stream, "stream") }?;
        let model = unsafe { model_arg(model) }?;
        stream
            .stream
            .supply(&unsafe { poses_in(model, poses, "poses") }?)?;
        Ok(())
    })
}

/// Makes the next `frames` frames on `model` (the model the stream was made with) and writes
/// their poses into `buffers`. The motion is the same whatever chunk sizes are asked for.
///
/// # Safety
/// `stream` and `model` are live handles; `buffers` as its documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_next(
    stream: *mut SinmdmStream,
    model: *mut SinmdmModel,
    frames: usize,
    buffers: *const SinmdmPoseBuffers,
) -> SinmdmStatus {
    guard(|| {
        let stream = unsafe { handle(stream, "stream") }?;
        let model = unsafe { handle(model, "model") }?;
        let joints = model.model.skeleton().len();
        // Check the buffers before making anything, so a bad one loses no motion.
        unsafe { pose_slices(buffers, frames, joints) }?;
        if model.model.metadata() != stream.stream.metadata() {
            return Err(Failure::invalid("the stream was made with another model"));
        }
        let chunk = stream.stream.next(&mut model.model, frames)?;
        unsafe { poses_out(&chunk.poses(), joints, buffers) }
    })
}

/// Frees a stream (NULL is fine).
///
/// # Safety
/// `stream` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_free(stream: *mut SinmdmStream) {
    if !stream.is_null() {
        drop(unsafe { Box::from_raw(stream) });
    }
}
