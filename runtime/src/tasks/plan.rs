//! Checking a request against a model and building its sampling run: count, schedule, the
//! task's guidance ([`super::guidance`]) and the run's size; then running it on a denoiser.

use std::ops::ControlFlow;

use super::Generated;
use super::guidance::{Guided, check_length, guided};
use super::run::Run;
use super::{Placement, Request, TaskError};
use crate::diffusion::sampler::{Denoiser, Guidance, Sampler};
use crate::diffusion::{Method, SamplerError, Schedule};
use crate::limits::{MAX_RUN_VALUES, MAX_SAMPLES};
use crate::model::Model;
use crate::model_file::ModelMetadata;
use crate::motion::feet::{Feet, Kept};

/// A request checked against a model: its length, guidance, schedule, sample count and seed,
/// ready to run. Made only by [`plan`], so what runs is what was checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    metadata: ModelMetadata,
    count: usize,
    seed: u64,
    frames: usize,
    guidance: Guidance,
    schedule: Schedule,
    feet: Feet,
    method: Method,
    placement: Option<Placement>,
    warnings: Vec<String>,
}

impl Plan {
    /// What the plan changed of the request, one line each (steering commands clamped to the
    /// clip's range); empty when it runs as asked.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Where a dance's keyframes went (level, tempo ratio, hold, keyframes); `None` for other
    /// tasks.
    pub fn placement(&self) -> Option<&Placement> {
        self.placement.as_ref()
    }

    /// Samples in the batch.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Seed of the portable noise.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Frames per sample.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Denoising steps the run takes.
    pub fn steps(&self) -> usize {
        self.schedule.len()
    }

    /// Masks and low-pass targets, normalised.
    pub fn guidance(&self) -> &Guidance {
        &self.guidance
    }

    /// The (respaced) schedule.
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// Per frame and joint, whether the task keeps that joint of the reference unchanged (every
    /// column of the joint fully masked); `None` for tasks without a reference mask. Joints
    /// without feature columns (end sites) are never kept.
    pub fn kept_joints(&self) -> Option<Vec<Vec<bool>>> {
        let inpaint = self.guidance.inpainting.as_ref()?;
        let layout = &self.metadata.layout;
        Some(
            (0..self.frames)
                .map(|frame| {
                    (0..layout.skeleton.len())
                        .map(|joint| {
                            let columns = layout.joint_columns(joint);
                            !columns.is_empty()
                                && columns.iter().all(|&c| inpaint.mask[[c, frame]] >= 1.0)
                        })
                        .collect()
                })
                .collect(),
        )
    }

    /// Per frame, whether the task sets the root's position: from the reference (every root
    /// position column fully masked), or by a steering command of its travel
    /// ([`crate::steer::Steering::travel_commanded`]); `None` for tasks with neither.
    pub fn kept_root(&self) -> Option<Vec<bool>> {
        let masked = self.guidance.inpainting.as_ref().map(|inpaint| {
            let axes = self.metadata.layout.root.as_ref().map_or(0, |r| r.width());
            (0..self.frames)
                .map(|frame| axes > 0 && (0..axes).all(|c| inpaint.mask[[c, frame]] >= 1.0))
                .collect::<Vec<bool>>()
        });
        let steered = self
            .guidance
            .steering
            .as_ref()
            .map(|s| s.travel_commanded());
        if masked.is_none() && steered.is_none() {
            return None;
        }
        let set = |by: &Option<Vec<bool>>, frame: usize| {
            by.as_ref().is_some_and(|v| v.get(frame) == Some(&true))
        };
        Some(
            (0..self.frames)
                .map(|frame| set(&masked, frame) || set(&steered, frame))
                .collect(),
        )
    }

    /// What the batch's motion and poses do to the feet.
    pub fn feet(&self) -> Feet {
        self.feet
    }

    /// The update rule of each step.
    pub fn method(&self) -> Method {
        self.method
    }

