// The snippet of bindings/bevy/README.md, section "Quick start" (the lines from
// `use` to the closing brace of `spawn_zombie`, line for line): change both together.
// tests/readme_snippet.rs compiles it and runs it in a headless app.
use bevy::prelude::*; // a game's Bevy, with DefaultPlugins
use sinmdm_bevy::{CharacterOptions, MotionModel, SinmdmPlugin, Steering, spawn_character};

// App::new().add_plugins((DefaultPlugins, SinmdmPlugin)).add_systems(Startup, spawn_zombie).run();
fn spawn_zombie(mut commands: Commands) {
    let model = MotionModel::open("onnx-models/human_zombie_walk_fair.onnx", Some(1)).unwrap();
    let options = CharacterOptions::for_fps(model.fps());
    let zombie = spawn_character(&mut commands, &model, options, Transform::default()).unwrap();
    // at the clip's speed, turning left at 0.3 rad/s (or Velocity { forward, turn } in m/s)
    commands.entity(zombie).insert(Steering::Turn { turn: 0.3 });
    // each joint is an entity with a Transform (a child of its parent joint, named after it)
}
