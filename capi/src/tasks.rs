//! Generation and every task, each in two forms: `sinmdm_TASK` runs it to the end in one call
//! (with the model's progress callback), `sinmdm_TASK_begin` gives an owned run to step.

use sinmdm::{Span, Task, features_from_poses};

use crate::limits::{SINMDM_MAX_JOINT_INDICES, SINMDM_MAX_SPANS};
use crate::model::SinmdmModel;
use crate::poses::{SinmdmPoses, poses_in};
use crate::result::SinmdmResult;
use crate::run::{SinmdmRun, begin, blocking};
use crate::sampling::{SinmdmSampling, SinmdmSpan, request};
use crate::status::{Failure, SinmdmStatus};
use crate::text::{handle_ref, slice_arg};

/// The sampling settings behind a pointer.
///
/// # Safety
/// `sampling` is NULL or readable.
pub(crate) unsafe fn sampling_arg(
    sampling: *const SinmdmSampling,
) -> Result<SinmdmSampling, Failure> {
    Ok(*unsafe { handle_ref(sampling, "sampling") }?)
}

/// Reference poses as raw features in the model's layout.
///
/// # Safety
/// As [`poses_in`].
pub(crate) unsafe fn reference_features(
    model: &SinmdmModel,
    poses: *const SinmdmPoses,
    argument: &str,
) -> Result<sinmdm::motion::FeatureMatrix, Failure> {
    let poses = unsafe { poses_in(&model.model, poses, argument) }?;
    Ok(features_from_poses(&model.model.metadata().layout, &poses)?)
}

/// Spans from a caller array, at most `SINMDM_MAX_SPANS` of them.
///
/// # Safety
/// `spans` is readable for `count` spans (or NULL with 0).
unsafe fn spans(spans: *const SinmdmSpan, count: usize) -> Result<Vec<Span>, Failure> {
    if count > SINMDM_MAX_SPANS {
        return Err(Failure::invalid(format!(
            "span_count is {count}; at most {SINMDM_MAX_SPANS} spans fit in the longest sample"
        )));
    }
    Ok(unsafe { slice_arg(spans, count, "spans") }?
        .iter()
        .map(|s| Span::new(s.start, s.end))
        .collect())
}

/// Begins new motion of `frames` frames (see `sinmdm_run_step`).
///
/// # Safety
/// `model` is a live handle, `sampling` readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_generate_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |_| {
            request(&sampling_arg(sampling)?, Task::Generate { frames })
        })
    }
}

/// New motion of `frames` frames.
///
/// # Safety
/// `model` is a live handle, `sampling` readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_generate(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_generate_begin(model, sampling, frames, run)
        })
    }
}

/// Begins an in-between (see `sinmdm_inbetween` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_inbetween`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_inbetween_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    keep: *const SinmdmSpan,
    span_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |m| {
            let sampling = sampling_arg(sampling)?;
            let keep = spans(keep, span_count)?;
            let task = Task::Inbetween {
                reference: reference_features(m, reference, "reference")?,
                keep,
                ramp,
            };
            request(&sampling, task)
        })
    }
}

/// In-betweening: keeps the `span_count` spans `keep` of the `reference` poses (soft borders
/// of `ramp` frames) and generates the gaps.
///
/// # Safety
/// Pointers as their types' documentation says; `keep` readable for `span_count` spans.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_inbetween(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    keep: *const SinmdmSpan,
    span_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_inbetween_begin(model, sampling, reference, keep, span_count, ramp, run)
        })
    }
}

/// Begins an expansion (see `sinmdm_expand` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_expand`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_expand_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    prefix: usize,
    suffix: usize,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |m| {
            let sampling = sampling_arg(sampling)?;
            let task = Task::Expand {
                reference: reference_features(m, reference, "reference")?,
                prefix,
                suffix,
                ramp,
            };
            request(&sampling, task)
        })
    }
}

/// Expansion: the `reference` poses in the middle, `prefix` new frames before and `suffix`
/// after (all together at most `SINMDM_MAX_SAMPLE_FRAMES`).
///
/// # Safety
/// Pointers as their types' documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_expand(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    prefix: usize,
    suffix: usize,
    ramp: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_expand_begin(model, sampling, reference, prefix, suffix, ramp, run)
        })
    }
}

/// Begins a composition (see `sinmdm_compose` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_compose`.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn sinmdm_compose_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    joints: *const usize,
    joint_count: usize,
    root: i32,
    spans_in: *const SinmdmSpan,
    span_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |m| {
            let sampling = sampling_arg(sampling)?;
            if joint_count > SINMDM_MAX_JOINT_INDICES {
                return Err(Failure::invalid(format!(
                    "joint_count is {joint_count}; at most {SINMDM_MAX_JOINT_INDICES} joint indices are taken"
                )));
            }
            let joints = slice_arg(joints, joint_count, "joints")?.to_vec();
            let spans = spans(spans_in, span_count)?;
            let task = Task::Compose {
                reference: reference_features(m, reference, "reference")?,
                joints,
                root: root != 0,
                spans,
                ramp,
            };
            request(&sampling, task)
        })
    }
}

/// Composition: the `joint_count` `joints` (and the root's travel when `root` is not 0) taken
/// from the `reference` poses on the `span_count` `spans` (every frame when 0), the rest of
/// the body generated.
///
/// # Safety
/// Pointers as their types' documentation says; `joints` readable for `joint_count` values,
/// `spans` for `span_count` spans.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn sinmdm_compose(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    reference: *const SinmdmPoses,
    joints: *const usize,
    joint_count: usize,
    root: i32,
    spans_in: *const SinmdmSpan,
    span_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_compose_begin(
                model,
                sampling,
                reference,
                joints,
                joint_count,
                root,
                spans_in,
                span_count,
                ramp,
                run,
            )
        })
    }
}

/// Begins a harmonization (see `sinmdm_harmonize` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_harmonize`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_harmonize_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    content: *const SinmdmPoses,
    factor: usize,
    free_share: f64,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |m| {
            let sampling = sampling_arg(sampling)?;
            let task = Task::Harmonize {
                content: reference_features(m, content, "content")?,
                factor,
                free_share,
            };
            request(&sampling, task)
        })
    }
}

/// Harmonization (style transfer): the `content` poses' low frequencies (down-sampled by
/// `factor`, 1 to the content's frames) in the model's style, the last `free_share` (0 to 1)
/// of steps left free.
///
/// # Safety
/// Pointers as their types' documentation says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_harmonize(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    content: *const SinmdmPoses,
    factor: usize,
    free_share: f64,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_harmonize_begin(model, sampling, content, factor, free_share, run)
        })
    }
}
