//! Endless motion, a chunk at a time: a [`Stream`] over a model hands out the next `n` frames on
//! demand, forever, with memory that does not grow.
//!
//! Motion is made in fixed blocks ([`blocks`]): each block is an in-betweening run whose window
//! starts with the last final frames of the block before (the model's receptive field by
//! default, kept exactly) and the frames that block held back (kept with a soft border, so the
//! seam is settled by the new block), followed by new frames. Every block is seeded from the
//! stream's seed and its index, so the motion depends on the model, the seed and the
//! [`StreamOptions`] only, never on the chunk sizes a caller asks for (with
//! [`StreamOptions::compose`], also on how far ahead poses were supplied when a block was made:
//! supply at least [`Stream::lookahead`] frames past what has been handed out to make that
//! moot). The root's travel continues from where the last chunk ended, and planted feet stay
//! planted across seams (spans are held where they landed, and frames handed out are never
//! changed).

mod block_run;
pub mod blocks;
mod crowd;
mod guide;

use std::collections::VecDeque;

use ndarray::Array2;

use crate::diffusion::sampler::Denoiser;
use crate::diffusion::{Method, Schedule};
use crate::limits::MAX_SAMPLE_FRAMES;
use crate::model_file::ModelMetadata;
use crate::motion::feet::Feet;
use crate::motion::math::{Mat3, Vec3};
use crate::motion::{FeatureMatrix, LocalMotion, Pose, RootStart, poses};
use crate::steer::{SteerFrame, SteerLimits};
use crate::tasks::{INBETWEEN_RAMP, Progress, TaskError};
use block_run::PendingBlock;
use blocks::{BlockSizes, block_seed};
pub use crowd::{CharacterId, Crowd, CrowdProgress};
use guide::Guide;

/// Joints (and the root's travel) that a stream takes from poses the game supplies.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StreamCompose {
    /// Joints whose rotations come from the supplied poses (indices into the skeleton).
    pub joints: Vec<usize>,
    /// Whether the root's travel (per-frame displacement) and height come from them.
    pub root: bool,
}

/// How a stream makes its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamOptions {
    /// Seed of the portable noise.
    pub seed: u64,
    /// Sampling steps per block (respaced); `None` runs all T steps.
    pub steps: Option<usize>,
    /// Frames each block makes final; `None` for the length of the model's training clip, the
    /// length its GroupNorm statistics were learned at (shorter blocks came out measurably more
    /// unlike one-shot samples: on the walk, global diversity 1.67 with 2 s blocks, 1.37 with
    /// 4 s and 1.18 with 8 s, against 1.24 in one shot). Longer blocks also cost less per frame
    /// (the context is paid once per block) but take longer to make.
    pub block_frames: Option<usize>,
    /// Final frames of the previous block each block sees; `None` for the model's receptive field.
    pub context_frames: Option<usize>,
    /// Frames held back and settled by the next block (the seam's soft border).
    pub ramp: usize,
    /// What is done to the feet of the motion handed out.
    pub feet: Feet,
    /// Joints taken from supplied poses ([`Stream::supply`]), if any.
    pub compose: Option<StreamCompose>,
    /// The update rule of each sampling step.
    pub method: Method,
}

/// Respaced denoising steps per block of a stream unless told otherwise, fewer than a one-shot
/// run's [`DEFAULT_STEPS`](crate::DEFAULT_STEPS): a block continues a context it is conditioned
/// on, and 60-second streams of the shipped walk, hop and fox at 20 steps score as those at 50
/// (coverage within a point, global diversity within 3 %, jitter within 7 %; docs/PERFORMANCE.md)
/// at less than half the cost of a chunk.
pub const DEFAULT_STREAM_STEPS: usize = 20;

impl Default for StreamOptions {
    fn default() -> Self {
        StreamOptions {
            seed: 0,
            steps: Some(DEFAULT_STREAM_STEPS),
            block_frames: None,
            context_frames: None,
            ramp: INBETWEEN_RAMP,
            feet: Feet::default(),
            compose: None,
            method: Method::default(),
        }
    }
}

