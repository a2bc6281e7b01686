//! Many characters of one model driven by one [`sinmdm::Crowd`]: their blocks made together,
//! one request on the compute pool for the whole crowd, each character the same motion as a
//! stream of its own.
//!
//! [`spawn_crowd`] makes the crowd's entity ([`MotionCrowd`]); [`spawn_crowd_character`] a
//! skeleton whose entity holds a [`CrowdCharacter`] of that crowd, steered by a [`Steering`] on
//! it. Every frame the plugin advances each character's clock; when any character has fewer
//! than its chunk plus [`CrowdOptions::ahead_frames`] frames ready and the crowd is idle, the
//! steering of every character that needs frames is queued on its stream and one request makes
//! their next chunks. A despawned character leaves the crowd at its next request.

use std::sync::Mutex;
use std::time::Instant;

use bevy_ecs::prelude::*;
use bevy_tasks::AsyncComputeTaskPool;
use bevy_transform::components::Transform;
use sinmdm::steer::{SteerFrame, SteerLimits};
use sinmdm::{CharacterId, Crowd, Pose, StreamOptions, TaskError};

use crate::character::{MotionModel, spawn_skeleton};
use crate::frame::EngineFrame;
use crate::playback::{Frames, needed, on_show};
use crate::steering::Steering;

/// How a crowd's characters are played.
#[derive(Debug, Clone)]
pub struct CrowdOptions {
    /// Frames each character is handed per request.
    pub chunk_frames: usize,
    /// Frames kept ready past the one on show, beyond a chunk; a request starts when a character
    /// has fewer.
    pub ahead_frames: usize,
    /// Metres per file unit; `None` guesses from the figure's height.
    pub metres_per_unit: Option<f64>,
    /// Whether the pose between two model frames is interpolated.
    pub interpolate: bool,
}

impl CrowdOptions {
    /// Options for a model at `fps`: half-second chunks, a second ready ahead, interpolated.
    pub fn for_fps(fps: f64) -> CrowdOptions {
        CrowdOptions {
            chunk_frames: (fps / 2.0).ceil().max(1.0) as usize,
            ahead_frames: fps.ceil().max(1.0) as usize,
            metres_per_unit: None,
            interpolate: true,
        }
    }
}

/// What a crowd's request gives back: each member's new frames, or why there are none.
type Maker = crate::playback::Maker<Engine, Result<Vec<(CharacterId, Vec<Pose>)>, TaskError>>;

/// The model and the crowd on it, moved to the compute pool for each request.
struct Engine {
    model: MotionModel,
    crowd: Crowd,
}

/// A crowd of one model (on an entity of its own).
#[derive(Component)]
pub struct MotionCrowd {
    /// In a mutex only to make the component `Sync`; reached through `&mut self`.
    maker: Mutex<Maker>,
    metadata: std::sync::Arc<sinmdm::ModelMetadata>,
    frame: EngineFrame,
    options: CrowdOptions,
    /// Characters waiting to join (their entity and stream options), joined when the crowd is
    /// idle.
    joining: Vec<(Entity, StreamOptions)>,
    requests: u64,
    members: usize,
    slowest_request: f64,
    error: Option<String>,
}

impl MotionCrowd {
    /// Characters in the crowd as of its last request (a despawned character leaves then).
    pub fn characters(&self) -> usize {
        self.members
    }

    /// Requests made so far (each makes the next chunk of every character that needs one).
    pub fn requests(&self) -> u64 {
        self.requests
    }

    /// The longest request so far, in seconds.
    pub fn slowest_request(&self) -> f64 {
        self.slowest_request
    }

    /// Why the crowd stopped, if it did (its characters then hold their last poses).
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn maker_mut(&mut self) -> &mut Maker {
        self.maker.get_mut().unwrap_or_else(|p| p.into_inner())
    }
}

/// A character of a [`MotionCrowd`] (on the entity that parents its top joints).
#[derive(Component)]
pub struct CrowdCharacter {
    crowd: Entity,
    id: Option<CharacterId>,
    joints: Vec<Entity>,
    parents: Vec<Option<usize>>,
    clock: Option<f64>,
    frames: Frames,
    /// Frames handed to this character so far, and frames given a steering command.
    received: usize,
    commanded: usize,
    frames_shown: u64,
    waits: Vec<u64>,
    steering_note: Option<String>,
}

impl CrowdCharacter {
    /// The joint entities, in the model's skeleton order.
    pub fn joints(&self) -> &[Entity] {
        &self.joints
    }

    /// The character's number in its crowd (`None` until it has joined).
    pub fn id(&self) -> Option<CharacterId> {
        self.id
    }

    /// The Bevy frames (counted from the character's first) that had to wait for motion.
    pub fn waits(&self) -> &[u64] {
        &self.waits
    }

    /// Bevy frames shown so far.
    pub fn frames_shown(&self) -> u64 {
        self.frames_shown
    }

