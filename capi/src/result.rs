//! A generated batch and what a host reads from it.

use sinmdm::Generated;

use crate::poses::{SinmdmPoseBuffers, poses_out};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::text::{handle_mut, handle_ref};

/// A generated batch (opaque).
pub struct SinmdmResult {
    pub(crate) generated: Generated,
}

/// Writes the number of samples in the batch to `count`.
///
/// # Safety
/// `result` is a live handle; `count` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_result_count(
    result: *const SinmdmResult,
    count: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let result = unsafe { handle_ref(result, "result") }?;
        *unsafe { handle_mut(count, "count") }? = result.generated.count();
        Ok(())
    })
}

/// Writes the frames per sample to `frames`.
///
/// # Safety
/// `result` is a live handle; `frames` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_result_frames(
    result: *const SinmdmResult,
    frames: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let result = unsafe { handle_ref(result, "result") }?;
        *unsafe { handle_mut(frames, "frames") }? = result.generated.frames();
        Ok(())
    })
}

/// Writes sample `sample`'s poses (feet as the sampling asked) into `buffers`.
///
/// # Safety
/// `result` is a live handle; `buffers` as its documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_result_poses(
    result: *const SinmdmResult,
    sample: usize,
    buffers: *const SinmdmPoseBuffers,
) -> SinmdmStatus {
    guard(|| {
        let result = unsafe { handle_ref(result, "result") }?;
        let count = result.generated.count();
        if sample >= count {
            return Err(Failure::invalid(format!(
                "sample {sample} is not in the batch of {count}"
            )));
        }
        let joints = result.generated.layout().skeleton.len();
        let frames = result.generated.frames();
        // Check the buffers before decoding anything.
        unsafe { crate::poses::pose_slices(buffers, frames, joints) }?;
        let poses = result
            .generated
            .poses(sample)
            // The batch was made by the network: motion it cannot give is a failed run.
            .map_err(|e| Failure::new(SinmdmStatus::TaskFailed, e.to_string()))?;
        unsafe { poses_out(&poses, joints, buffers) }
    })
}

/// Frees a batch (NULL is fine).
///
/// # Safety
/// `result` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_result_free(result: *mut SinmdmResult) {
    unsafe { crate::text::free_handle(result) }
}
