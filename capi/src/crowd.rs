//! Many characters' streams advanced together over the C ABI: one network call per step for
//! the whole crowd, each character the same bits as its stream alone.

use sinmdm::{CharacterId, Crowd};

use crate::limits::{SINMDM_MAX_CROWD_CHARACTERS, SINMDM_MAX_SAMPLE_FRAMES};
use crate::model::SinmdmModel;
use crate::poses::{SinmdmPoseBuffers, SinmdmPoses, pose_slices, poses_in, poses_out};
use crate::status::{Failure, SinmdmStatus, guard, guard_out};
use crate::steer::{SINMDM_STEER_POSITION_FACING, SinmdmSteerCommand, steer_stream};
use crate::stream::{SinmdmStreamOptions, made_by_the_run, stream_options};
use crate::text::{give, handle_mut, handle_ref};

/// A crowd (opaque): characters of one model, each an endless stream, made together.
pub struct SinmdmCrowd {
    crowd: Crowd,
    /// The model it was made on.
    model: u64,
}

impl SinmdmCrowd {
    /// Character `id`'s stream, or why not.
    fn character(&mut self, id: u64) -> Result<&mut sinmdm::Stream, Failure> {
        self.crowd
            .character_mut(CharacterId(id))
            .ok_or_else(|| Failure::invalid(format!("no character {id} is in the crowd")))
    }
}

/// Makes an empty crowd of `model` and writes its handle to `out`.
///
/// # Safety
/// `model` is a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_new(
    model: *const SinmdmModel,
    out: *mut *mut SinmdmCrowd,
) -> SinmdmStatus {
    unsafe {
        guard_out(out, |out| {
            let model = handle_ref(model, "model")?;
            give(
                out,
                SinmdmCrowd {
                    crowd: Crowd::new(model.model.metadata()),
                    model: model.id,
                },
            );
            Ok(())
        })
    }
}

/// Adds a character whose motion is a stream with `options` (as `sinmdm_stream_new` takes
/// them) and writes its number to `id`: numbers count up from 0 and are never given again. At
/// most `SINMDM_MAX_CROWD_CHARACTERS` characters at once.
///
/// # Safety
/// `crowd` is a live handle; `options` readable (its joint array as it says); `id` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_join(
    crowd: *mut SinmdmCrowd,
    options: *const SinmdmStreamOptions,
    id: *mut u64,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        let options = unsafe { stream_options(handle_ref(options, "options")?) }?;
        let id = unsafe { handle_mut(id, "id") }?;
        if crowd.crowd.len() >= SINMDM_MAX_CROWD_CHARACTERS {
            return Err(Failure::invalid(format!(
                "the crowd holds {SINMDM_MAX_CROWD_CHARACTERS} characters, the most it takes"
            )));
        }
        *id = crowd.crowd.join(options)?.0;
        Ok(())
    })
}

/// Takes character `id` out of the crowd (its motion ends); `SINMDM_INVALID_ARGUMENT` if no
/// such character is in it.
///
/// # Safety
/// `crowd` is a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_leave(crowd: *mut SinmdmCrowd, id: u64) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        crowd.character(id)?;
        crowd.crowd.leave(CharacterId(id));
        Ok(())
    })
}

/// Characters in the crowd, written to `count`.
///
/// # Safety
/// `crowd` is a live handle; `count` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_count(
    crowd: *const SinmdmCrowd,
    count: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_ref(crowd, "crowd") }?;
        *unsafe { handle_mut(count, "count") }? = crowd.crowd.len();
        Ok(())
    })
}

/// Queues character `id`'s steering commands, as `sinmdm_stream_steer_commands` does for a
/// stream.
///
/// # Safety
/// `crowd` is a live handle; `commands` readable for `count` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_steer(
    crowd: *mut SinmdmCrowd,
    id: u64,
    commands: *const SinmdmSteerCommand,
    count: usize,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        let stream = crowd.character(id)?;
        unsafe { steer_stream(stream, commands, count, SINMDM_STEER_POSITION_FACING) }
    })
}

