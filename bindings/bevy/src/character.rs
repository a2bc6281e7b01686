//! A character driven by a stream: one entity per joint, poses written every frame from motion
//! made ahead on Bevy's async compute pool.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use bevy_ecs::prelude::*;
use bevy_tasks::AsyncComputeTaskPool;
use bevy_transform::components::Transform;
use sinmdm::steer::SteerLimits;
use sinmdm::{
    Model, ModelError, ModelMetadata, ModelOptions, Pose, Skeleton, Stream, StreamOptions,
    TaskError,
};

use crate::frame::EngineFrame;
use crate::playback::{Frames, needed, on_show};
use crate::steering::Steering;

/// A model shared by any number of characters. Its metadata is read without waiting; its
/// network is locked by one stream at a time while it denoises, so characters on one model take
/// turns (open the file once per character to run them side by side on several threads).
#[derive(Clone)]
pub struct MotionModel {
    model: Arc<Mutex<Model>>,
    metadata: Arc<ModelMetadata>,
}

impl MotionModel {
    /// Opens a `.onnx` model file; `threads` as [`ModelOptions::threads`] (a stream denoises one
    /// sample, so one thread is the usual choice in a game).
    pub fn open(path: impl AsRef<Path>, threads: Option<usize>) -> Result<MotionModel, ModelError> {
        Ok(MotionModel::from(Model::open(
            path,
            &ModelOptions { threads },
        )?))
    }

    /// The model file's metadata (skeleton, frame rate, layout).
    pub fn metadata(&self) -> &ModelMetadata {
        &self.metadata
    }

    /// The model's frames per second.
    pub fn fps(&self) -> f64 {
        self.metadata.layout.fps
    }

    /// Runs `f` on the model, waiting while a stream denoises on it.
    pub fn with<R>(&self, f: impl FnOnce(&mut Model) -> R) -> R {
        let mut guard = self.model.lock().unwrap_or_else(|p| p.into_inner());
        f(&mut guard)
    }
}

impl From<Model> for MotionModel {
    fn from(model: Model) -> MotionModel {
        let metadata = Arc::new(model.metadata().clone());
        MotionModel {
            model: Arc::new(Mutex::new(model)),
            metadata,
        }
    }
}

/// How a character's motion is made and played.
#[derive(Debug, Clone)]
pub struct CharacterOptions {
    /// The stream's options (seed, steps, block size, feet).
    pub stream: StreamOptions,
    /// Frames the stream hands out per request to the compute pool.
    pub chunk_frames: usize,
    /// Frames kept ready past the one on show; a new request starts when fewer are. `None`
    /// adapts to the machine: a chunk plus twice the longest request so far, in frames, so
    /// the next block is made before the frames ready run out.
    pub ahead_frames: Option<usize>,
    /// Metres per file unit; `None` guesses from the figure's height.
    pub metres_per_unit: Option<f64>,
    /// Whether the pose between two model frames is interpolated (otherwise the last frame is
    /// held until the next one is due).
    pub interpolate: bool,
}

impl CharacterOptions {
    /// Options for a model at `fps`: half-second chunks, frames ready ahead as the machine
    /// needs, interpolated, the stream's defaults.
    pub fn for_fps(fps: f64) -> CharacterOptions {
        CharacterOptions {
            stream: StreamOptions::default(),
            chunk_frames: (fps / 2.0).ceil().max(1.0) as usize,
            ahead_frames: None,
            metres_per_unit: None,
            interpolate: true,
        }
    }
}

/// What a character's request gives back: the frames, or why there are none.
type Maker = crate::playback::Maker<Engine, Result<Vec<Pose>, TaskError>>;

/// The model and the stream on it, moved to the compute pool for each request.
struct Engine {
    model: MotionModel,
    stream: Stream,
}

/// A character driven by a stream (on the entity that parents its top joints).
#[derive(Component)]
pub struct MotionCharacter {
    joints: Vec<Entity>,
    parents: Vec<Option<usize>>,
    frame: EngineFrame,
    fps: f64,
    options: CharacterOptions,
    /// The clip's speed range, for a heading-relative model (`None`: it cannot steer).
    limits: Option<SteerLimits>,
    clock: Option<f64>,
    frames: Frames,
    /// Stream frames given a steering command so far.
    commanded: usize,
    /// In a mutex only to make the component `Sync` (a stream is `Send`, not `Sync`); reached
    /// through `&mut self`, so it is never locked.
    maker: Mutex<Maker>,
    frames_shown: u64,
    waits: Vec<u64>,
    slowest_request: f64,
    error: Option<String>,
    steering_note: Option<String>,
    stream_warnings: Vec<String>,
}

