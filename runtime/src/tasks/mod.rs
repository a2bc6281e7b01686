//! The applications of SPEC section 5, each a [`Task`] run by [`run`]: plain generation (one
//! sample or a crowd), in-betweening, expansion, joint composition and harmonization.
//!
//! A task is checked against the model first ([`plan`]), so bad spans, joints or lengths fail
//! before any network call; the result is a [`Generated`] batch in the model's feature layout.

pub mod mask;

use ndarray::{Array2, Array3, Axis};
use thiserror::Error;

use crate::diffusion::sampler::{Guidance, Harmonization, Inpainting, sample};
use crate::diffusion::{Schedule, ScheduleError};
use crate::model::{Model, ModelError};
use crate::model_file::ModelMetadata;
use crate::motion::{FeatureLayout, LocalMotion, MotionError, Pose, decode, poses};
pub use mask::{Span, covered, soft_mask};

/// The longest sample a task makes, in frames (55 minutes at 30 fps).
pub const MAX_FRAMES: usize = 100_000;
/// The largest crowd one run makes.
pub const MAX_COUNT: usize = 1024;
/// The largest batch one run holds, in feature values (`count x F x frames`; 1 GiB of f32).
pub const MAX_VALUES: usize = 1 << 28;
/// Default soft border of in-betweening and composition spans, in frames.
pub const INBETWEEN_RAMP: usize = 10;
/// Default soft border of expansion, in frames.
pub const EXPAND_RAMP: usize = 6;
/// Default share of final steps that harmonization leaves free.
pub const HARMONIZE_FREE_SHARE: f64 = 0.02;
/// Default down-sampling factor of harmonization's low-pass.
pub const HARMONIZE_FACTOR: usize = 2;

/// Why a task could not run.
#[derive(Debug, Error)]
pub enum TaskError {
    /// The model failed to run.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Features that could not be turned into motion.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// A bad number of sampling steps.
    #[error(transparent)]
    Steps(#[from] ScheduleError),
    /// A sample length of zero or beyond the limit.
    #[error("a sample of {frames} frames is not possible: {reason}")]
    Length {
        /// The frames asked for.
        frames: usize,
        /// Why not.
        reason: String,
    },
    /// A crowd of zero or beyond the limit.
    #[error("--count must be between 1 and {MAX_COUNT}, got {0}")]
    Count(usize),
    /// A batch too large to hold.
    #[error(
        "{count} samples of {frames} frames x {features} features need {gib:.1} GiB; ask for fewer or shorter samples"
    )]
    TooLarge {
        /// Samples.
        count: usize,
        /// Frames each.
        frames: usize,
        /// Feature rows.
        features: usize,
        /// The memory the batch would take.
        gib: f64,
    },
    /// A span with no frames.
    #[error("span {0} is empty (its end must come after its start)")]
    EmptySpan(Span),
    /// A span beyond the reference.
    #[error("span {span} reaches past the reference's {frames} frames (frames are 0..{frames})")]
    SpanOutOfRange {
        /// The span.
        span: Span,
        /// Frames in the reference.
        frames: usize,
    },
    /// Two spans that share frames.
    #[error("spans {0} and {1} overlap")]
    SpansOverlap(Span, Span),
    /// A task that needs spans got none.
    #[error("{0}")]
    NothingToDo(String),
    /// A joint name not in the model's skeleton.
    #[error("joint '{name}' is not in the model's skeleton (joints: {available})")]
    UnknownJoint {
        /// The name given.
        name: String,
        /// The skeleton's joints.
        available: String,
    },
    /// A reference of the wrong width.
    #[error("the reference has {got} feature rows, the model {expected}")]
    ReferenceWidth {
        /// F of the model.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// A harmonization factor or free share out of range.
    #[error("{0}")]
    Harmonization(String),
}

