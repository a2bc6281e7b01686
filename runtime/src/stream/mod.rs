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

pub mod blocks;
mod guide;

use std::collections::VecDeque;

use ndarray::{Array2, Axis, s};

use crate::diffusion::sampler::{Denoiser, Guidance, Inpainting, Sampler};
use crate::diffusion::{Method, Schedule};
use crate::limits::MAX_SAMPLE_FRAMES;
use crate::model_file::ModelMetadata;
use crate::motion::features::heading::yaw;
use crate::motion::feet::{Anchor, Feet, Kept, PlantOptions, plant_feet};
use crate::motion::math::{Mat3, Vec3};
use crate::motion::up::UP;
use crate::motion::{
    FeatureMatrix, LocalMotion, Pose, RootStart, decode, decode_from, poses, root_track,
};
use crate::steer::{SteerFrame, SteerLimits, plan_steering};
use crate::tasks::mask::soft_mask;
use crate::tasks::{INBETWEEN_RAMP, Progress, TaskError};
use blocks::{BlockSizes, block_seed};
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

/// One final frame waiting to be handed out.
#[derive(Debug, Clone)]
struct Frame {
    features: Vec<f32>,
    rotations: Vec<Mat3>,
    translations: Vec<Vec3>,
}

/// A block whose sampling run is under way (see [`Stream::prepare`]).
#[derive(Debug)]
struct PendingBlock {
    window: blocks::Window,
    sampler: Sampler,
    /// Per window frame, whether steering commands the root's travel there (planting leaves
    /// those roots where the steering put them).
    travel_commanded: Vec<bool>,
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
        if frames > MAX_SAMPLE_FRAMES {
            return Err(TaskError::Length {
                frames,
                reason: format!("one chunk holds at most {MAX_SAMPLE_FRAMES} frames"),
            });
        }
        while self.ready.len() < frames {
            self.advance(denoiser, usize::MAX)?;
        }
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
        Ok(StreamChunk {
            motion: LocalMotion {
                skeleton: layout.skeleton.clone(),
                fps: layout.fps,
                rotations,
                translations,
            },
            features,
        })
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

    /// Starts the next block's sampling run: its window, guidance and noise.
    fn start_block(&mut self) -> Result<PendingBlock, TaskError> {
        let sizes = self.sizes;
        let window = sizes.window(self.blocks);
        let f = self.metadata.network.features;
        let n = window.frames;
        let mut reference = Array2::<f32>::zeros((f, n));
        let mut mask = Array2::<f32>::zeros((f, n));
        if let Some(carried) = &self.carried {
            reference
                .slice_mut(s![.., ..window.carried])
                .assign(carried);
            for (i, w) in sizes.carry_weights(&window).into_iter().enumerate() {
                mask.column_mut(i).fill(w);
            }
        }
        if !self.compose_rows.is_empty() {
            let (guide, covered) = self.guide.features(&self.metadata, window.start, n)?;
            let weights = soft_mask(&covered, sizes.ramp);
            for &row in &self.compose_rows {
                for i in window.context..n {
                    if weights[i] > mask[[row, i]] {
                        mask[[row, i]] = weights[i];
                        reference[[row, i]] = guide[[row, i]];
                    }
                }
            }
        }
        let steering = if self.commands.is_empty() {
            None
        } else {
            let course = match (self.last_course, window.context) {
                (Some(last), c) if c > 0 => Some((c - 1, last)),
                _ => RootStart::of(&self.metadata.layout).map(|start| (0, start)),
            };
            match course {
                Some((anchor, course)) => {
                    let commands = self.commands_for(window.start, n);
                    let planned =
                        plan_steering(&self.metadata, &commands, anchor, course, sizes.ramp)
                            .map_err(TaskError::Steer)?;
                    for line in planned.warnings {
                        if !self.warnings.contains(&line) {
                            self.warnings.push(line);
                        }
                    }
                    planned.steering
                }
                None => None,
            }
        };
        // Commands the next blocks cannot reach are dropped.
        let floor = (window.start + window.frames).saturating_sub(sizes.context + sizes.ramp + 1);
        while self.commands_first < floor && !self.commands.is_empty() {
            self.commands.pop_front();
            self.commands_first += 1;
        }
        // Supplied poses the next blocks cannot reach are dropped (also when nothing is composed,
        // so supplying poses never makes memory grow).
        self.guide.forget_before(
            (window.start + window.frames).saturating_sub(sizes.context + sizes.ramp + 1),
        );
        let inpainting = mask
            .iter()
            .any(|&m| m > 0.0)
            .then_some(Inpainting { reference, mask });
        let guidance = Guidance {
            inpainting,
            harmonization: None,
            steering,
        };
        let travel_commanded = guidance
            .steering
            .as_ref()
            .map(|s| s.travel_commanded())
            .unwrap_or_default();
        let seed = block_seed(self.seed, self.blocks as u64);
        let sampler =
            Sampler::new(&self.schedule, &guidance, 1, f, n, seed)?.with_method(self.method)?;
        Ok(PendingBlock {
            window,
            sampler,
            travel_commanded,
        })
    }

