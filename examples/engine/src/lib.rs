//! An engine's use of the runtime, through the items at the root of `sinmdm` and nothing else:
//! open a shipped model, list its skeleton, generate a crowd a few steps at a time (as a game
//! would across frames), and read engine poses.

use std::error::Error;
use std::path::Path;

use sinmdm::{Model, ModelOptions, Pose, Request, Task};

/// One generated character: its joint names and a pose per frame.
pub struct Character {
    /// Joint names, in the order of every pose's rotations and translations.
    pub joints: Vec<String>,
    /// Frames per second of the poses.
    pub fps: f64,
    /// One pose per frame.
    pub poses: Vec<Pose>,
}

/// Generates `count` characters of `seconds` each from the model at `model_path`, stepping the
/// sampler by hand with at most `steps_per_tick` denoising steps per call of `tick` (where a
/// game would yield to its frame loop).
pub fn generate_crowd(
    model_path: &Path,
    count: usize,
    seconds: f64,
    seed: u64,
    steps_per_tick: usize,
    mut tick: impl FnMut(usize, usize),
) -> Result<Vec<Character>, Box<dyn Error>> {
    let mut model = Model::open(model_path, &ModelOptions { threads: Some(1) })?;
    let joints: Vec<String> = model
        .skeleton()
        .joints
        .iter()
        .map(|j| j.name.clone())
        .collect();
    let request = Request {
        task: Task::Generate {
            frames: (seconds * model.fps()).round() as usize,
        },
        count,
        seed,
        steps: Some(20),
        feet: sinmdm::Feet::default(),
        method: Default::default(),
    };
    let plan = sinmdm::plan(model.metadata(), &request)?;
    let mut sampler = plan.sampler()?;
    while !sampler.is_finished() {
        for _ in 0..steps_per_tick.max(1) {
            sampler.step(&mut model)?;
        }
        tick(sampler.done(), sampler.steps());
    }
    let generated = plan.finish(sampler);
    (0..generated.count())
        .map(|i| {
            Ok(Character {
                joints: joints.clone(),
                fps: model.fps(),
                poses: generated.poses(i)?,
            })
        })
        .collect()
}
