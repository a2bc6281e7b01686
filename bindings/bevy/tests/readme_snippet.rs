//! The plugin README's snippet (docs/readme_snippet.rs, its code block line for line) compiles
//! against the plugin and runs in a headless app; a test also checks that the README still
//! shows it.

use std::time::Duration;

/// What the snippet's `use bevy::prelude::*` brings that it uses, from Bevy's own crates.
mod bevy {
    pub mod prelude {
        pub use bevy_ecs::prelude::Commands;
        pub use bevy_transform::components::Transform;
    }
}

include!("../docs/readme_snippet.rs");

use bevy_app::{App, Startup, TaskPoolPlugin};
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::GlobalTransform;
use sinmdm::steer::SteerLimits;
use sinmdm_bevy::MotionCharacter;

#[test]
fn the_readme_snippet_spawns_a_walking_zombie() {
    // Its model path is the repository root's, where the README's commands run.
    std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).unwrap();
    let mut app = App::new();
    app.add_plugins((
        TaskPoolPlugin::default(),
        TimePlugin,
        TransformPlugin,
        SinmdmPlugin,
    ))
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 60.0,
    )))
    .add_systems(Startup, spawn_zombie);
    let mut roots = Vec::new();
    let mut frame = None;
    for _ in 0..240 {
        app.update();
        let world = app.world_mut();
        let mut query = world.query::<&MotionCharacter>();
        let character = query.single(world).expect("one character");
        assert_eq!(character.joints().len(), 27);
        assert!(character.steering_note().is_none());
        frame = Some(character.frame());
        let root = character.joints()[0];
        roots.push(world.get::<GlobalTransform>(root).unwrap().translation());
    }
    // Each second it walks at the clip's mean forward speed, as `Turn` asks (the ground
    // distance of a second's travel on a 0.3 rad/s arc is within half a percent of its length;
    // the stream's feet planting leaves a commanded root where the steering put it).
    let model =
        sinmdm_bevy::MotionModel::open("onnx-models/human_zombie_walk_fair.onnx", Some(1)).unwrap();
    let limits = SteerLimits::of(model.metadata()).expect("a heading-relative model");
    let speed = f64::from(sinmdm_bevy::Steering::clip_speed(&frame.unwrap(), &limits));
    for second in 0..4 {
        let moved =
            f64::from((roots[second * 60 + 59] - roots[second * 60]).length()) * 60.0 / 59.0;
        assert!(
            (moved - speed).abs() < 0.15 * speed,
            "second {second}: moved {moved:.3} m against the clip's {speed:.3} m/s"
        );
    }
    // The direction of travel over the first second and over the fourth: turned left (a left
    // turn about +Y takes +Z toward +X) by about the commanded 0.3 rad/s over 3 s.
    let heading = |a: usize, b: usize| {
        let d = roots[b] - roots[a];
        f64::from(d.x).atan2(f64::from(d.z))
    };
    let mut turned = heading(180, 239) - heading(0, 59);
    if turned > std::f64::consts::PI {
        turned -= std::f64::consts::TAU;
    } else if turned < -std::f64::consts::PI {
        turned += std::f64::consts::TAU;
    }
    assert!((0.45..1.35).contains(&turned), "turned {turned} rad in 3 s");
}

#[test]
fn the_readme_shows_the_snippet_line_for_line() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let snippet = include_str!("../docs/readme_snippet.rs");
    let lines: Vec<&str> = snippet.lines().collect();
    let first = lines.iter().position(|l| l.starts_with("use ")).unwrap();
    let last = lines.iter().rposition(|l| *l == "}").unwrap();
    let block = format!("```rust\n{}\n```", lines[first..=last].join("\n"));
    assert!(
        readme.contains(&block),
        "bindings/bevy/README.md's block differs from bindings/bevy/docs/readme_snippet.rs"
    );
}