    /// Decodes a finished block and queues its final frames.
    fn complete_block(&mut self, pending: PendingBlock) -> Result<(), TaskError> {
        let PendingBlock {
            window,
            sampler,
            travel_commanded,
        } = pending;
        let sizes = self.sizes;
        let n = window.frames;
        let normalized = sampler.into_sample().index_axis_move(Axis(0), 0);
        let keep = sizes.context + sizes.ramp;
        // Nothing of the stream changes until every fallible step has passed: a block that
        // cannot be decoded leaves the stream as it was (the same block is made again).
        let carried = normalized.slice(s![.., n - keep..]).to_owned();
        let raw = self.metadata.normalizer.denormalize(normalized.view());

        // Decode the context and the final frames; carry the root on from the last chunk.
        let done = window.finalised(&sizes);
        let layout = &self.metadata.layout;
        let joints = layout.skeleton.len();
        let rows = raw.slice(s![.., ..done.end]);
        let mut last_root = self.last_root;
        let mut last_course = self.last_course;
        let mut motion = match RootStart::of(layout) {
            // A heading-relative root: the block's course is turned and moved so that it goes
            // on from the last final frame's position and facing.
            Some(first) => {
                let start = match (self.last_course, done.start > 0) {
                    (Some(last), true) => {
                        let from_layout = root_track(layout, rows, None);
                        let (positions, headings) = from_layout.unwrap_or_default();
                        let k = done.start - 1;
                        let turn = last.heading - headings[k];
                        let mut travelled = positions[k] - first.position;
                        travelled[UP] = 0.0;
                        RootStart {
                            position: last.position - yaw(turn) * travelled,
                            heading: first.heading + turn,
                        }
                    }
                    _ => first,
                };
                let (positions, headings) =
                    root_track(layout, rows, Some(start)).unwrap_or_default();
                last_course = Some(RootStart {
                    position: positions[done.end - 1],
                    heading: headings[done.end - 1],
                });
                decode_from(layout, rows, Some(start))?
            }
            None => decode(layout, rows)?,
        };
        if let Some(root) = layout.root.as_ref().filter(|r| r.heading.is_none()) {
            let r = root.joint;
            if let (Some(last), true) = (self.last_root, done.start > 0) {
                let offset = last - motion.translations[(done.start - 1) * joints + r];
                for frame in 0..done.end {
                    let t = &mut motion.translations[frame * joints + r];
                    *t += offset;
                }
            }
            last_root = Some(motion.translations[(done.end - 1) * joints + r]);
        }
        if self.feet == Feet::Planted {
            if let Some(tail) = &self.tail {
                // What was handed out stays as it was.
                let kept = done.start * joints;
                motion.rotations[..kept].copy_from_slice(&tail.rotations);
                motion.translations[..kept].copy_from_slice(&tail.translations);
            }
            let labels: Vec<Vec<f32>> = layout
                .contact_rows()
                .into_iter()
                .map(|row| raw.row(row).slice(s![..done.end]).to_vec())
                .collect();
            let kept = Kept {
                joints: (0..done.end)
                    .map(|frame| vec![frame < done.start; joints])
                    .collect(),
                root: (0..done.end)
                    .map(|frame| {
                        frame < done.start || travel_commanded.get(frame).copied() == Some(true)
                    })
                    .collect(),
            };
            let options = PlantOptions {
                anchor: Anchor::Landing,
                ..PlantOptions::default()
            };
            motion = plant_feet(layout, &motion, &labels, &kept, &options)?.0;
        }
        self.carried = Some(carried);
        self.last_root = last_root;
        self.last_course = last_course;
        for frame in done.clone() {
            let range = frame * joints..(frame + 1) * joints;
            self.ready.push_back(Frame {
                features: raw.column(frame).to_vec(),
                rotations: motion.rotations[range.clone()].to_vec(),
                translations: motion.translations[range].to_vec(),
            });
        }
        let tail_from = (done.end - sizes.context) * joints;
        self.tail = Some(LocalMotion {
            skeleton: layout.skeleton.clone(),
            fps: layout.fps,
            rotations: motion.rotations[tail_from..].to_vec(),
            translations: motion.translations[tail_from..].to_vec(),
        });
        self.blocks += 1;
        Ok(())
    }
}