/// Frames handed out by [`Stream::next`].
#[derive(Debug, Clone, PartialEq)]
pub struct StreamChunk {
    /// The frames as local joint transforms (the file's frame and units).
    pub motion: LocalMotion,
    /// The network's features of the frames `[F, n]` (file units; the same whatever the feet).
    pub features: FeatureMatrix,
}

impl StreamChunk {
    /// The frames as engine poses.
    pub fn poses(&self) -> Vec<Pose> {
        poses(&self.motion)
    }

    /// Frames in the chunk.
    pub fn frames(&self) -> usize {
        self.features.ncols()
    }
}

/// Refuses a chunk of more frames than one sample may hold.
fn check_chunk(frames: usize) -> Result<(), TaskError> {
    if frames > MAX_SAMPLE_FRAMES {
        return Err(TaskError::Length {
            frames,
            reason: format!("one chunk holds at most {MAX_SAMPLE_FRAMES} frames"),
        });
    }
    Ok(())
}

/// One final frame waiting to be handed out.
#[derive(Debug, Clone)]
struct Frame {
    features: Vec<f32>,
    rotations: Vec<Mat3>,
    translations: Vec<Vec3>,
}

/// Endless motion from one model; see the [module documentation](self).
#[derive(Debug)]
pub struct Stream {
    metadata: ModelMetadata,
    feet: Feet,
    seed: u64,
    method: Method,
    sizes: BlockSizes,
    schedule: Schedule,
    compose_rows: Vec<usize>,
    /// Blocks made so far.
    blocks: usize,
    /// Frames handed out so far.
    handed_out: usize,
    /// The last `C + R` normalised frames of the last block's window.
    carried: Option<Array2<f32>>,
    /// The last `C` final frames as handed out (feet as chosen).
    tail: Option<LocalMotion>,
    /// The root joint's translation in the last final frame, before planting (a world-layout
    /// root).
    last_root: Option<Vec3>,
    /// A heading-relative root's canonical position and facing in the last final frame.
    last_course: Option<RootStart>,
    /// Steering commands from stream frame `commands_first` on.
    commands: VecDeque<SteerFrame>,
    commands_first: usize,
    /// Lines on what steering clamped.
    warnings: Vec<String>,
    /// Final frames not yet handed out.
    ready: VecDeque<Frame>,
    /// The next block, when its run has been started ahead of need.
    pending: Option<PendingBlock>,
    guide: Guide,
    /// Whether blocks draw their noise on the calling thread (a crowd's streams) rather than
    /// on a worker of their own; the values are the same.
    noise_on_this_thread: bool,
}

impl Stream {
    /// A stream over a model with `metadata` (the [`crate::Model`] it will run on), checked.
    pub fn new(metadata: &ModelMetadata, options: StreamOptions) -> Result<Stream, TaskError> {
        let bad = |m: String| Err(TaskError::Stream(m));
        let layout = &metadata.layout;
        let context = options
            .context_frames
            .unwrap_or(metadata.network.receptive_field.max(1));
        let block = options
            .block_frames
            .unwrap_or(metadata.training.clip_frames.max(context));
        let ramp = options.ramp.max(1);
        if context == 0 {
            return bad("a stream needs at least one frame of context".into());
        }
        if block < context {
            return bad(format!(
                "blocks of {block} frames are shorter than their {context} frames of context; make them at least as long"
            ));
        }
        if ramp > block {
            return bad(format!(
                "a soft border of {ramp} frames does not fit in blocks of {block} frames"
            ));
        }
        let window = context.saturating_add(ramp).saturating_add(block);
        if window > MAX_SAMPLE_FRAMES {
            return bad(format!(
                "a window of {window} frames is beyond the limit of {MAX_SAMPLE_FRAMES}"
            ));
        }
        if let Some(problem) = options.method.problem() {
            return bad(problem);
        }
        let schedule = match options.steps {
            Some(s) => Schedule::respaced(metadata.diffusion.steps, s)?,
            None => Schedule::cosine(metadata.diffusion.steps)?,
        };
        let mut compose_rows = Vec::new();
        if let Some(compose) = &options.compose {
            if let Some(&index) = compose.joints.iter().find(|&&j| j >= layout.skeleton.len()) {
                return Err(TaskError::JointIndex {
                    index,
                    joints: layout.skeleton.len(),
                });
            }
            compose_rows.extend(compose.joints.iter().flat_map(|&j| layout.joint_columns(j)));
            if compose.root
                && let Some(r) = &layout.root
            {
                compose_rows.extend(0..r.width());
            }
            compose_rows.sort_unstable();
            compose_rows.dedup();
            if compose_rows.is_empty() {
                return Err(TaskError::NothingToDo(
                    "composition needs joints or the root to take from the supplied poses".into(),
                ));
            }
        }
        Ok(Stream {
            metadata: metadata.clone(),
            feet: options.feet,
            seed: options.seed,
            method: options.method,
            sizes: BlockSizes {
                context,
                ramp,
                block,
            },
            schedule,
            compose_rows,
            blocks: 0,
            handed_out: 0,
            carried: None,
            tail: None,
            last_root: None,
            last_course: None,
            commands: VecDeque::new(),
            commands_first: 0,
            warnings: Vec::new(),
            ready: VecDeque::new(),
            pending: None,
            guide: Guide::default(),
            noise_on_this_thread: false,
        })
    }

