//! The plugin in a headless Bevy app paced as a game's frames are (task pools, time with a
//! manual frame time of 1/60 s, transform propagation), on the shipped CMU walk (+Y up) and
//! zombie walk (+Z up): every joint's global transform against forward kinematics computed here
//! from the same seed's stream, and no frame after the first waiting for motion. One test, the
//! models one after the other, so nothing else competes for the compute pool.

mod common;

use std::time::{Duration, Instant};

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_math::{Quat, Vec3};
use bevy_transform::components::{GlobalTransform, Transform};
use sinmdm::{Pose, Stream, StreamOptions};
use sinmdm_bevy::{CharacterOptions, MotionCharacter, MotionModel};

use common::{BEVY_FPS, app_with, matrix, model_path, world_positions};

#[test]
fn joints_follow_the_streams_forward_kinematics_and_frames_do_not_wait() {
    for name in ["human_walk_cmu.onnx", "human_zombie_walk_fair.onnx"] {
        follows_forward_kinematics(name);
    }
}

fn follows_forward_kinematics(name: &str) {
    let model = MotionModel::open(model_path(name), Some(1)).unwrap();
    let metadata = model.metadata().clone();
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
    let seen = paced_frames(&mut app, character, frames);
    let c = app.world().get::<MotionCharacter>(character).unwrap();
    assert_eq!(
        c.waits(),
        &[0],
        "{name}: only the first frame may wait for motion (machine too slow? ahead {} frames)",
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
    let worst = worst_joint_distance(&seen, &poses, &parents, &turn, scale, &place);
    eprintln!(
        "{name}: worst joint distance {:.3e} m ({:.3e} x height), ahead {} frames",
        worst,
        worst / height,
        c.ahead_frames()
    );
    assert!(
        worst <= 1e-5 * height,
        "joints {worst} m from forward kinematics (height {height} m)"
    );
}

/// Updates `app` `frames` times, each at its time on the wall clock, checking that the character
/// has no error: the character's clock and joint positions after each update.
fn paced_frames(app: &mut App, character: Entity, frames: usize) -> Vec<(f64, Vec<Vec3>)> {
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
    seen
}

/// The largest distance of any joint in `seen` from its position by forward kinematics of the
/// stream's `poses`, interpolated at the clock it was seen at, with the character at `place`.
fn worst_joint_distance(
    seen: &[(f64, Vec<Vec3>)],
    poses: &[Pose],
    parents: &[Option<usize>],
    turn: &[[f64; 3]; 3],
    scale: f64,
    place: &Transform,
) -> f64 {
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
    for (clock, joints) in seen {
        let base = clock.floor() as usize;
        let t = clock - base as f64;
        let expected = world_positions(
            parents,
            &poses[base],
            &poses[base + 1],
            t,
            (&place_rot, place_pos),
            turn,
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
    worst
}