    /// What became of a [`Steering`] that could not be followed as given, if any.
    pub fn steering_note(&self) -> Option<&str> {
        self.steering_note.as_deref()
    }
}

/// Spawns a crowd of `model` with `options`; returns its entity, or why not (a unit scale that is
/// not a positive number).
pub fn spawn_crowd(
    commands: &mut Commands,
    model: &MotionModel,
    options: CrowdOptions,
) -> Result<Entity, TaskError> {
    let metadata = model.metadata();
    let frame = EngineFrame::of(metadata, options.metres_per_unit).map_err(TaskError::Stream)?;
    Ok(commands
        .spawn(MotionCrowd {
            maker: Mutex::new(Maker::Idle(Box::new(Engine {
                model: model.clone(),
                crowd: Crowd::new(metadata),
            }))),
            metadata: std::sync::Arc::new(metadata.clone()),
            frame,
            options,
            joining: Vec::new(),
            requests: 0,
            members: 0,
            slowest_request: 0.0,
            error: None,
        })
        .id())
}

/// Spawns a character of the crowd at `crowd` (from [`spawn_crowd`], of `model`): a skeleton
/// whose entity holds a [`CrowdCharacter`] at `transform`, joining the crowd with `stream`'s
/// options when the crowd is next idle (options the stream refuses stop the crowd with that
/// error). Returns the character's entity.
pub fn spawn_crowd_character(
    commands: &mut Commands,
    crowd: Entity,
    model: &MotionModel,
    stream: StreamOptions,
    metres_per_unit: Option<f64>,
    transform: Transform,
) -> Result<Entity, TaskError> {
    let metadata = model.metadata();
    let frame = EngineFrame::of(metadata, metres_per_unit).map_err(TaskError::Stream)?;
    let skeleton = &metadata.layout.skeleton;
    let (character, joints) = spawn_skeleton(commands, skeleton, &frame, transform);
    commands.entity(character).insert(CrowdCharacter {
        crowd,
        id: None,
        joints,
        parents: skeleton.joints.iter().map(|j| j.parent).collect(),
        clock: None,
        frames: Frames::default(),
        received: 0,
        commanded: 0,
        frames_shown: 0,
        waits: Vec::new(),
        steering_note: None,
    });
    commands.queue(move |world: &mut World| {
        if let Some(mut motion) = world.get_mut::<MotionCrowd>(crowd) {
            motion.joining.push((character, stream));
        }
    });
    Ok(character)
}

/// Advances every crowd character's clock, hands out finished requests, starts the next where a
/// character runs short, and writes the poses.
pub(crate) fn drive_crowds(
    time: Res<bevy_time::Time>,
    mut crowds: Query<(Entity, &mut MotionCrowd)>,
    mut characters: Query<(Entity, &mut CrowdCharacter, Option<&Steering>)>,
    mut transforms: Query<&mut Transform, (Without<CrowdCharacter>, Without<MotionCrowd>)>,
) {
    let seconds = time.delta_secs_f64();
    for (crowd_entity, mut crowd) in &mut crowds {
        let fps = crowd.metadata.layout.fps;
        let options = crowd.options.clone();
        let mut short = false;
        for (_, mut c, _) in &mut characters {
            if c.crowd != crowd_entity {
                continue;
            }
            let clock = c.clock.map_or(0.0, |t| t + seconds * fps);
            c.clock = Some(clock);
            short |= c.frames.ready_past(clock.floor() as usize)
                < options.chunk_frames + options.ahead_frames;
        }
        collect(&mut crowd, &mut characters, crowd_entity, false);
        if short || !crowd.joining.is_empty() {
            request(&mut crowd, &mut characters, crowd_entity);
        }
        // A character without the frames it shows now waits for them (recorded in its waits).
        let mut waited = false;
        while crowd.error.is_none() {
            let mut short_now = false;
            for (_, mut c, _) in &mut characters {
                if c.crowd != crowd_entity || c.id.is_none() {
                    continue;
                }
                let (base, frac) = on_show(c.clock);
                if c.frames.end() < needed(base, frac, options.interpolate) {
                    short_now = true;
                    if !waited {
                        let shown = c.frames_shown;
                        c.waits.push(shown);
                    }
                }
            }
            if !short_now {
                break;
            }
            waited = true;
            collect(&mut crowd, &mut characters, crowd_entity, true);
            request(&mut crowd, &mut characters, crowd_entity);
            collect(&mut crowd, &mut characters, crowd_entity, true);
        }
        for (_, mut c, _) in &mut characters {
            if c.crowd != crowd_entity {
                continue;
            }
            let (base, frac) = on_show(c.clock);
            if let Some(pose) = c.frames.show(base, frac, options.interpolate) {
                crowd
                    .frame
                    .write_pose(&pose, &c.joints, &c.parents, &mut transforms);
            }
            c.frames_shown += 1;
        }
    }
}