    /// The metadata of the model the stream was made for.
    pub fn metadata(&self) -> &ModelMetadata {
        &self.metadata
    }

    /// The block sizes in use.
    pub fn sizes(&self) -> BlockSizes {
        self.sizes
    }

    /// Frames handed out so far.
    pub fn frames_handed_out(&self) -> usize {
        self.handed_out
    }

    /// How many frames past those handed out a block may reach: poses supplied that far ahead
    /// make a composed stream independent of chunk sizes.
    pub fn lookahead(&self) -> usize {
        2 * self.sizes.block + self.sizes.ramp
    }

    /// Steering commands for the frames after the last commanded one (the first call commands
    /// frame 0): where the root goes, frame by frame and ahead of time ([`crate::steer`]).
    /// Command `i` given in all belongs to stream frame `i`, always: a block uses the commands
    /// given when it starts, so commands for frames a block has already started on are not
    /// used (give them at least [`Stream::lookahead`] frames ahead of what has been handed
    /// out, plus whatever [`Stream::prepare`] made ahead). Needs a heading-relative model,
    /// finite numbers and facings with a direction on the ground. Commands beyond the clip's
    /// range are clamped when used and reported by [`Stream::warnings`].
    pub fn steer(&mut self, commands: &[SteerFrame]) -> Result<(), TaskError> {
        if SteerLimits::of(&self.metadata).is_none() {
            return Err(TaskError::Steer(
                "the model has no heading-relative root (train it with --root-layout heading)"
                    .into(),
            ));
        }
        crate::steer::check_commands(&self.metadata, commands).map_err(|e| {
            TaskError::Steer(format!(
                "{e} (command 0 is stream frame {})",
                self.commands_first + self.commands.len()
            ))
        })?;
        self.commands.extend(commands.iter().copied());
        Ok(())
    }

    /// What steering changed of the commands so far (clamped to the clip's range), one line
    /// per kind.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The commands for stream frames `start..start + frames` (free where none was given).
    fn commands_for(&self, start: usize, frames: usize) -> Vec<SteerFrame> {
        (start..start + frames)
            .map(|frame| {
                frame
                    .checked_sub(self.commands_first)
                    .and_then(|i| self.commands.get(i).copied())
                    .unwrap_or(SteerFrame::Free)
            })
            .collect()
    }

    /// Poses for the frames after the last supplied one (the first call supplies frame 0), for
    /// [`StreamOptions::compose`]. Frames without a supplied pose are generated freely.
    pub fn supply(&mut self, poses: &[Pose]) -> Result<(), TaskError> {
        if self.compose_rows.is_empty() {
            return Err(TaskError::Stream(
                "this stream takes no supplied poses: make it with joints or the root to compose"
                    .into(),
            ));
        }
        Ok(self.guide.supply(&self.metadata, poses)?)
    }

