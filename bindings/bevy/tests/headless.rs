//! The plugin in a headless Bevy app (task pools, time with a manual frame time, transform
//! propagation) on the shipped models: the joints' global transforms against forward kinematics
//! computed here from the same seed's stream, frames that never wait after the first, and a
//! steering command that turns the character.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use bevy_app::{App, TaskPoolPlugin};
use bevy_ecs::prelude::*;
use bevy_math::{Quat, Vec3};
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::{GlobalTransform, Transform};
use sinmdm::steer::SteerLimits;
use sinmdm::{Pose, Stream, StreamOptions};
use sinmdm_bevy::{CharacterOptions, MotionCharacter, MotionModel, SinmdmPlugin, Steering};

const BEVY_FPS: f64 = 60.0;

fn model_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../onnx-models")
        .join(name)
}

/// A headless app stepping 1/60 s a frame, with a character of `model` at `place`.
fn app_with(model: &MotionModel, options: CharacterOptions, place: Transform) -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins((
        TaskPoolPlugin::default(),
        TimePlugin,
        TransformPlugin,
        SinmdmPlugin,
    ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / BEVY_FPS,
    )));
    let world = app.world_mut();
    let mut commands = world.commands();
    let character = sinmdm_bevy::spawn_character(&mut commands, model, options, place)
        .expect("the character spawns");
    world.flush();
    (app, character)
}

/// A rotation matrix (rows) of a unit quaternion, in f64.
fn matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [x, y, z, w] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] = (0..3).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    m
}

fn apply(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| m[r][k] * v[k]).sum())
}

/// Spherical interpolation along the shorter arc, written out (f64).
fn slerp(a: [f64; 4], b: [f64; 4], t: f64) -> [f64; 4] {
    let mut dot: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    let b = if dot < 0.0 {
        dot = -dot;
        b.map(|v| -v)
    } else {
        b
    };
    if dot > 0.9995 {
        let q: [f64; 4] = [0, 1, 2, 3].map(|i| a[i] + (b[i] - a[i]) * t);
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        return q.map(|v| v / n);
    }
    let theta = dot.clamp(-1.0, 1.0).acos();
    let (wa, wb) = (
        ((1.0 - t) * theta).sin() / theta.sin(),
        (t * theta).sin() / theta.sin(),
    );
    [0, 1, 2, 3].map(|i| wa * a[i] + wb * b[i])
}

/// World positions of every joint of the pose a fraction `t` from `a` to `b`, by forward
/// kinematics in f64: the character's placement, then the file-to-Bevy turn and the unit scale
/// on the top joints, then each joint's local transform.
fn world_positions(
    parents: &[Option<usize>],
    a: &Pose,
    b: &Pose,
    t: f64,
    place: (&[[f64; 3]; 3], [f64; 3]),
    turn: &[[f64; 3]; 3],
    scale: f64,
) -> Vec<[f64; 3]> {
    let f = |v: [f32; 3]| v.map(f64::from);
    let mut rotations: Vec<[[f64; 3]; 3]> = Vec::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    for (j, parent) in parents.iter().enumerate() {
        let qa = a.rotations[j];
        let qb = b.rotations[j];
        let q = slerp(
            [qa.x, qa.y, qa.z, qa.w].map(f64::from),
            [qb.x, qb.y, qb.z, qb.w].map(f64::from),
            t,
        );
        let (ta, tb) = (f(a.translations[j]), f(b.translations[j]));
        let local_t: [f64; 3] = [0, 1, 2].map(|i| (ta[i] + (tb[i] - ta[i]) * t) * scale);
        let (parent_rot, parent_pos, local_t, local_r) = match parent {
            Some(p) => (rotations[*p], positions[*p], local_t, matrix(q)),
            None => (
                *place.0,
                place.1,
                apply(turn, local_t),
                mul(turn, &matrix(q)),
            ),
        };
        let offset = apply(&parent_rot, local_t);
        positions.push([0, 1, 2].map(|i| parent_pos[i] + offset[i]));
        rotations.push(mul(&parent_rot, &local_r));
    }
    positions
}

