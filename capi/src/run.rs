//! Generation and every task, and the batch they give.

use std::ops::ControlFlow;

use sinmdm::{Feet, Generated, Request, Span, Task, features_from_poses};

use crate::model::SinmdmModel;
use crate::poses::{SinmdmPoseBuffers, SinmdmPoses, poses_in, poses_out};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::text::{give, handle, slice_arg};

/// Respaced sampling steps of the command line (the library's `DEFAULT_STEPS`); what a `steps`
/// of 0 gives in `SinmdmSampling` and `SinmdmStreamOptions`.
pub const SINMDM_DEFAULT_STEPS: u32 = 50;

/// A `steps` value that runs all of the model's diffusion steps T (slow; the reference quality).
pub const SINMDM_ALL_STEPS: u32 = u32::MAX;

/// The library's step count for a C `steps` value: 0 is the default, `SINMDM_ALL_STEPS` all T.
pub(crate) fn steps_arg(steps: u32) -> Option<usize> {
    match steps {
        0 => Some(sinmdm::DEFAULT_STEPS),
        SINMDM_ALL_STEPS => None,
        n => Some(n as usize),
    }
}

/// Feet: contact points held still on the ground (the default).
pub const SINMDM_FEET_PLANTED: u32 = 0;
/// Feet: the network's motion untouched.
pub const SINMDM_FEET_RAW: u32 = 1;

/// Sampling method: ancestral DDPM (the paper's sampler; the default).
pub const SINMDM_METHOD_ANCESTRAL: u32 = 0;
/// Sampling method: DDIM, with `eta` the share of the ancestral noise (0: deterministic).
pub const SINMDM_METHOD_DDIM: u32 = 1;
/// Sampling method: DPM-Solver++(2M), deterministic, good motion in fewer steps.
pub const SINMDM_METHOD_DPM2M: u32 = 2;

/// A `method` and `eta` as the library's setting.
pub(crate) fn method_arg(method: u32, eta: f64) -> Result<sinmdm::Method, Failure> {
    let chosen = match method {
        SINMDM_METHOD_ANCESTRAL => sinmdm::Method::Ancestral,
        SINMDM_METHOD_DDIM => sinmdm::Method::Ddim { eta },
        SINMDM_METHOD_DPM2M => sinmdm::Method::DpmSolver2M,
        other => {
            return Err(Failure::invalid(format!(
                "method must be SINMDM_METHOD_ANCESTRAL (0), SINMDM_METHOD_DDIM (1) or SINMDM_METHOD_DPM2M (2), got {other}"
            )));
        }
    };
    if let Some(problem) = chosen.problem() {
        return Err(Failure::invalid(problem));
    }
    Ok(chosen)
}

/// A `feet` field's value as the library's setting.
pub(crate) fn feet_arg(feet: u32) -> Result<Feet, Failure> {
    match feet {
        SINMDM_FEET_PLANTED => Ok(Feet::Planted),
        SINMDM_FEET_RAW => Ok(Feet::Raw),
        other => Err(Failure::invalid(format!(
            "feet must be SINMDM_FEET_PLANTED (0) or SINMDM_FEET_RAW (1), got {other}"
        ))),
    }
}

/// Sampling settings shared by every task. The same model, settings and arguments give the same
/// poses, here, in Rust and in the Python reference.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSampling {
    /// Seed of the portable noise.
    pub seed: u64,
    /// Samples in the batch (a crowd when more than 1).
    pub count: u32,
    /// Respaced denoising steps; 0 for `SINMDM_DEFAULT_STEPS`, `SINMDM_ALL_STEPS` for all of
    /// the model's T.
    pub steps: u32,
    /// `SINMDM_FEET_PLANTED` or `SINMDM_FEET_RAW`.
    pub feet: u32,
    /// `SINMDM_METHOD_ANCESTRAL` (0, the default), `SINMDM_METHOD_DDIM` or `SINMDM_METHOD_DPM2M`.
    pub method: u32,
    /// DDIM's share of the ancestral noise, 0 to 1 (ignored by the other methods).
    pub eta: f64,
}

/// A span of frames `start..end` (end excluded).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSpan {
    /// First frame.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
}

/// A generated batch (opaque).
pub struct SinmdmResult {
    generated: Generated,
}