    /// The next `frames` frames, making as many blocks as that needs on `denoiser` (the model
    /// whose metadata made the stream).
    pub fn next<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        frames: usize,
    ) -> Result<StreamChunk, TaskError>
    where
        TaskError: From<D::Error>,
    {
        check_chunk(frames)?;
        while self.ready.len() < frames {
            self.advance(denoiser, usize::MAX)?;
        }
        Ok(self.hand_out(frames))
    }

    /// Hands out the first `frames` ready frames (at most [`Stream::ready_frames`]).
    fn hand_out(&mut self, frames: usize) -> StreamChunk {
        let frames = frames.min(self.ready.len());
        let layout = &self.metadata.layout;
        let joints = layout.skeleton.len();
        let mut features = Array2::<f32>::zeros((self.metadata.network.features, frames));
        let mut rotations = Vec::with_capacity(frames * joints);
        let mut translations = Vec::with_capacity(frames * joints);
        for (i, frame) in self.ready.drain(..frames).enumerate() {
            features
                .column_mut(i)
                .iter_mut()
                .zip(&frame.features)
                .for_each(|(o, v)| *o = *v);
            rotations.extend(frame.rotations);
            translations.extend(frame.translations);
        }
        self.handed_out += frames;
        StreamChunk {
            motion: LocalMotion {
                skeleton: layout.skeleton.clone(),
                fps: layout.fps,
                rotations,
                translations,
            },
            features,
        }
    }

    /// Final frames made and not yet handed out: [`Stream::next`] for at most this many frames
    /// runs no network.
    pub fn ready_frames(&self) -> usize {
        self.ready.len()
    }

    /// Prepares frames ahead of need, spending at most `max_steps` denoising steps: while
    /// fewer than `ahead` frames are ready, it steps the next block's run (starting it if
    /// needed) and queues its frames once it finishes. A game calls it every frame with a
    /// small `max_steps` and reads with [`Stream::next`], which then never waits when enough
    /// frames are ready. The motion is the same bits as a stream read without preparing. A
    /// stream with composed joints starts a block's guidance from the poses supplied when the
    /// block starts: supply at least `ahead` + [`Stream::lookahead`] frames past those handed out
    /// before preparing, or blocks are guided by fewer poses than a later start would see.
    /// Returns the progress of the block in the making (`0 of 0` when none is).
    pub fn prepare<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        max_steps: usize,
        ahead: usize,
    ) -> Result<Progress, TaskError>
    where
        TaskError: From<D::Error>,
    {
        let mut budget = max_steps;
        while self.ready.len() < ahead && budget > 0 {
            budget -= self.advance(denoiser, budget)?;
        }
        Ok(self.block_progress())
    }

    /// Steps taken and steps in all of the block in the making (`0 of 0` when none is).
    pub fn block_progress(&self) -> Progress {
        self.pending
            .as_ref()
            .map_or(Progress { done: 0, total: 0 }, |p| Progress {
                done: p.sampler.done(),
                total: p.sampler.steps(),
            })
    }

    /// Takes up to `max_steps` steps of the next block (starting it if none is under way) and
    /// queues its frames when it finishes; returns the steps taken (at least one, so a caller
    /// looping on it always gets on).
    fn advance<D: Denoiser>(
        &mut self,
        denoiser: &mut D,
        max_steps: usize,
    ) -> Result<usize, TaskError>
    where
        TaskError: From<D::Error>,
    {
        let mut pending = match self.pending.take() {
            Some(p) => p,
            None => self.start_block()?,
        };
        let mut taken = 0;
        while taken < max_steps.max(1) && !pending.sampler.is_finished() {
            if let Err(e) = pending.sampler.step(denoiser) {
                self.pending = Some(pending);
                return Err(e.into());
            }
            taken += 1;
        }
        if pending.sampler.is_finished() {
            self.complete_block(pending)?;
        } else {
            self.pending = Some(pending);
        }
        Ok(taken.max(1))
    }
}
