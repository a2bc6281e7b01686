//! A character from the shipped zombie walk, steered round a circle: a headless app at 60 fps
//! that prints where the character is each second. The zombie rig's unit is not written in its
//! file; 44 units tall, it is guessed as centimetres (set `CharacterOptions::metres_per_unit`
//! when you know better). A game adds its own plugins (rendering,
//! input) and a mesh skinned to the joint entities; the sinmdm part is the same.
//!
//! `cargo run --release --example walk_in_circles -- [MODEL] [SECONDS]`

use std::time::Duration;

use bevy_app::{App, AppExit, ScheduleRunnerPlugin, Startup, TaskPoolPlugin, Update};
use bevy_ecs::prelude::*;
use bevy_time::{Time, TimePlugin};
use bevy_transform::TransformPlugin;
use bevy_transform::components::{GlobalTransform, Transform};
use sinmdm_bevy::{CharacterOptions, MotionCharacter, MotionModel, SinmdmPlugin, Steering};

#[derive(Resource)]
struct Settings {
    model: MotionModel,
    seconds: f64,
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../onnx-models/human_zombie_walk_fair.onnx"
        )
        .into()
    });
    let seconds = args.next().and_then(|s| s.parse().ok()).unwrap_or(10.0);
    let model = MotionModel::open(&path, Some(1)).unwrap_or_else(|e| {
        eprintln!("cannot open {path}: {e}");
        std::process::exit(1);
    });
    App::new()
        .add_plugins((
            TaskPoolPlugin::default(),
            TimePlugin,
            TransformPlugin,
            ScheduleRunnerPlugin::run_loop(Duration::from_secs_f64(1.0 / 60.0)),
            SinmdmPlugin,
        ))
        .insert_resource(Settings { model, seconds })
        .add_systems(Startup, spawn)
        .add_systems(Update, report)
        .run();
}

fn spawn(mut commands: Commands, settings: Res<Settings>) {
    let fps = settings.model.with(|m| m.fps());
    let options = CharacterOptions {
        // Two-second blocks: a steering change shows within about five seconds.
        stream: sinmdm::StreamOptions {
            block_frames: Some((2.0 * fps) as usize),
            ..Default::default()
        },
        ..CharacterOptions::for_fps(fps)
    };
    let character =
        sinmdm_bevy::spawn_character(&mut commands, &settings.model, options, Transform::IDENTITY)
            .expect("the model makes a stream");
    // The clip's own speed, a full turn every 20 s.
    commands.entity(character).insert(Steering::Turn {
        turn: std::f32::consts::TAU / 20.0,
    });
}

fn report(
    time: Res<Time>,
    settings: Res<Settings>,
    characters: Query<&MotionCharacter>,
    joints: Query<&GlobalTransform>,
    mut last: Local<f64>,
    mut exit: MessageWriter<AppExit>,
) {
    let now = time.elapsed_secs_f64();
    for character in &characters {
        if let Some(e) = character.error() {
            eprintln!("motion stopped: {e}");
            exit.write(AppExit::error());
        }
        if now - *last >= 1.0 {
            *last = now;
            if let Ok(root) = joints.get(character.joints()[0]) {
                let p = root.translation();
                println!(
                    "{now:5.1} s  root at ({:6.2}, {:5.2}, {:6.2}) m  frames that waited {:?}",
                    p.x,
                    p.y,
                    p.z,
                    character.waits()
                );
            }
        }
    }
    if now >= settings.seconds {
        exit.write(AppExit::Success);
    }
}