impl MotionCharacter {
    /// The joint entities, in the model's skeleton order.
    pub fn joints(&self) -> &[Entity] {
        &self.joints
    }

    /// How the model's poses are placed in Bevy's frame.
    pub fn frame(&self) -> EngineFrame {
        self.frame
    }

    /// The model frame on show (fractional between two frames); `None` before the first.
    pub fn clock(&self) -> Option<f64> {
        self.clock
    }

    /// The model's frames per second.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The Bevy frames (counted from the character's first, 0) that had to wait for motion:
    /// the first does (nothing is made before it); later ones only when the compute pool fell
    /// behind.
    pub fn waits(&self) -> &[u64] {
        &self.waits
    }

    /// Bevy frames shown so far.
    pub fn frames_shown(&self) -> u64 {
        self.frames_shown
    }

    /// Frames kept ready past the one on show ([`CharacterOptions::ahead_frames`]).
    pub fn ahead_frames(&self) -> usize {
        let chunk = self.options.chunk_frames.max(1);
        self.options
            .ahead_frames
            .unwrap_or_else(|| chunk + (2.0 * self.slowest_request * self.fps).ceil() as usize)
    }

    /// How many model frames past the one on show already have their steering command: a
    /// change of [`Steering`] shows in the motion within this many frames (the frames made
    /// ahead, and the rest of the last block started; shorter blocks steer sooner).
    pub fn steering_reach(&self) -> usize {
        let shown = self.clock.map_or(0, |c| c.floor() as usize);
        self.commanded.saturating_sub(shown)
    }

    /// Why the motion stopped, if it did (the character then holds its last pose).
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// What the stream changed of the steering commands (speeds and turns clamped to the clip's
    /// range), one line per kind, as of the last request.
    pub fn warnings(&self) -> &[String] {
        &self.stream_warnings
    }

    /// What became of a [`Steering`] that could not be followed as given, if any (a model
    /// without a heading-relative root, a value that is not finite), the latest.
    pub fn steering_note(&self) -> Option<&str> {
        self.steering_note.as_deref()
    }

    /// Advances the clock by `seconds`, takes the frames of a finished request and starts the
    /// next one if fewer than [`Self::ahead_frames`] frames are ready; never waits.
    pub(crate) fn advance(&mut self, seconds: f64, steering: Option<&Steering>) {
        let clock = self.clock.map_or(0.0, |c| c + seconds * self.fps);
        self.clock = Some(clock);
        self.collect(false);
        let base = clock.floor() as usize;
        if self.frames.ready_past(base) < self.ahead_frames() {
            self.request(steering);
        }
    }

    /// Writes the pose due into the joints' transforms, waiting for the frames it needs when
    /// they are not ready (recorded in [`Self::waits`]). Runs after [`Self::advance`].
    pub(crate) fn show(
        &mut self,
        steering: Option<&Steering>,
        transforms: &mut Query<&mut Transform, Without<MotionCharacter>>,
    ) {
        let (base, frac) = on_show(self.clock);
        let needed = needed(base, frac, self.options.interpolate);
        if self.frames.end() < needed && self.error.is_none() {
            self.waits.push(self.frames_shown);
            while self.frames.end() < needed && self.error.is_none() {
                self.request(steering);
                self.collect(true);
            }
        }
        let interpolated = self.options.interpolate;
        if let Some(pose) = self.frames.show(base, frac, interpolated) {
            self.frame
                .write_pose(&pose, &self.joints, &self.parents, transforms);
        }
        self.frames_shown += 1;
    }

    /// Takes the frames of a finished request (waiting for it when `wait`).
    fn collect(&mut self, wait: bool) {
        let Some((engine, result, seconds)) = self.maker_mut().finished(wait) else {
            return;
        };
        self.slowest_request = self.slowest_request.max(seconds);
        match result {
            Ok(poses) => {
                self.frames.extend(poses);
                if self.stream_warnings.as_slice() != engine.stream.warnings() {
                    self.stream_warnings = engine.stream.warnings().to_vec();
                }
                *self.maker_mut() = Maker::Idle(engine);
            }
            Err(e) => {
                self.error = Some(e.to_string());
                *self.maker_mut() = Maker::Stopped;
            }
        }
    }