/// What to make.
#[derive(Debug, Clone, PartialEq)]
pub enum Task {
    /// New motion of `frames` frames.
    Generate {
        /// Frames per sample.
        frames: usize,
    },
    /// Keep `keep` spans of the reference, generate the gaps; soft borders of `ramp` frames.
    Inbetween {
        /// Raw (unnormalised) reference features `[F, N]` in the model's layout.
        reference: Array2<f32>,
        /// Frame spans to keep.
        keep: Vec<Span>,
        /// Soft border on the kept side, in frames.
        ramp: usize,
    },
    /// The reference in the middle, `prefix` new frames before and `suffix` after.
    Expand {
        /// Raw reference features `[F, N]`.
        reference: Array2<f32>,
        /// New frames before the reference.
        prefix: usize,
        /// New frames after it.
        suffix: usize,
        /// Soft border on the reference's side, in frames.
        ramp: usize,
    },
    /// Take the chosen joints (and/or the root motion) from the reference on `spans` (all frames
    /// when empty); generate the rest of the body.
    Compose {
        /// Raw reference features `[F, N]`.
        reference: Array2<f32>,
        /// Joints whose columns come from the reference (indices into the model's skeleton).
        joints: Vec<usize>,
        /// Whether the root's travel and height come from the reference.
        root: bool,
        /// Frame spans where they do; empty means every frame.
        spans: Vec<Span>,
        /// Soft border at span ends, in frames.
        ramp: usize,
    },
    /// Style transfer: the content's low frequencies in the model's style.
    Harmonize {
        /// Raw content features `[F, N]`.
        content: Array2<f32>,
        /// Down-sampling factor of the low-pass.
        factor: usize,
        /// Share of final steps left free.
        free_share: f64,
    },
}

/// A task with its sampling settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// What to make.
    pub task: Task,
    /// Samples in the batch (a crowd when more than 1).
    pub count: usize,
    /// Seed of the portable noise.
    pub seed: u64,
    /// Sampling steps S (respaced); `None` runs all T steps.
    pub steps: Option<usize>,
}

/// A sampling run ready to go: length, guidance and schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Frames per sample.
    pub frames: usize,
    /// Masks and low-pass targets, normalised.
    pub guidance: Guidance,
    /// The (respaced) schedule.
    pub schedule: Schedule,
}

