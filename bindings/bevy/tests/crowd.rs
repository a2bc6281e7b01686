//! A crowd in a headless Bevy app: 200 characters of the shipped walk (heading-relative), each
//! told its own turn, each following it (a left turn turns left, a right turn right, straight
//! stays nearly straight); two characters with the same seed and steering move alike whatever
//! the crowd around them, every character has joined and moved, and ten despawned half-way have
//! left the crowd.

mod common;

use bevy_app::App;
use bevy_math::Vec3;
use bevy_transform::components::{GlobalTransform, Transform};
use sinmdm::StreamOptions;
use sinmdm::steer::SteerLimits;
use sinmdm_bevy::{CrowdCharacter, CrowdOptions, EngineFrame, MotionCrowd, MotionModel, Steering};

use common::{BEVY_FPS, headless_app, model_path, signed_angle};

const CHARACTERS: usize = 200;

/// Character `i`'s turn in radians per second: left, straight or right.
fn turn_of(i: usize) -> f32 {
    [0.9, 0.0, -0.9][i % 3]
}

#[test]
fn two_hundred_characters_each_follow_their_own_path() {
    let model = MotionModel::open(model_path("human_walk_cmu.onnx"), Some(2)).unwrap();
    let limits = SteerLimits::of(model.metadata()).expect("the walk is heading-relative");
    let frame = EngineFrame::of(model.metadata(), None).unwrap();
    let speed = Steering::clip_speed(&frame, &limits);
    let (mut app, crowd, characters) = crowd_app(&model, speed);

    let frames = (4.0 * BEVY_FPS) as usize;
    let mut roots: Vec<Vec<Vec3>> = vec![Vec::new(); CHARACTERS];
    let mut characters = characters;
    let leaving = 10;
    for frame in 0..frames {
        if frame == frames / 2 {
            // The last ten walkers are despawned half-way: they leave the crowd.
            for &c in &characters[CHARACTERS - leaving..] {
                app.world_mut().entity_mut(c).despawn();
            }
            characters.truncate(CHARACTERS - leaving);
        }
        app.update();
        let world = app.world();
        for (k, &c) in characters.iter().enumerate() {
            let character = world.get::<CrowdCharacter>(c).unwrap();
            let root = world
                .get::<GlobalTransform>(character.joints()[0])
                .unwrap()
                .translation();
            roots[k].push(root);
        }
    }
    let world = app.world();
    let motion = world.get::<MotionCrowd>(crowd).unwrap();
    assert!(motion.error().is_none(), "{:?}", motion.error());
    assert_eq!(motion.characters(), CHARACTERS - leaving);
    println!(
        "{CHARACTERS} characters, {frames} frames: {} requests, the slowest {:.3} s",
        motion.requests(),
        motion.slowest_request()
    );
    for (k, &c) in characters.iter().enumerate() {
        let character = world.get::<CrowdCharacter>(c).unwrap();
        assert!(character.id().is_some(), "character {k} never joined");
        assert!(
            character.steering_note().is_none(),
            "{:?}",
            character.steering_note()
        );
        assert_eq!(character.frames_shown(), frames as u64);
    }
    // The turn over the last 3 s: the direction of travel from the first half-second of that
    // span to its last (2.5 s apart).
    let heading = |r: &[Vec3], from: usize, to: usize| {
        let d = r[to] - r[from];
        f64::from(d.x).atan2(f64::from(d.z))
    };
    let half = (BEVY_FPS / 2.0) as usize;
    let start = frames - 6 * half;
    let mut turned = [Vec::new(), Vec::new(), Vec::new()];
    roots.truncate(CHARACTERS - leaving);
    for (k, r) in roots.iter().enumerate() {
        let moved = (r[frames - 1] - r[start]).length();
        // Asked to walk at the clip's speed for 3 s: at least half of that.
        assert!(moved > 1.5 * speed, "character {k} moved only {moved:.2} m");
        let before = heading(r, start, start + half);
        let after = heading(r, frames - 1 - half, frames - 1);
        turned[k % 3].push(signed_angle(after, before));
    }
    let (left, straight, right) = (&turned[0], &turned[1], &turned[2]);
    println!(
        "turns (rad): left {:.2}..{:.2}, straight {:.2}..{:.2}, right {:.2}..{:.2}",
        min(left),
        max(left),
        min(straight),
        max(straight),
        min(right),
        max(right)
    );
    // Told 0.9 rad/s, 2.25 rad between the two headings: each left turner turns more than 1 rad
    // left, each right turner more than 1 rad right, and no straight walker turns 1 rad.
    assert!(min(left) > 1.0, "a left turner turned {:.2}", min(left));
    assert!(max(right) < -1.0, "a right turner turned {:.2}", max(right));
    assert!(
        straight.iter().all(|t| t.abs() < 1.0),
        "a straight walker turned {:.2}..{:.2}",
        min(straight),
        max(straight)
    );
    // The same seed and steering: the same motion, wherever the two stand in the crowd.
    let relative = |k: usize| -> Vec<Vec3> { roots[k].iter().map(|p| *p - roots[k][0]).collect() };
    let apart = |a: usize, b: usize| -> f32 {
        relative(a)
            .iter()
            .zip(relative(b))
            .map(|(p, q)| (*p - q).length())
            .fold(0.0, f32::max)
    };
    // (Only the f32 rounding of their places apart: both are placed unturned.)
    assert!(apart(0, 3) < 1e-4, "{}", apart(0, 3));
    assert!(apart(0, 6) > 0.05, "{}", apart(0, 6));
}

/// A headless app stepping 1/60 s a frame with a crowd of [`CHARACTERS`] walkers of `model`, each
/// told to walk at `speed` turning at [`turn_of`] its index: the app, the crowd and the
/// characters.
fn crowd_app(
    model: &MotionModel,
    speed: f32,
) -> (App, bevy_ecs::entity::Entity, Vec<bevy_ecs::entity::Entity>) {
    let mut app = headless_app();
    let options = CrowdOptions::for_fps(model.fps());
    let world = app.world_mut();
    let mut commands = world.commands();
    let crowd = sinmdm_bevy::spawn_crowd(&mut commands, model, options).unwrap();
    let mut characters = Vec::new();
    for i in 0..CHARACTERS {
        // Characters 0 and 3 share a seed and a turn; the rest differ.
        let seed = if i == 3 { 0 } else { i as u64 };
        let stream = StreamOptions {
            seed,
            steps: Some(4),
            block_frames: Some(45),
            ..StreamOptions::default()
        };
        let place = Transform::from_xyz(3.0 * (i % 20) as f32, 0.0, 3.0 * (i / 20) as f32);
        let c =
            sinmdm_bevy::spawn_crowd_character(&mut commands, crowd, model, stream, None, place)
                .unwrap();
        commands.entity(c).insert(Steering::Velocity {
            forward: speed,
            turn: turn_of(i),
        });
        characters.push(c);
    }
    world.flush();

    (app, crowd, characters)
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}
