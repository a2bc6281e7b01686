//! What each task asks of the sampler: its window length and guidance (masks, steering,
//! low-pass targets), checked against the model. One function per task; [`guided`] picks it.

use ndarray::Array2;

use super::mask::{Span, covered, soft_mask};
use super::{DanceBeats, Placement, Task, TaskError, place_keyframes};
use crate::diffusion::sampler::{Guidance, Harmonization, Inpainting};
use crate::limits::{MAX_RAMP_FRAMES, MAX_SAMPLE_FRAMES};
use crate::model_file::ModelMetadata;
use crate::steer::SteerFrame;

/// A task's window length and guidance, with what planning it decided on the way.
pub(super) struct Guided {
    /// Frames of the window sampled.
    pub frames: usize,
    /// What pulls the samples.
    pub guidance: Guidance,
    /// Where a dance's keyframes went.
    pub placement: Option<Placement>,
    /// What was clamped (steering beyond the clip's range).
    pub warnings: Vec<String>,
}

impl Guided {
    /// A window of `frames` under `guidance`, nothing else decided.
    fn plain(frames: usize, guidance: Guidance) -> Guided {
        Guided {
            frames,
            guidance,
            placement: None,
            warnings: Vec::new(),
        }
    }

    /// A window of `frames` whose `reference` is kept where `mask` says.
    fn inpainting(frames: usize, reference: Array2<f32>, mask: Array2<f32>) -> Guided {
        Guided::plain(
            frames,
            Guidance {
                inpainting: Some(Inpainting { reference, mask }),
                harmonization: None,
                steering: None,
            },
        )
    }
}

/// The window and guidance of `task` on the model of `metadata` (`seed` places a dance's
/// keyframes).
pub(super) fn guided(
    metadata: &ModelMetadata,
    task: &Task,
    seed: u64,
) -> Result<Guided, TaskError> {
    match task {
        Task::Generate { frames } => Ok(Guided::plain(*frames, Guidance::default())),
        Task::Steer {
            frames,
            commands,
            ramp,
        } => steer(metadata, *frames, commands, *ramp),
        Task::Dance {
            reference,
            beats,
            root,
        } => dance(metadata, reference, beats, *root, seed),
        Task::Inbetween {
            reference,
            keep,
            ramp,
        } => inbetween(metadata, reference, keep, *ramp),
        Task::Expand {
            reference,
            prefix,
            suffix,
            ramp,
        } => expand(metadata, reference, *prefix, *suffix, *ramp),
        Task::Compose {
            reference,
            joints,
            root,
            spans,
            ramp,
        } => compose(metadata, reference, joints, *root, spans, *ramp),
        Task::Harmonize {
            content,
            factor,
            free_share,
        } => harmonize(metadata, content, *factor, *free_share),
    }
}

fn steer(
    metadata: &ModelMetadata,
    frames: usize,
    commands: &[SteerFrame],
    ramp: usize,
) -> Result<Guided, TaskError> {
    check_length(frames)?;
    let ramp = check_ramp(ramp)?;
    let mut per_frame = commands.to_vec();
    per_frame.resize(frames, SteerFrame::Free);
    let start = crate::motion::RootStart::of(&metadata.layout).ok_or_else(|| {
        TaskError::Steer(
            "the model has no heading-relative root (train it with --root-layout heading)".into(),
        )
    })?;
    let planned = crate::steer::plan_steering(metadata, &per_frame, 0, start, ramp)
        .map_err(TaskError::Steer)?;
    Ok(Guided {
        warnings: planned.warnings,
        ..Guided::plain(
            frames,
            Guidance {
                steering: planned.steering,
                ..Guidance::default()
            },
        )
    })
}