/// Joint indices for names, in the model's skeleton.
pub fn joints_by_name(layout: &FeatureLayout, names: &[String]) -> Result<Vec<usize>, TaskError> {
    names
        .iter()
        .map(|name| {
            layout
                .skeleton
                .find(name)
                .ok_or_else(|| TaskError::UnknownJoint {
                    name: name.clone(),
                    available: layout
                        .skeleton
                        .joints
                        .iter()
                        .map(|j| j.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                })
        })
        .collect()
}

/// `joint` and every joint below it.
pub fn subtree(layout: &FeatureLayout, joint: usize) -> Vec<usize> {
    let joints = &layout.skeleton.joints;
    let mut inside = vec![false; joints.len()];
    inside[joint] = true;
    // Parents precede children, so one pass in order marks every descendant.
    for j in joint + 1..joints.len() {
        if let Some(p) = joints[j].parent {
            inside[j] = inside[p];
        }
    }
    (0..joints.len()).filter(|&j| inside[j]).collect()
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

fn check_length(frames: usize) -> Result<(), TaskError> {
    if frames == 0 {
        return Err(TaskError::Length {
            frames,
            reason: "ask for at least one frame".into(),
        });
    }
    if frames > MAX_FRAMES {
        return Err(TaskError::Length {
            frames,
            reason: format!("the limit is {MAX_FRAMES} frames per sample"),
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

/// Checks a request against a model and builds its sampling plan.
pub fn plan(metadata: &ModelMetadata, request: &Request) -> Result<Plan, TaskError> {
    let f = metadata.network.features;
    if request.count == 0 || request.count > MAX_COUNT {
        return Err(TaskError::Count(request.count));
    }
    let schedule = match request.steps {
        Some(s) => Schedule::respaced(metadata.diffusion.steps, s)?,
        None => Schedule::cosine(metadata.diffusion.steps)?,
    };
    let (frames, guidance) = match &request.task {
        Task::Generate { frames } => (*frames, Guidance::default()),
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
            let keep = check_spans(keep, n)?;
            let weights = soft_mask(&covered(n, &keep), *ramp);
            let mask = frame_mask(f, &weights, None);
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting { reference: y, mask }),
                    harmonization: None,
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
            if prefix + suffix == 0 {
                return Err(TaskError::NothingToDo(
                    "expansion needs a prefix or a suffix of at least one frame".into(),
                ));
            }
            let n = prefix + y.ncols() + suffix;
            check_length(n)?;
            let mut padded = Array2::<f32>::zeros((f, n));
            padded
                .slice_mut(ndarray::s![.., *prefix..prefix + y.ncols()])
                .assign(&y);
            let keep = covered(n, &[Span::new(*prefix, prefix + y.ncols())]);
            let mask = frame_mask(f, &soft_mask(&keep, *ramp), None);
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting {
                        reference: padded,
                        mask,
                    }),
                    harmonization: None,
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
            let layout = &metadata.layout;
            let mut rows: Vec<usize> = joints
                .iter()
                .flat_map(|&j| layout.joint_columns(j))
                .collect();
            if *root && let Some(r) = &layout.root {
                rows.extend(0..r.axes.len());
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
                soft_mask(&covered(n, &spans), *ramp)
            };
            let mask = frame_mask(f, &weights, Some(&rows));
            (
                n,
                Guidance {
                    inpainting: Some(Inpainting { reference: y, mask }),
                    harmonization: None,
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
    let values = request.count.saturating_mul(f).saturating_mul(frames);
    if values > MAX_VALUES {
        return Err(TaskError::TooLarge {
            count: request.count,
            frames,
            features: f,
            gib: values as f64 * 4.0 / (1u64 << 30) as f64,
        });
    }
    Ok(Plan {
        frames,
        guidance,
        schedule,
    })
}

/// Runs a request on a model; `progress` is called after each step with (done, total).
pub fn run(
    model: &mut Model,
    request: &Request,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Generated, TaskError> {
    let plan = plan(model.metadata(), request)?;
    run_plan(model, &plan, request.count, request.seed, progress)
}

/// Samples `count` motions of a plan already made by [`plan`] for this model.
pub fn run_plan(
    model: &mut Model,
    plan: &Plan,
    count: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Generated, TaskError> {
    let normalized = sample(
        model,
        &plan.schedule,
        count,
        plan.frames,
        seed,
        &plan.guidance,
        progress,
    )?;
    Ok(Generated::from_normalized(
        model.metadata().clone(),
        normalized,
    ))
}

/// A batch of generated samples in the model's layout.
#[derive(Debug, Clone)]
pub struct Generated {
    metadata: ModelMetadata,
    /// Normalised features `[B, F, N]`, as the network sees them.
    pub normalized: Array3<f32>,
    /// Features `[B, F, N]` in file units (denormalised).
    pub features: Array3<f32>,
}

impl Generated {
    /// Wraps normalised sampler output.
    pub fn from_normalized(metadata: ModelMetadata, normalized: Array3<f32>) -> Generated {
        let mut features = normalized.clone();
        for mut sample in features.outer_iter_mut() {
            let raw = metadata.normalizer.denormalize(sample.view());
            sample.assign(&raw);
        }
        Generated {
            metadata,
            normalized,
            features,
        }
    }

    /// Samples in the batch.
    pub fn count(&self) -> usize {
        self.features.len_of(Axis(0))
    }

    /// Frames per sample.
    pub fn frames(&self) -> usize {
        self.features.len_of(Axis(2))
    }

    /// The feature layout (skeleton, frame rate, columns).
    pub fn layout(&self) -> &FeatureLayout {
        &self.metadata.layout
    }

    /// Sample `index` as local joint transforms.
    pub fn motion(&self, index: usize) -> Result<LocalMotion, MotionError> {
        decode(
            &self.metadata.layout,
            self.features.index_axis(Axis(0), index),
        )
    }

    /// Sample `index` as per-frame root positions and joint quaternions, for engines.
    pub fn poses(&self, index: usize) -> Result<Vec<Pose>, MotionError> {
        Ok(poses(&self.motion(index)?))
    }
}
