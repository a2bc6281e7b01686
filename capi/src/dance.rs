//! Dance through the C ABI: the reference's beats (`sinmdm_dance_reference_beats`) and the task
//! (`sinmdm_dance`, `sinmdm_dance_begin`), with beats as plain frame arrays: the host brings the
//! music's beats (from its own tracker, a beat map, or a tempo).

use sinmdm::Task;
use sinmdm::motion::decode;
use sinmdm::tasks::{BeatLevel, DanceBeats, KeyOrder};

use crate::limits::SINMDM_MAX_SAMPLE_FRAMES;
use crate::model::SinmdmModel;
use crate::poses::SinmdmPoses;
use crate::result::SinmdmResult;
use crate::run::{SinmdmRun, begin, blocking};
use crate::sampling::{SinmdmSampling, request};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::tasks::{reference_features, sampling_arg};
use crate::text::{copy_array, handle_ref, slice_arg};

/// Keyframe order: each pass over the reference's beats in an order drawn from the seed (the
/// default).
pub const SINMDM_DANCE_ORDER_SHUFFLED: u32 = 0;
/// Keyframe order: the reference's own, over and over.
pub const SINMDM_DANCE_ORDER_REFERENCE: u32 = 1;

/// Beat level: the one that brings the music's tempo nearest the reference's (the default).
pub const SINMDM_DANCE_LEVEL_AUTO: u32 = 0;
/// Beat level: every music beat carries a keyframe.
pub const SINMDM_DANCE_LEVEL_EVERY: u32 = 1;
/// Beat level: every other music beat, from the first.
pub const SINMDM_DANCE_LEVEL_EVERY_OTHER: u32 = 2;
/// Beat level: every music beat and the frame half-way to the next.
pub const SINMDM_DANCE_LEVEL_HALF: u32 = 3;

/// Default half-width of a keyframe window, in frames (`hold` of 0 takes it too); the
/// library's `DANCE_HOLD`, which a test keeps equal.
pub const SINMDM_DANCE_HOLD: usize = 12;
/// Default soft border of a keyframe window, in frames (the library's `DANCE_RAMP`).
pub const SINMDM_DANCE_RAMP: usize = 13;

/// A dance's beats and placement. Beat frames are at the model's frame rate, increasing.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmDance {
    /// The reference's beats (frames of the reference poses), e.g. from
    /// `sinmdm_dance_reference_beats`.
    pub reference_beats: *const usize,
    /// Values in `reference_beats`.
    pub reference_beat_count: usize,
    /// The music's beats (frames of the output).
    pub music_beats: *const usize,
    /// Values in `music_beats`.
    pub music_beat_count: usize,
    /// Frames of the output.
    pub frames: usize,
    /// Half-width of each keyframe window in frames; 0 takes `SINMDM_DANCE_HOLD`.
    pub hold: usize,
    /// Soft border on the kept side of each window, in frames (at most `hold + 1` is used).
    pub ramp: usize,
    /// `SINMDM_DANCE_ORDER_*`.
    pub order: u32,
    /// `SINMDM_DANCE_LEVEL_*`.
    pub level: u32,
    /// 1: the root's travel and height in each window come from the reference; 0: generated.
    pub keep_root: u32,
}

/// Beat frames from a caller array, at most `SINMDM_MAX_SAMPLE_FRAMES` of them.
///
/// # Safety
/// `beats` is readable for `count` values (or NULL with 0).
unsafe fn beats_arg(
    beats: *const usize,
    count: usize,
    argument: &str,
) -> Result<Vec<usize>, Failure> {
    if count > SINMDM_MAX_SAMPLE_FRAMES {
        return Err(Failure::invalid(format!(
            "{argument}: {count} beats; at most {SINMDM_MAX_SAMPLE_FRAMES} (one per frame of the longest sample)"
        )));
    }
    Ok(unsafe { slice_arg(beats, count, argument) }?.to_vec())
}