    /// A sampler for this plan, to step by hand.
    pub fn sampler(&self) -> Result<Sampler, TaskError> {
        Ok(Sampler::new(
            &self.schedule,
            &self.guidance,
            self.count,
            self.metadata.network.features,
            self.frames,
            self.seed,
        )?
        .with_method(self.method)?)
    }

    /// The batch of a sampler made by [`Plan::sampler`] once finished.
    pub fn finish(&self, sampler: Sampler) -> Generated {
        self.batch(sampler.into_sample())
    }

    /// The batch of normalised features `[B, F, N]` made by this plan's sampler.
    pub(crate) fn batch(&self, normalized: ndarray::Array3<f32>) -> Generated {
        let kept = Kept {
            joints: self.kept_joints().unwrap_or_default(),
            root: self.kept_root().unwrap_or_default(),
        };
        Generated::from_normalized(self.metadata.clone(), normalized).with_feet(self.feet, kept)
    }

    /// Starts an owned, stepped run of this plan (see [`Run`]).
    pub fn start(&self) -> Result<Run, TaskError> {
        Run::new(self.clone())
    }

    /// Runs the plan on a denoiser. `progress` is called after each step with (steps done,
    /// steps in all); returning [`ControlFlow::Break`] stops the run with
    /// [`TaskError::Cancelled`].
    pub fn run<D: Denoiser>(
        &self,
        denoiser: &mut D,
        progress: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    ) -> Result<Generated, TaskError>
    where
        TaskError: From<D::Error>,
    {
        let mut run = self.start()?;
        run.complete(denoiser, progress)?;
        run.finish()
    }
}

/// Checks `request` against `model` and runs it; `progress` as in [`Plan::run`].
pub fn run(
    model: &mut Model,
    request: &Request,
    progress: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
) -> Result<Generated, TaskError> {
    plan(model.metadata(), request)?.run(model, progress)
}

/// The f32 values one frame of one sample needs while a run is made: the larger of the
/// network's working set (the features and about eight layers' worth of channels: hidden state,
/// residual, concatenation, attention) and the decoded motion's transforms per joint, that is
/// `max(F + 8 C, 12 x joints)`. A request of `count x frames x` this over
/// [`MAX_RUN_VALUES`] is refused, so a host can size its requests from it.
pub fn run_values_per_frame(metadata: &ModelMetadata) -> usize {
    metadata
        .network
        .features
        .saturating_add(8usize.saturating_mul(metadata.network.channels))
        .max(12usize.saturating_mul(metadata.layout.skeleton.len()))
}

/// Checks a request against a model and builds its sampling plan.
pub fn plan(metadata: &ModelMetadata, request: &Request) -> Result<Plan, TaskError> {
    let f = metadata.network.features;
    if request.count == 0 || request.count > MAX_SAMPLES {
        return Err(TaskError::Count(request.count));
    }
    if let Some(problem) = request.method.problem() {
        return Err(TaskError::Sampler(SamplerError::Method(problem)));
    }
    let schedule = match request.steps {
        Some(s) => Schedule::respaced(metadata.diffusion.steps, s)?,
        None => Schedule::cosine(metadata.diffusion.steps)?,
    };
    let Guided {
        frames,
        guidance,
        placement,
        warnings,
    } = guided(metadata, &request.task, request.seed)?;
    check_length(frames)?;
    let values = request
        .count
        .saturating_mul(run_values_per_frame(metadata))
        .saturating_mul(frames);
    if values > MAX_RUN_VALUES {
        return Err(TaskError::TooLarge {
            count: request.count,
            frames,
            features: f,
            gib: values as f64 * 4.0 / (1u64 << 30) as f64,
        });
    }
    Ok(Plan {
        metadata: metadata.clone(),
        count: request.count,
        seed: request.seed,
        frames,
        guidance,
        schedule,
        feet: request.feet,
        method: request.method,
        placement,
        warnings,
    })
}