/// Supplies character `id`'s poses for the frames after the last supplied ones, as
/// `sinmdm_stream_supply` does for a stream made with composed joints.
///
/// # Safety
/// `crowd` and `model` are live handles (the crowd's model); `poses` as its documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_supply(
    crowd: *mut SinmdmCrowd,
    model: *const SinmdmModel,
    id: u64,
    poses: *const SinmdmPoses,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        let model = unsafe { handle_ref(model, "model") }?;
        model.check_same(crowd.model, "crowd")?;
        let poses = unsafe { poses_in(&model.model, poses, "poses") }?;
        crowd.character(id)?.supply(&poses)?;
        Ok(())
    })
}

/// Prepares frames ahead on `model` (the crowd's), spending at most `max_steps` denoising steps
/// (one step of one character each): in rounds, each character with fewer than `ahead` frames
/// (at most `SINMDM_MAX_SAMPLE_FRAMES`) ready takes one step, those with the fewest ready first,
/// all of a round through the network together. A game calls it each frame with the steps it
/// can afford, then reads each character with `sinmdm_crowd_next`, which then never waits.
/// `steps` (if not NULL) gets the steps taken, `waiting` (if not NULL) the characters still
/// short of `ahead` frames.
///
/// # Safety
/// `crowd` and `model` are live handles; `steps` and `waiting` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_step(
    crowd: *mut SinmdmCrowd,
    model: *mut SinmdmModel,
    max_steps: usize,
    ahead: usize,
    steps: *mut usize,
    waiting: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        let model = unsafe { handle_mut(model, "model") }?;
        model.check_same(crowd.model, "crowd")?;
        if ahead > SINMDM_MAX_SAMPLE_FRAMES {
            return Err(Failure::invalid(format!(
                "ahead is {ahead}; at most {SINMDM_MAX_SAMPLE_FRAMES} frames are prepared"
            )));
        }
        let progress = crowd
            .crowd
            .prepare(&mut model.model, max_steps, ahead)
            .map_err(made_by_the_run)?;
        for (slot, value) in [(steps, progress.steps), (waiting, progress.waiting)] {
            if !slot.is_null() {
                unsafe { *slot = value };
            }
        }
        Ok(())
    })
}

/// Character `id`'s next `frames` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) into `buffers`,
/// the same bits as its stream alone; frames not yet prepared by `sinmdm_crowd_step` are made
/// for this character alone on `model` (the crowd's). `buffers` is checked as for
/// `sinmdm_stream_next`.
///
/// # Safety
/// `crowd` and `model` are live handles; `buffers` as its documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_next(
    crowd: *mut SinmdmCrowd,
    model: *mut SinmdmModel,
    id: u64,
    frames: usize,
    buffers: *const SinmdmPoseBuffers,
) -> SinmdmStatus {
    guard(|| {
        let crowd = unsafe { handle_mut(crowd, "crowd") }?;
        let model = unsafe { handle_mut(model, "model") }?;
        model.check_same(crowd.model, "crowd")?;
        if frames > SINMDM_MAX_SAMPLE_FRAMES {
            return Err(Failure::invalid(format!(
                "frames is {frames}; one chunk holds at most {SINMDM_MAX_SAMPLE_FRAMES}"
            )));
        }
        let joints = model.model.skeleton().len();
        let stream = crowd.character(id)?;
        // Check the buffers before making anything, so a bad one loses no motion.
        unsafe { pose_slices(buffers, frames, joints) }?;
        let chunk = stream
            .next(&mut model.model, frames)
            .map_err(made_by_the_run)?;
        unsafe { poses_out(&chunk.poses(), joints, buffers) }
    })
}

/// Frees a crowd and its characters (NULL is fine).
///
/// # Safety
/// `crowd` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_crowd_free(crowd: *mut SinmdmCrowd) {
    unsafe { crate::text::free_handle(crowd) }
}