/// The library's dance settings from the C struct.
///
/// # Safety
/// The struct's arrays are readable for their counts.
unsafe fn dance_arg(dance: &SinmdmDance) -> Result<DanceBeats, Failure> {
    let order = match dance.order {
        SINMDM_DANCE_ORDER_SHUFFLED => KeyOrder::Shuffled,
        SINMDM_DANCE_ORDER_REFERENCE => KeyOrder::Reference,
        other => {
            return Err(Failure::invalid(format!(
                "dance.order must be SINMDM_DANCE_ORDER_SHUFFLED (0) or SINMDM_DANCE_ORDER_REFERENCE (1), got {other}"
            )));
        }
    };
    let level = match dance.level {
        SINMDM_DANCE_LEVEL_AUTO => BeatLevel::Auto,
        SINMDM_DANCE_LEVEL_EVERY => BeatLevel::Every,
        SINMDM_DANCE_LEVEL_EVERY_OTHER => BeatLevel::EveryOther,
        SINMDM_DANCE_LEVEL_HALF => BeatLevel::Half,
        other => {
            return Err(Failure::invalid(format!(
                "dance.level must be one of SINMDM_DANCE_LEVEL_AUTO (0), _EVERY (1), _EVERY_OTHER (2), _HALF (3), got {other}"
            )));
        }
    };
    if dance.keep_root > 1 {
        return Err(Failure::invalid(format!(
            "dance.keep_root must be 0 or 1, got {}",
            dance.keep_root
        )));
    }
    Ok(DanceBeats {
        reference_beats: unsafe {
            beats_arg(
                dance.reference_beats,
                dance.reference_beat_count,
                "dance.reference_beats",
            )
        }?,
        target_beats: unsafe {
            beats_arg(
                dance.music_beats,
                dance.music_beat_count,
                "dance.music_beats",
            )
        }?,
        frames: dance.frames,
        hold: if dance.hold == 0 {
            SINMDM_DANCE_HOLD
        } else {
            dance.hold
        },
        ramp: dance.ramp,
        order,
        level,
    })
}

/// Writes the beats of the `reference` poses that a dance places (its speed minima on the
/// dance's own beat; frames of the reference) to `beats`, which holds `capacity` values;
/// `needed` (if not NULL) gets their count, also for a NULL `beats` (a size query).
///
/// # Safety
/// `model` is a live handle; `reference` readable; `beats` NULL or writable for `capacity`
/// values; `needed` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_dance_reference_beats(
    model: *const SinmdmModel,
    reference: *const SinmdmPoses,
    beats: *mut usize,
    capacity: usize,
    needed: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let m = unsafe { handle_ref(model, "model") }?;
        let features = unsafe { reference_features(m, reference, "reference") }?;
        let motion = decode(&m.model.metadata().layout, features.view())?;
        let (_, regular) = sinmdm_beats::pulses::motion_beats(&motion)
            .map_err(|e| Failure::invalid(format!("reference: {e}")))?;
        unsafe { copy_array(&regular.frames, beats, capacity, needed, "beats") }
    })
}

/// Begins a dance (see `sinmdm_dance` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_dance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_dance_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    dance: *const SinmdmDance,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |m| {
            let sampling = sampling_arg(sampling)?;
            let dance = *handle_ref(dance, "dance")?;
            let beats = dance_arg(&dance)?;
            let task = Task::Dance {
                reference: reference_features(m, reference, "reference")?,
                beats,
                root: dance.keep_root == 1,
            };
            request(&sampling, task)
        })
    }
}

/// A dance: windows of the `reference` poses around its beats placed on the music's beats,
/// the motion between them generated (the same motion as `sinmdm dance` for the same beats,
/// seed and settings).
///
/// # Safety
/// Pointers as their types' documentation says; the arrays of `dance` readable for their
/// counts.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_dance(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    dance: *const SinmdmDance,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_dance_begin(model, sampling, reference, dance, run)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_defaults_are_the_librarys() {
        assert_eq!(SINMDM_DANCE_HOLD, sinmdm::tasks::DANCE_HOLD);
        assert_eq!(SINMDM_DANCE_RAMP, sinmdm::tasks::DANCE_RAMP);
    }
}
