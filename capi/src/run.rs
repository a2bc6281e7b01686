//! Owned, stepped runs: a task begun with `sinmdm_*_begin`, advanced a few denoising steps at a
//! time with `sinmdm_run_step` (a game's frame budget), finished (early: a preview) with
//! `sinmdm_run_finish`, cancelled by `sinmdm_run_free`. The blocking tasks are a run stepped to
//! the end with the model's progress callback.

use std::ops::ControlFlow;

use sinmdm::Run;

use crate::model::SinmdmModel;
use crate::result::SinmdmResult;
use crate::status::{Failure, SinmdmStatus, guard, guard_out};
use crate::text::{give, handle_mut};

/// A task being run (opaque): it owns its plan, schedule, guidance, noise and sample, not the
/// model; each step is given the model it was begun on.
pub struct SinmdmRun {
    /// `None` once finished.
    run: Option<Run>,
    model: u64,
}

impl SinmdmRun {
    fn live(&mut self) -> Result<&mut Run, Failure> {
        self.run
            .as_mut()
            .ok_or_else(|| Failure::invalid("the run was finished; free it with sinmdm_run_free"))
    }
}

/// Begins a run of the request `make` builds (checked against the model now) into `out`.
///
/// # Safety
/// `model` is a live handle; `out` writable.
pub(crate) unsafe fn begin(
    model: *mut SinmdmModel,
    out: *mut *mut SinmdmRun,
    make: impl FnOnce(&SinmdmModel) -> Result<sinmdm::Request, Failure>,
) -> SinmdmStatus {
    unsafe {
        guard_out(out, |out| {
            let model = handle_mut(model, "model")?;
            let request = make(model)?;
            let run = sinmdm::plan(model.model.metadata(), &request)?.start()?;
            give(
                out,
                SinmdmRun {
                    run: Some(run),
                    model: model.id,
                },
            );
            Ok(())
        })
    }
}

/// Runs a task to the end in one call: `begin_task` begins it; each step reports to the
/// model's progress callback, which may cancel after any step, the last included
/// (`SINMDM_CANCELLED`, no result), as the header promises a host.
///
/// # Safety
/// `model` is a live handle; `out` writable; `begin_task` is a `sinmdm_*_begin` call.
pub(crate) unsafe fn blocking(
    model: *mut SinmdmModel,
    out: *mut *mut SinmdmResult,
    begin_task: impl FnOnce(*mut *mut SinmdmRun) -> SinmdmStatus,
) -> SinmdmStatus {
    unsafe {
        guard_out(out, |out| {
            let mut run: *mut SinmdmRun = std::ptr::null_mut();
            let status = begin_task(&mut run);
            if status != SinmdmStatus::Ok {
                return Err(Failure::new(
                    status,
                    std::ffi::CStr::from_ptr(crate::status::sinmdm_last_error())
                        .to_string_lossy()
                        .into_owned(),
                ));
            }
            let owned = crate::text::take_handle(run);
            let model = handle_mut(model, "model")?;
            let progress = model.progress;
            let mut run = owned.run.expect("a run just begun is live");
            let mut stopped = false;
            run.complete(&mut model.model, &mut |done, total| {
                if progress.go_on(done, total) {
                    ControlFlow::Continue(())
                } else {
                    stopped = true;
                    ControlFlow::Break(())
                }
            })?;
            // The engine finishes a run cancelled at its last step; the C ABI gives no result
            // for any cancel, so a host reads one answer one way.
            if stopped {
                let sinmdm::Progress { done, total } = run.progress();
                return Err(Failure::from(sinmdm::TaskError::Cancelled {
                    done,
                    steps: total,
                }));
            }
            give(
                out,
                SinmdmResult {
                    generated: run.finish()?,
                },
            );
            Ok(())
        })
    }
}

/// Takes up to `max_steps` denoising steps of `run` on `model` (the model it was begun on),
/// and writes the steps taken so far and in all to `done` and `total` (each may be NULL). One
/// step costs about a 50th of the whole run at the default step count; 0 steps only reports.
/// `model` is the very handle the run was begun on: another handle, even of the same file,
/// gives `SINMDM_INVALID_ARGUMENT` (a handle and its runs are one for the threading rule). The
/// progress callback is not called here: a stepped run is never cancelled, only freed.
///
/// # Safety
/// `run` and `model` are live handles; `done` and `total` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_run_step(
    run: *mut SinmdmRun,
    model: *mut SinmdmModel,
    max_steps: usize,
    done: *mut usize,
    total: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let run = unsafe { handle_mut(run, "run") }?;
        let model = unsafe { handle_mut(model, "model") }?;
        model.check_same(run.model, "run")?;
        let progress = run.live()?.step(&mut model.model, max_steps)?;
        if !done.is_null() {
            unsafe { *done = progress.done };
        }
        if !total.is_null() {
            unsafe { *total = progress.total };
        }
        Ok(())
    })
}

/// Finishes `run` and writes its batch to `out`: the motion once every step is taken, or,
/// before that, the network's latest prediction of the clean motion (a preview; a run that has
/// taken no step has none and gives `SINMDM_INVALID_ARGUMENT`). The run is spent afterwards:
/// free it with `sinmdm_run_free`. Which failures spend it: the refusals (`SINMDM_NULL_ARGUMENT`
/// for a NULL `run` or `out`; `SINMDM_INVALID_ARGUMENT` for a spent run or one with no step
/// taken) leave it as it was, to be stepped and finished again; only `SINMDM_INTERNAL` (a
/// caught panic while the batch is made) spends it without a result.
///
/// # Safety
/// `run` is a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_run_finish(
    run: *mut SinmdmRun,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        guard_out(out, |out| {
            let run = handle_mut(run, "run")?;
            let live = run.live()?;
            if live.progress().done == 0 {
                return Err(Failure::invalid(format!(
                    "the run has taken none of its {} steps, so there is no motion yet",
                    live.progress().total
                )));
            }
            let generated = run.run.take().expect("checked live").finish()?;
            give(out, SinmdmResult { generated });
            Ok(())
        })
    }
}

/// Frees a run (NULL is fine); freeing one before it is finished cancels it.
///
/// # Safety
/// `run` is NULL or a handle from this library, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_run_free(run: *mut SinmdmRun) {
    unsafe { crate::text::free_handle(run) }
}