/// Takes the frames of a finished request (waiting for it when `wait`).
fn collect(
    crowd: &mut MotionCrowd,
    characters: &mut Query<(Entity, &mut CrowdCharacter, Option<&Steering>)>,
    crowd_entity: Entity,
    wait: bool,
) {
    let Some((engine, result, seconds)) = crowd.maker_mut().finished(wait) else {
        return;
    };
    crowd.slowest_request = crowd.slowest_request.max(seconds);
    match result {
        Ok(made) => {
            for (_, mut c, _) in characters.iter_mut() {
                if c.crowd != crowd_entity {
                    continue;
                }
                if let Some(id) = c.id
                    && let Some((_, poses)) = made.iter().find(|(m, _)| *m == id)
                {
                    c.received += poses.len();
                    c.frames.extend(poses.iter().cloned());
                }
            }
            *crowd.maker_mut() = Maker::Idle(engine);
        }
        Err(e) => {
            crowd.error = Some(e.to_string());
            *crowd.maker_mut() = Maker::Stopped;
        }
    }
}

/// Starts the next request if the crowd is idle: characters waiting join, every character's
/// steering is queued for the frames its next blocks may reach, and one task makes a chunk for
/// every character short of frames.
fn request(
    crowd: &mut MotionCrowd,
    characters: &mut Query<(Entity, &mut CrowdCharacter, Option<&Steering>)>,
    crowd_entity: Entity,
) {
    let Some(mut engine) = crowd.maker_mut().take_idle() else {
        return;
    };
    let options = crowd.options.clone();
    let limits = SteerLimits::of(&crowd.metadata);
    for (entity, stream) in std::mem::take(&mut crowd.joining) {
        match engine.crowd.join(stream) {
            Ok(id) => {
                if let Ok((_, mut c, _)) = characters.get_mut(entity) {
                    c.id = Some(id);
                }
            }
            Err(e) => crowd.error = Some(format!("a character could not join: {e}")),
        }
    }
    // Characters whose entities are gone leave the crowd.
    let mut present: Vec<CharacterId> = characters
        .iter()
        .filter(|(_, c, _)| c.crowd == crowd_entity)
        .filter_map(|(_, c, _)| c.id)
        .collect();
    present.sort_unstable();
    let gone: Vec<CharacterId> = engine
        .crowd
        .ids()
        .filter(|id| present.binary_search(id).is_err())
        .collect();
    for id in gone {
        engine.crowd.leave(id);
    }
    crowd.members = engine.crowd.len();
    let chunk = options.chunk_frames.max(1);
    let mut wanted = Vec::new();
    for (_, mut c, steering) in characters.iter_mut() {
        let Some(id) = c.id.filter(|_| c.crowd == crowd_entity) else {
            continue;
        };
        let (base, _) = on_show(c.clock);
        if c.frames.ready_past(base) >= chunk + options.ahead_frames {
            continue;
        }
        wanted.push(id);
        let Some(stream) = engine.crowd.character_mut(id) else {
            continue;
        };
        if let Some(limits) = &limits {
            // The blocks `next(chunk)` starts reach the next multiple of B past the frames
            // made final, plus R (as for a character of its own).
            let sizes = stream.sizes();
            let block = sizes.block.max(1);
            let until = (c.received + chunk).div_ceil(block) * block + sizes.ramp;
            if until > c.commanded {
                let command = match steering.map(|s| s.command(&crowd.frame, limits)) {
                    Some(Ok(command)) => command,
                    Some(Err(why)) => {
                        c.steering_note = Some(why);
                        SteerFrame::Free
                    }
                    None => SteerFrame::Free,
                };
                match stream.steer(&vec![command; until - c.commanded]) {
                    Ok(()) => c.commanded = until,
                    Err(e) => c.steering_note = Some(e.to_string()),
                }
            }
        }
    }
    if wanted.is_empty() {
        *crowd.maker_mut() = Maker::Idle(engine);
        return;
    }
    crowd.requests += 1;
    let task = AsyncComputeTaskPool::get().spawn(async move {
        let started = Instant::now();
        let model = engine.model.clone();
        let result = model.with(|m| make_chunks(&mut engine.crowd, m, &wanted, chunk));
        (engine, result, started.elapsed().as_secs_f64())
    });
    *crowd.maker_mut() = Maker::Busy(task);
}

/// The next `chunk` frames of each character in `wanted`, their blocks made together first.
fn make_chunks(
    crowd: &mut Crowd,
    model: &mut sinmdm::Model,
    wanted: &[CharacterId],
    chunk: usize,
) -> Result<Vec<(CharacterId, Vec<Pose>)>, TaskError> {
    // Only the wanted characters are stepped, so a character's blocks start only when its own
    // steering has been queued for them.
    crowd.prepare_characters(model, wanted, usize::MAX, chunk)?;
    wanted
        .iter()
        .filter_map(|&id| {
            let stream = crowd.character_mut(id)?;
            Some(stream.next(model, chunk).map(|c| (id, c.poses())))
        })
        .collect()
}