    /// Starts the next request on the compute pool, if none is under way: steering commands
    /// for every frame the blocks it may start reach, then the next chunk of frames.
    fn request(&mut self, steering: Option<&Steering>) {
        let Some(mut engine) = self.maker_mut().take_idle() else {
            return;
        };
        let chunk = self.options.chunk_frames.max(1);
        if self.limits.is_some() {
            // `next(chunk)` starts blocks until the frames made final reach `handed_out +
            // chunk`; block k's window ends at (k + 1) B + R, so the last one started ends at
            // the next multiple of B past that, plus R.
            let sizes = engine.stream.sizes();
            let block = sizes.block.max(1);
            let finals = engine.stream.frames_handed_out() + chunk;
            let until = finals.div_ceil(block) * block + sizes.ramp;
            if until > self.commanded {
                let command = self.command(steering);
                let commands = vec![command; until - self.commanded];
                match engine.stream.steer(&commands) {
                    Ok(()) => self.commanded = until,
                    Err(e) => self.steering_note = Some(e.to_string()),
                }
            }
        } else if let Some(s) = steering
            && self.steering_note.is_none()
        {
            self.steering_note = Some(format!(
                "{s:?} ignored: the model has no heading-relative root (train it with --root-layout heading)"
            ));
        }
        let task = AsyncComputeTaskPool::get().spawn(async move {
            let started = Instant::now();
            let model = engine.model.clone();
            let result = model.with(|m| engine.stream.next(m, chunk).map(|c| c.poses()));
            (engine, result, started.elapsed().as_secs_f64())
        });
        *self.maker_mut() = Maker::Busy(task);
    }

    /// The stream command for `steering` (free without one, or for a value that is not
    /// finite, which is noted).
    fn command(&mut self, steering: Option<&Steering>) -> sinmdm::steer::SteerFrame {
        let (Some(steering), Some(limits)) = (steering, self.limits.as_ref()) else {
            return sinmdm::steer::SteerFrame::Free;
        };
        match steering.command(&self.frame, limits) {
            Ok(command) => command,
            Err(why) => {
                self.steering_note = Some(why);
                sinmdm::steer::SteerFrame::Free
            }
        }
    }

    /// The motion maker (the mutex is never contended: it is reached through `&mut self`).
    fn maker_mut(&mut self) -> &mut Maker {
        self.maker.get_mut().unwrap_or_else(|p| p.into_inner())
    }
}

/// Spawns a skeleton: an entity at `transform` and under it one entity per joint (named after
/// it, with a [`Transform`] at its rest offset, the top joints turned into Bevy's frame),
/// parented as the skeleton is. Returns the entity and the joints' entities in skeleton order.
/// [`spawn_character`] uses it; on its own it is a rig for baked clips.
pub fn spawn_skeleton(
    commands: &mut Commands,
    skeleton: &Skeleton,
    frame: &EngineFrame,
    transform: Transform,
) -> (Entity, Vec<Entity>) {
    let root = commands.spawn(transform).id();
    let mut joints: Vec<Entity> = Vec::with_capacity(skeleton.len());
    for joint in &skeleton.joints {
        let offset =
            bevy_math::Vec3::from_array(joint.offset.0.map(|v| v as f32)) * frame.metres_per_unit;
        let (parent, rest) = match joint.parent {
            Some(p) => (joints[p], Transform::from_translation(offset)),
            None => (
                root,
                Transform::from_translation(frame.turn * offset).with_rotation(frame.turn),
            ),
        };
        let entity = commands
            .spawn((Name::new(joint.name.clone()), rest, ChildOf(parent)))
            .id();
        joints.push(entity);
    }
    (root, joints)
}

/// Spawns a character from `model`: a skeleton ([`spawn_skeleton`]) whose entity holds a
/// [`MotionCharacter`] at `transform` (where the character stands in the world). Returns the
/// character's entity, or why the stream cannot be made (options it refuses, a unit scale that
/// is not a positive number).
pub fn spawn_character(
    commands: &mut Commands,
    model: &MotionModel,
    options: CharacterOptions,
    transform: Transform,
) -> Result<Entity, TaskError> {
    let metadata = model.metadata();
    let frame = EngineFrame::of(metadata, options.metres_per_unit).map_err(TaskError::Stream)?;
    let stream = Stream::new(metadata, options.stream.clone())?;
    let skeleton = &metadata.layout.skeleton;
    let (character, joints) = spawn_skeleton(commands, skeleton, &frame, transform);
    let parents = skeleton.joints.iter().map(|j| j.parent).collect();
    commands.entity(character).insert(MotionCharacter {
        joints,
        parents,
        frame,
        fps: metadata.layout.fps,
        options,
        limits: SteerLimits::of(metadata),
        clock: None,
        frames: Frames::default(),
        commanded: 0,
        maker: Mutex::new(Maker::Idle(Box::new(Engine {
            model: model.clone(),
            stream,
        }))),
        frames_shown: 0,
        waits: Vec::new(),
        slowest_request: 0.0,
        error: None,
        steering_note: None,
        stream_warnings: Vec::new(),
    });
    Ok(character)
}