#[test]
fn joints_follow_the_streams_forward_kinematics_and_frames_do_not_wait() {
    let model = MotionModel::open(model_path("human_walk_cmu.onnx"), Some(1)).unwrap();
    let metadata = model.with(|m| m.metadata().clone());
    let fps = metadata.layout.fps;
    let stream_options = StreamOptions {
        seed: 7,
        // Two-second blocks, so that four seconds cross block seams.
        block_frames: Some(60),
        ..StreamOptions::default()
    };
    let options = CharacterOptions {
        stream: stream_options.clone(),
        ..CharacterOptions::for_fps(fps)
    };
    let place = Transform::from_xyz(1.0, 0.0, -2.0).with_rotation(Quat::from_rotation_y(0.5));
    let (mut app, character) = app_with(&model, options, place);

    // Paced as a game's frames are: each update at its time on the wall clock.
    let frames = 240;
    let start = Instant::now();
    let mut seen = Vec::new();
    for k in 0..frames {
        let due = start + Duration::from_secs_f64(k as f64 / BEVY_FPS);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        app.update();
        let world = app.world();
        let c = world.get::<MotionCharacter>(character).unwrap();
        assert!(c.error().is_none(), "{:?}", c.error());
        let joints: Vec<Vec3> = c
            .joints()
            .iter()
            .map(|&e| world.get::<GlobalTransform>(e).unwrap().translation())
            .collect();
        seen.push((c.clock().unwrap(), joints));
    }
    let c = app.world().get::<MotionCharacter>(character).unwrap();
    assert_eq!(
        c.waits(),
        &[0],
        "only the first frame may wait for motion (machine too slow? ahead {} frames)",
        c.ahead_frames()
    );
    // The clock moves by the frame time: half a model frame per Bevy frame at 30 fps.
    let (first, last) = (seen[0].0, seen[frames - 1].0);
    assert_eq!(first, 0.0);
    let expected_last = (frames - 1) as f64 / BEVY_FPS * fps;
    assert!(
        (last - expected_last).abs() < 1e-3,
        "{last} vs {expected_last}"
    );

    // The same seed's stream, read in one go (a stream's motion does not depend on chunks).
    let needed = last.floor() as usize + 2;
    let poses = model.with(|m| {
        let mut stream = Stream::new(&metadata, stream_options).unwrap();
        stream.next(m, needed).unwrap().poses()
    });
    let parents: Vec<Option<usize>> = metadata
        .layout
        .skeleton
        .joints
        .iter()
        .map(|j| j.parent)
        .collect();
    let turn = metadata.layout.up.canonical_from_file().0;
    let scale = f64::from(c.frame().metres_per_unit);
    let height = metadata.layout.skeleton_height * scale;
    let place_rot = matrix(
        [
            place.rotation.x,
            place.rotation.y,
            place.rotation.z,
            place.rotation.w,
        ]
        .map(f64::from),
    );
    let place_pos = place.translation.to_array().map(f64::from);
    let mut worst = 0.0f64;
    for (clock, joints) in &seen {
        let base = clock.floor() as usize;
        let t = clock - base as f64;
        let expected = world_positions(
            &parents,
            &poses[base],
            &poses[base + 1],
            t,
            (&place_rot, place_pos),
            &turn,
            scale,
        );
        for (got, want) in joints.iter().zip(&expected) {
            let d = (0..3)
                .map(|i| (f64::from(got[i]) - want[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(d);
        }
    }
    eprintln!(
        "worst joint distance {:.3e} m ({:.3e} x height), ahead {} frames",
        worst,
        worst / height,
        c.ahead_frames()
    );
    assert!(
        worst <= 1e-5 * height,
        "joints {worst} m from forward kinematics (height {height} m)"
    );
}

/// Directions of travel on the ground (radians about up) of the root, one per Bevy frame, each
/// over the half second around it.
fn travel_headings(roots: &[Vec3]) -> Vec<Option<f64>> {
    let half = (BEVY_FPS / 4.0) as usize;
    (0..roots.len())
        .map(|k| {
            let (a, b) = (roots.get(k.checked_sub(half)?)?, roots.get(k + half)?);
            let d = *b - *a;
            (d.x.hypot(d.z) > 1e-3).then(|| f64::from(d.x).atan2(f64::from(d.z)))
        })
        .collect()
}

fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

#[test]
fn a_steering_command_turns_the_character_within_its_reach() {
    let model = MotionModel::open(model_path("human_zombie_walk_fair.onnx"), Some(1)).unwrap();
    let metadata = model.with(|m| m.metadata().clone());
    let fps = metadata.layout.fps;
    let limits = SteerLimits::of(&metadata).expect("the zombie walk is heading-relative");
    let options = CharacterOptions {
        stream: StreamOptions {
            seed: 3,
            block_frames: Some(60),
            ..StreamOptions::default()
        },
        ..CharacterOptions::for_fps(fps)
    };
    let run = |turn_at: Option<usize>, frames: usize| {
        let (mut app, character) = app_with(&model, options.clone(), Transform::IDENTITY);
        let metres = f64::from(
            app.world()
                .get::<MotionCharacter>(character)
                .unwrap()
                .frame()
                .metres_per_unit,
        );
        let speed = ((limits.forward.0 + limits.forward.1) / 2.0 * metres) as f32;
        app.world_mut()
            .entity_mut(character)
            .insert(Steering::Velocity {
                forward: speed,
                turn: 0.0,
            });
        let mut roots = Vec::new();
        let mut reach = 0;
        for k in 0..frames {
            if Some(k) == turn_at {
                reach = app
                    .world()
                    .get::<MotionCharacter>(character)
                    .unwrap()
                    .steering_reach();
                app.world_mut()
                    .entity_mut(character)
                    .insert(Steering::Velocity {
                        forward: speed,
                        turn: 0.8,
                    });
            }
            app.update();
            let world = app.world();
            let c = world.get::<MotionCharacter>(character).unwrap();
            assert!(c.error().is_none(), "{:?}", c.error());
            assert!(c.steering_note().is_none());
            roots.push(
                world
                    .get::<GlobalTransform>(c.joints()[0])
                    .unwrap()
                    .translation(),
            );
        }
        (travel_headings(&roots), reach)
    };
    let turn_at = (4.0 * BEVY_FPS) as usize;
    let frames = turn_at + (8.0 * BEVY_FPS) as usize;
    let (straight, _) = run(None, frames);
    let (turned, reach) = run(Some(turn_at), frames);
    // The model frames a change can take to show, in Bevy frames.
    let reach_bevy = (reach as f64 / fps * BEVY_FPS).ceil() as usize;
    assert!(reach > 0 && turn_at + reach_bevy < frames, "reach {reach}");
    // Up to the change both runs are the same motion.
    for k in 0..turn_at {
        if let (Some(a), Some(b)) = (straight[k], turned[k]) {
            assert!(angle_between(a, b) < 1e-3, "frame {k}: {a} vs {b}");
        }
    }
    // After it, the steered run's travel leaves the straight run's once the commands reach
    // the turn: within the reach, plus the quarter second either side over which a direction
    // of travel is measured here.
    let departs_by = |degrees: f64| {
        (turn_at..frames).find(|&k| match (straight[k], turned[k]) {
            (Some(a), Some(b)) => angle_between(a, b) > degrees.to_radians(),
            _ => false,
        })
    };
    let departs = departs_by(5.0).expect("the steered character never turned away");
    let turned_away = departs_by(45.0).expect("the steered character never turned 45 degrees");
    eprintln!(
        "steering reach {reach} model frames ({reach_bevy} Bevy frames); travel 5 degrees away after {} Bevy frames, 45 degrees after {}",
        departs - turn_at,
        turned_away - turn_at
    );
    let window = (BEVY_FPS / 4.0) as usize;
    assert!(
        departs <= turn_at + reach_bevy + window,
        "turned after {} Bevy frames, reach {reach_bevy}",
        departs - turn_at
    );
}