fn dance(
    metadata: &ModelMetadata,
    reference: &Array2<f32>,
    beats: &DanceBeats,
    root: bool,
    seed: u64,
) -> Result<Guided, TaskError> {
    let f = metadata.network.features;
    let y = normalized(metadata, reference)?;
    check_length(beats.frames)?;
    check_ramp(beats.ramp)?;
    let placed = place_keyframes(y.ncols(), beats, seed)?;
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
    let rows: Vec<usize> = if root {
        (0..f).collect()
    } else {
        (root_rows..f).collect()
    };
    let mask = frame_mask(f, &weights, Some(&rows));
    Ok(Guided {
        placement: Some(placed),
        ..Guided::inpainting(n, target, mask)
    })
}

fn inbetween(
    metadata: &ModelMetadata,
    reference: &Array2<f32>,
    keep: &[Span],
    ramp: usize,
) -> Result<Guided, TaskError> {
    let y = normalized(metadata, reference)?;
    let n = y.ncols();
    if keep.is_empty() {
        return Err(TaskError::NothingToDo(
            "in-betweening needs at least one span of the reference to keep".into(),
        ));
    }
    let ramp = check_ramp(ramp)?;
    let keep = check_spans(keep, n)?;
    let weights = soft_mask(&covered(n, &keep), ramp);
    let mask = frame_mask(metadata.network.features, &weights, None);
    Ok(Guided::inpainting(n, y, mask))
}

fn expand(
    metadata: &ModelMetadata,
    reference: &Array2<f32>,
    prefix: usize,
    suffix: usize,
    ramp: usize,
) -> Result<Guided, TaskError> {
    let f = metadata.network.features;
    let y = normalized(metadata, reference)?;
    if prefix == 0 && suffix == 0 {
        return Err(TaskError::NothingToDo(
            "expansion needs a prefix or a suffix of at least one frame".into(),
        ));
    }
    // Checked: a prefix or suffix near usize::MAX must be refused, not wrap around.
    let n = prefix
        .checked_add(y.ncols())
        .and_then(|n| n.checked_add(suffix))
        .unwrap_or(usize::MAX);
    check_length(n)?;
    let ramp = check_ramp(ramp)?;
    let mut padded = Array2::<f32>::zeros((f, n));
    padded
        .slice_mut(ndarray::s![.., prefix..prefix + y.ncols()])
        .assign(&y);
    let keep = covered(n, &[Span::new(prefix, prefix + y.ncols())]);
    let mask = frame_mask(f, &soft_mask(&keep, ramp), None);
    Ok(Guided::inpainting(n, padded, mask))
}

fn compose(
    metadata: &ModelMetadata,
    reference: &Array2<f32>,
    joints: &[usize],
    root: bool,
    spans: &[Span],
    ramp: usize,
) -> Result<Guided, TaskError> {
    let y = normalized(metadata, reference)?;
    let n = y.ncols();
    let ramp = check_ramp(ramp)?;
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
    if root && let Some(r) = &layout.root {
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
    let mask = frame_mask(metadata.network.features, &weights, Some(&rows));
    Ok(Guided::inpainting(n, y, mask))
}

fn harmonize(
    metadata: &ModelMetadata,
    content: &Array2<f32>,
    factor: usize,
    free_share: f64,
) -> Result<Guided, TaskError> {
    let y = normalized(metadata, content)?;
    if factor < 1 || factor > y.ncols().max(1) {
        return Err(TaskError::Harmonization(format!(
            "the down-sampling factor must be between 1 and the content's {} frames, got {factor}",
            y.ncols()
        )));
    }
    if !(0.0..=1.0).contains(&free_share) {
        return Err(TaskError::Harmonization(format!(
            "the free share of final steps must be between 0 and 1, got {free_share}"
        )));
    }
    Ok(Guided::plain(
        y.ncols(),
        Guidance {
            inpainting: None,
            steering: None,
            harmonization: Some(Harmonization {
                content: y,
                factor,
                free_share,
            }),
        },
    ))
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

pub(super) fn check_length(frames: usize) -> Result<(), TaskError> {
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