/// Runs `task` with `sampling` and writes the batch to `out`.
///
/// # Safety
/// `model` is a live handle, `sampling` readable, `out` writable.
unsafe fn run_task(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    out: *mut *mut SinmdmResult,
    task: impl FnOnce(&SinmdmModel) -> Result<Task, Failure>,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { handle(model, "model") }?;
        let sampling = *unsafe { handle(sampling.cast_mut(), "sampling") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let task = task(model)?;
        let request = Request {
            task,
            count: sampling.count as usize,
            seed: sampling.seed,
            steps: steps_arg(sampling.steps),
            feet: feet_arg(sampling.feet)?,
            method: method_arg(sampling.method, sampling.eta)?,
        };
        let generated = sinmdm::run(&mut model.model, &request, &mut |_, _| {
            ControlFlow::Continue(())
        })?;
        unsafe { give(out, SinmdmResult { generated }) };
        Ok(())
    })
}

/// Reference poses as raw features in the model's layout.
///
/// # Safety
/// As [`poses_in`].
unsafe fn reference_features(
    model: &SinmdmModel,
    poses: *const SinmdmPoses,
    argument: &str,
) -> Result<sinmdm::motion::FeatureMatrix, Failure> {
    let poses = unsafe { poses_in(&model.model, poses, argument) }?;
    Ok(features_from_poses(&model.model.metadata().layout, &poses)?)
}

/// Spans from a caller array.
///
/// # Safety
/// `spans` is readable for `count` spans (or NULL with 0).
unsafe fn spans(spans: *const SinmdmSpan, count: usize) -> Result<Vec<Span>, Failure> {
    Ok(unsafe { slice_arg(spans, count, "spans") }?
        .iter()
        .map(|s| Span::new(s.start, s.end))
        .collect())
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
    unsafe { run_task(model, sampling, out, |_| Ok(Task::Generate { frames })) }
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
        run_task(model, sampling, out, |m| {
            Ok(Task::Inbetween {
                reference: reference_features(m, reference, "reference")?,
                keep: spans(keep, span_count)?,
                ramp,
            })
        })
    }
}

/// Expansion: the `reference` poses in the middle, `prefix` new frames before and `suffix`
/// after.
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
        run_task(model, sampling, out, |m| {
            Ok(Task::Expand {
                reference: reference_features(m, reference, "reference")?,
                prefix,
                suffix,
                ramp,
            })
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
        run_task(model, sampling, out, |m| {
            Ok(Task::Compose {
                reference: reference_features(m, reference, "reference")?,
                joints: slice_arg(joints, joint_count, "joints")?.to_vec(),
                root: root != 0,
                spans: spans(spans_in, span_count)?,
                ramp,
            })
        })
    }
}

/// Harmonization (style transfer): the `content` poses' low frequencies (down-sampled by
/// `factor`) in the model's style, the last `free_share` of steps left free.
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
        run_task(model, sampling, out, |m| {
            Ok(Task::Harmonize {
                content: reference_features(m, content, "content")?,
                factor,
                free_share,
            })
        })
    }
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
        let result = unsafe { handle(result.cast_mut(), "result") }?;
        *unsafe { handle(count, "count") }? = result.generated.count();
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
        let result = unsafe { handle(result.cast_mut(), "result") }?;
        *unsafe { handle(frames, "frames") }? = result.generated.frames();
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
        let result = unsafe { handle(result.cast_mut(), "result") }?;
        let joints = result.generated.layout().skeleton.len();
        let poses = result
            .generated
            .poses(sample)
            .map_err(|e| Failure::new(SinmdmStatus::SinmdmInvalidArgument, e.to_string()))?;
        unsafe { poses_out(&poses, joints, buffers) }
    })
}

/// Frees a batch (NULL is fine).
///
/// # Safety
/// `result` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_result_free(result: *mut SinmdmResult) {
    if !result.is_null() {
        drop(unsafe { Box::from_raw(result) });
    }
}

#[cfg(test)]
mod default_steps_tests {
    use super::*;

    #[test]
    fn the_c_default_is_the_library_default() {
        assert_eq!(SINMDM_DEFAULT_STEPS as usize, sinmdm::DEFAULT_STEPS);
        assert_eq!(steps_arg(0), Some(sinmdm::DEFAULT_STEPS));
        assert_eq!(steps_arg(SINMDM_DEFAULT_STEPS), Some(sinmdm::DEFAULT_STEPS));
        assert_eq!(steps_arg(SINMDM_ALL_STEPS), None);
        assert_eq!(steps_arg(7), Some(7));
    }
}
