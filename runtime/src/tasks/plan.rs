//! Checking a request against a model and building its sampling run: length, masks, low-pass
//! targets and schedule; then running it on a denoiser.

use std::ops::ControlFlow;

use ndarray::Array2;

use super::Generated;
use super::mask::{Span, covered, soft_mask};
use super::run::Run;
use super::{Placement, Request, Task, TaskError, place_keyframes};
use crate::diffusion::sampler::{Denoiser, Guidance, Harmonization, Inpainting, Sampler};
use crate::diffusion::{Method, SamplerError, Schedule};
use crate::limits::{MAX_RAMP_FRAMES, MAX_RUN_VALUES, MAX_SAMPLE_FRAMES, MAX_SAMPLES};
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

fn check_spans(spans: &[Span], frames: usize) -> Result<Vec<Span>, TaskError> {
    let mut sorted = spans.to_vec();
    sorted.sort();
    for span in &sorted {
        if span.is_empty() {
            return Err(TaskError::EmptySpan(*span));
        }
        if span.end > frames {
            return Err(TaskError::SpanOutOfRange {
                span: *span,
                frames,
            });
        }
    }
    for pair in sorted.windows(2) {
        if pair[1].start < pair[0].end {
            return Err(TaskError::SpansOverlap(pair[0], pair[1]));
        }
    }
    Ok(sorted)
}

fn check_ramp(ramp: usize) -> Result<usize, TaskError> {
    if ramp > MAX_RAMP_FRAMES {
        return Err(TaskError::Ramp(ramp));
    }
    Ok(ramp)
}

fn check_length(frames: usize) -> Result<(), TaskError> {
    if frames == 0 {
        return Err(TaskError::Length {
            frames,
            reason: "ask for at least one frame".into(),
        });
    }
    if frames > MAX_SAMPLE_FRAMES {
        return Err(TaskError::Length {
            frames,
            reason: format!("the limit is {MAX_SAMPLE_FRAMES} frames per sample"),
        });
    }
    Ok(())
}

fn normalized(metadata: &ModelMetadata, raw: &Array2<f32>) -> Result<Array2<f32>, TaskError> {
    if raw.nrows() != metadata.network.features {
        return Err(TaskError::ReferenceWidth {
            expected: metadata.network.features,
            got: raw.nrows(),
        });
    }
    Ok(metadata.normalizer.normalize(raw.view()))
}

