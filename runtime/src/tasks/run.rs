//! An owned, stepped run of a plan: a game advances it a few denoising steps a frame, shows its
//! progress, finishes it early or drops it (cancel), and gets the same bits as the one-call run.

use std::ops::ControlFlow;

use super::{Generated, Plan, TaskError};
use crate::diffusion::sampler::{Denoiser, Sampler};

/// How far a run (or a stream's block in the making) has come.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Denoising steps taken.
    pub done: usize,
    /// Denoising steps in the whole run.
    pub total: usize,
}

impl Progress {
    /// Whether every step has been taken.
    pub fn is_finished(&self) -> bool {
        self.done >= self.total
    }
}

/// A plan being run, owning everything it needs (`Send + 'static`): its plan, schedule,
/// guidance, noise and sample. It does not hold the model: each call to [`Run::step`] is given
/// the denoiser, so one model can serve many runs and streams in turn.
///
/// Stepping 1, 3 or all steps at a time gives the same bits as [`Plan::run`] (it is the same
/// loop). Dropping a run cancels it; [`Run::finish`] before the last step gives the network's
/// latest prediction of the clean motion (a preview).
#[derive(Debug)]
pub struct Run {
    plan: Plan,
    sampler: Sampler,
}

impl Run {
    /// Starts a run of `plan`: draws its initial noise (no network call yet).
    pub fn new(plan: Plan) -> Result<Run, TaskError> {
        let sampler = plan.sampler()?;
        Ok(Run { plan, sampler })
    }

    /// The plan being run.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// Steps taken and steps in all.
    pub fn progress(&self) -> Progress {
        Progress {
            done: self.sampler.done(),
            total: self.sampler.steps(),
        }
    }

    /// Takes up to `max_steps` denoising steps (none once finished) and says how far the run
    /// has come. On a denoiser error the run is left as it was before the failed step.
    pub fn step<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        max_steps: usize,
    ) -> Result<Progress, TaskError>
    where
        TaskError: From<D::Error>,
    {
        for _ in 0..max_steps {
            if self.sampler.is_finished() {
                break;
            }
            self.sampler.step(denoiser)?;
        }
        Ok(self.progress())
    }

    /// Steps to the end, calling `progress` after each step with (steps done, steps in all);
    /// a [`ControlFlow::Break`] before the last step stops with [`TaskError::Cancelled`] and
    /// leaves the run where it is (it may be stepped on, finished early or dropped).
    pub fn complete<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        progress: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    ) -> Result<(), TaskError>
    where
        TaskError: From<D::Error>,
    {
        while !self.sampler.is_finished() {
            self.sampler.step(denoiser)?;
            let Progress { done, total } = self.progress();
            if progress(done, total).is_break() && done < total {
                return Err(TaskError::Cancelled { done, steps: total });
            }
        }
        Ok(())
    }

    /// The batch: the finished sample, or, for a run stopped early, the latest prediction of
    /// the clean motion (masks applied; the plan's feet as for a finished run). A run that has
    /// taken no step has nothing to show and gives [`TaskError::NotStarted`].
    pub fn finish(self) -> Result<Generated, TaskError> {
        let Progress { done, total } = self.progress();
        if done >= total {
            return Ok(self.plan.finish(self.sampler));
        }
        let preview = self
            .sampler
            .latest_prediction()
            .map(|x0| x0.to_owned())
            .ok_or(TaskError::NotStarted { steps: total })?;
        Ok(self.plan.batch(preview))
    }
}
