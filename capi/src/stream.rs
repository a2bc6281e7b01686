//! Endless streamed motion over the C ABI.

use sinmdm::{Stream, StreamCompose, StreamOptions};

use crate::limits::{SINMDM_MAX_JOINT_INDICES, SINMDM_MAX_SAMPLE_FRAMES};
use crate::model::SinmdmModel;
use crate::poses::{SinmdmPoseBuffers, SinmdmPoses, pose_slices, poses_in, poses_out};
use crate::sampling::{feet_arg, method_arg, steps_or};
use crate::status::{Failure, SinmdmStatus, guard, guard_out};
use crate::text::{give, handle_mut, handle_ref, slice_arg};

/// An error of a stream's block, whose arguments were checked when the stream was made: motion
/// that cannot be decoded came from the network, so it is a failed run, not a bad argument.
pub(crate) fn made_by_the_run(e: sinmdm::TaskError) -> Failure {
    match e {
        sinmdm::TaskError::Motion(m) => Failure::new(SinmdmStatus::TaskFailed, m.to_string()),
        other => Failure::from(other),
    }
}

/// A stream (opaque): motion handed out a chunk at a time, forever, in flat memory.
pub struct SinmdmStream {
    pub(crate) stream: Stream,
    /// The model it was made on.
    model: u64,
}

/// How a stream makes its motion; zeros give the defaults.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmStreamOptions {
    /// Seed of the portable noise.
    pub seed: u64,
    /// Respaced denoising steps per block; 0 for `SINMDM_DEFAULT_STREAM_STEPS`, `SINMDM_ALL_STEPS` for
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

/// The stream options a caller's struct asks for, checked.
///
/// # Safety
/// `o`'s joint array as it says.
pub(crate) unsafe fn stream_options(o: &SinmdmStreamOptions) -> Result<StreamOptions, Failure> {
    if o.compose_joint_count > SINMDM_MAX_JOINT_INDICES {
        return Err(Failure::invalid(format!(
            "compose_joint_count is {}; at most {SINMDM_MAX_JOINT_INDICES} joint indices are taken",
            o.compose_joint_count
        )));
    }
    let joints = unsafe { slice_arg(o.compose_joints, o.compose_joint_count, "compose_joints") }?;
    let compose = (!joints.is_empty() || o.compose_root != 0).then(|| StreamCompose {
        joints: joints.to_vec(),
        root: o.compose_root != 0,
    });
    Ok(StreamOptions {
        seed: o.seed,
        steps: steps_or(o.steps, sinmdm::DEFAULT_STREAM_STEPS),
        block_frames: (o.block_frames > 0).then_some(o.block_frames as usize),
        feet: feet_arg(o.feet)?,
        compose,
        method: method_arg(o.method, o.eta)?,
        ..StreamOptions::default()
    })
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
    unsafe {
        guard_out(out, |out| {
            let model = handle_ref(model, "model")?;
            let options = stream_options(handle_ref(options, "options")?)?;
            let stream = Stream::new(model.model.metadata(), options)?;
            give(
                out,
                SinmdmStream {
                    stream,
                    model: model.id,
                },
            );
            Ok(())
        })
    }
}

/// Supplies poses for the frames after the last supplied ones (the first call supplies frame
/// 0 on), for a stream made with composed joints (`SINMDM_INVALID_ARGUMENT` for one without).
/// Poses supplied at least `2 x block_frames + 10` frames ahead of what has been handed out
/// make the stream's motion independent of chunk sizes.
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
        let stream = unsafe { handle_mut(stream, "stream") }?;
        let model = unsafe { handle_ref(model, "model") }?;
        model.check_same(stream.model, "stream")?;
        stream
            .stream
            .supply(&unsafe { poses_in(&model.model, poses, "poses") }?)?;
        Ok(())
    })
}

/// Makes the next `frames` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) on `model` (the model
/// the stream was made with) and writes their poses into `buffers`. The motion is the same
/// whatever chunk sizes are asked for. It runs the network only for frames not yet prepared
/// by `sinmdm_stream_step`. `buffers` is checked as for any other `frames`, 0 included: NULL
/// (or a NULL array but `translations`) gives `SINMDM_NULL_ARGUMENT` and hands out nothing. A
/// stream is advanced on the very handle it was made with: another handle, even of the same
/// file, gives `SINMDM_INVALID_ARGUMENT`, as in `sinmdm_stream_step` and `sinmdm_stream_supply`.
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
        let stream = unsafe { handle_mut(stream, "stream") }?;
        let model = unsafe { handle_mut(model, "model") }?;
        model.check_same(stream.model, "stream")?;
        if frames > SINMDM_MAX_SAMPLE_FRAMES {
            return Err(Failure::invalid(format!(
                "frames is {frames}; one chunk holds at most {SINMDM_MAX_SAMPLE_FRAMES}"
            )));
        }
        let joints = model.model.skeleton().len();
        // Check the buffers before making anything, so a bad one loses no motion.
        unsafe { pose_slices(buffers, frames, joints) }?;
        let chunk = stream
            .stream
            .next(&mut model.model, frames)
            .map_err(made_by_the_run)?;
        unsafe { poses_out(&chunk.poses(), joints, buffers) }
    })
}

/// Prepares frames ahead on `model` (the stream's), spending at most `max_steps` denoising
/// steps: while fewer than `ahead` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) are ready, the
/// next block is made a step at a time. A game calls it each frame with a small `max_steps`
/// and reads with `sinmdm_stream_next`, which then never waits when enough frames are ready;
/// the motion is the same bits as without preparing (for a stream with composed joints, when
/// poses are supplied at least `ahead + 2 x block_frames + 10` frames past those handed out).
/// `ready` (if not NULL) gets the frames
/// ready now; `done` and `total` (if not NULL) the steps of the block in the making (0 of 0
/// when none is).
///
/// # Safety
/// `stream` and `model` are live handles; `ready`, `done` and `total` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_step(
    stream: *mut SinmdmStream,
    model: *mut SinmdmModel,
    max_steps: usize,
    ahead: usize,
    ready: *mut usize,
    done: *mut usize,
    total: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let stream = unsafe { handle_mut(stream, "stream") }?;
        let model = unsafe { handle_mut(model, "model") }?;
        model.check_same(stream.model, "stream")?;
        if ahead > SINMDM_MAX_SAMPLE_FRAMES {
            return Err(Failure::invalid(format!(
                "ahead is {ahead}; at most {SINMDM_MAX_SAMPLE_FRAMES} frames are prepared"
            )));
        }
        let progress = stream
            .stream
            .prepare(&mut model.model, max_steps, ahead)
            .map_err(made_by_the_run)?;
        for (slot, value) in [
            (ready, stream.stream.ready_frames()),
            (done, progress.done),
            (total, progress.total),
        ] {
            if !slot.is_null() {
                unsafe { *slot = value };
            }
        }
        Ok(())
    })
}

/// Frees a stream (NULL is fine).
///
/// # Safety
/// `stream` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_free(stream: *mut SinmdmStream) {
    unsafe { crate::text::free_handle(stream) }
}