/// Broadcasts a per-frame weight over all rows, or over `rows` only.
fn frame_mask(features: usize, weights: &[f32], rows: Option<&[usize]>) -> Array2<f32> {
    let mut m = Array2::<f32>::zeros((features, weights.len()));
    let mut fill = |r: usize| {
        for (i, &w) in weights.iter().enumerate() {
            m[[r, i]] = w;
        }
    };
    match rows {
        Some(rows) => rows.iter().for_each(|&r| fill(r)),
        None => (0..features).for_each(fill),
    }
    m
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
    let mut placement = None;
    let mut warnings = Vec::new();
    let (frames, guidance) = match &request.task {
        Task::Generate { frames } => (*frames, Guidance::default()),
        Task::Steer {
            frames,
            commands,
            ramp,
        } => {
            check_length(*frames)?;
            let ramp = check_ramp(*ramp)?;
            let mut per_frame = commands.clone();
            per_frame.resize(*frames, crate::steer::SteerFrame::Free);
            let start = crate::motion::RootStart::of(&metadata.layout).ok_or_else(|| {
                TaskError::Steer(
                    "the model has no heading-relative root (train it with --root-layout heading)"
                        .into(),
                )
            })?;
            let planned = crate::steer::plan_steering(metadata, &per_frame, 0, start, ramp)
                .map_err(TaskError::Steer)?;
            warnings = planned.warnings;
            (
                *frames,
                Guidance {
                    steering: planned.steering,
                    ..Guidance::default()
                },
            )
        }
        Task::Dance {
            reference,
            beats,
            root,
        } => {
            let y = normalized(metadata, reference)?;
            check_length(beats.frames)?;
            check_ramp(beats.ramp)?;
            let placed = place_keyframes(y.ncols(), beats, request.seed)?;
            let n = beats.frames;
            let h = placed.hold;
            let mut target = Array2::<f32>::zeros((f, n));
            let mut keep = vec![false; n];
            for key in &placed.keys {
                // Frames of the window that fall inside the output.
                let first = key.target.saturating_sub(h);
                let last = (key.target + h).min(n - 1);
                let from = key.reference + first - key.target;
                let to = key.reference + last - key.target;
                target
                    .slice_mut(ndarray::s![.., first..=last])
                    .assign(&y.slice(ndarray::s![.., from..=to]));
                keep[first..=last].fill(true);
            }
            let weights = soft_mask(&keep, placed.ramp);
            let root_rows = metadata.layout.root.as_ref().map_or(0, |r| r.width());
            let rows: Vec<usize> = if *root {
                (0..f).collect()
            } else {
                (root_rows..f).collect()
            };
            let mask = frame_mask(f, &weights, Some(&rows));
            placement = Some(placed);
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting {
                        reference: target,
                        mask,
                    }),
                    harmonization: None,
                    steering: None,
                },
            )
        }
        Task::Inbetween {
            reference,
            keep,
            ramp,
        } => {
            let y = normalized(metadata, reference)?;
            let n = y.ncols();
            if keep.is_empty() {
                return Err(TaskError::NothingToDo(
                    "in-betweening needs at least one span of the reference to keep".into(),
                ));
            }
            let ramp = check_ramp(*ramp)?;
            let keep = check_spans(keep, n)?;
            let weights = soft_mask(&covered(n, &keep), ramp);
            let mask = frame_mask(f, &weights, None);
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting { reference: y, mask }),
                    harmonization: None,
                    steering: None,
                },
            )
        }
        Task::Expand {
            reference,
            prefix,
            suffix,
            ramp,
        } => {
            let y = normalized(metadata, reference)?;
            if *prefix == 0 && *suffix == 0 {
                return Err(TaskError::NothingToDo(
                    "expansion needs a prefix or a suffix of at least one frame".into(),
                ));
            }
            // Checked: a prefix or suffix near usize::MAX must be refused, not wrap around.
            let n = prefix
                .checked_add(y.ncols())
                .and_then(|n| n.checked_add(*suffix))
                .unwrap_or(usize::MAX);
            check_length(n)?;
            let ramp = check_ramp(*ramp)?;
            let mut padded = Array2::<f32>::zeros((f, n));
            padded
                .slice_mut(ndarray::s![.., *prefix..prefix + y.ncols()])
                .assign(&y);
            let keep = covered(n, &[Span::new(*prefix, prefix + y.ncols())]);
            let mask = frame_mask(f, &soft_mask(&keep, ramp), None);
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting {
                        reference: padded,
                        mask,
                    }),
                    harmonization: None,
                    steering: None,
                },
            )
        }
        Task::Compose {
            reference,
            joints,
            root,
            spans,
            ramp,
        } => {
            let y = normalized(metadata, reference)?;
            let n = y.ncols();
            let ramp = check_ramp(*ramp)?;
            let layout = &metadata.layout;
            if let Some(&index) = joints.iter().find(|&&j| j >= layout.skeleton.len()) {
                return Err(TaskError::JointIndex {
                    index,
                    joints: layout.skeleton.len(),
                });
            }
            let mut rows: Vec<usize> = joints
                .iter()
                .flat_map(|&j| layout.joint_columns(j))
                .collect();
            if *root && let Some(r) = &layout.root {
                rows.extend(0..r.width());
            }
            rows.sort_unstable();
            rows.dedup();
            if rows.is_empty() {
                return Err(TaskError::NothingToDo(
                    "composition needs joints or the root to take from the reference".into(),
                ));
            }
            let weights = if spans.is_empty() {
                vec![1.0; n]
            } else {
                let spans = check_spans(spans, n)?;
                soft_mask(&covered(n, &spans), ramp)
            };
            let mask = frame_mask(f, &weights, Some(&rows));
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting { reference: y, mask }),
                    harmonization: None,
                    steering: None,
                },
            )
        }
        Task::Harmonize {
            content,
            factor,
            free_share,
        } => {
            let y = normalized(metadata, content)?;
            if *factor < 1 || *factor > y.ncols().max(1) {
                return Err(TaskError::Harmonization(format!(
                    "the down-sampling factor must be between 1 and the content's {} frames, got {factor}",
                    y.ncols()
                )));
            }
            if !(0.0..=1.0).contains(free_share) {
                return Err(TaskError::Harmonization(format!(
                    "the free share of final steps must be between 0 and 1, got {free_share}"
                )));
            }
            (
                y.ncols(),
                Guidance {
                    inpainting: None,
                    steering: None,
                    harmonization: Some(Harmonization {
                        content: y,
                        factor: *factor,
                        free_share: *free_share,
                    }),
                },
            )
        }
    };
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
