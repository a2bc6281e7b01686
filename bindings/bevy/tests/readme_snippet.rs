//! The README's Bevy snippet (docs/readme_snippet.rs, the README's code block line for line)
//! compiles against the plugin and runs in a headless app; a test also checks that the README
//! still shows it.

use std::time::Duration;

/// What the snippet's `use bevy::prelude::*` brings that it uses, from Bevy's own crates.
mod bevy {
    pub mod prelude {
        pub use bevy_ecs::prelude::{Commands, Component};
        pub use bevy_transform::components::Transform;
    }
}

include!("../docs/readme_snippet.rs");

use bevy_app::{App, Startup, TaskPoolPlugin};
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::GlobalTransform;
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
    for _ in 0..120 {
        app.update();
        let world = app.world_mut();
        let mut query = world.query::<&MotionCharacter>();
        let character = query.single(world).expect("one character");
        assert_eq!(character.joints().len(), 27);
        let root = character.joints()[0];
        roots.push(world.get::<GlobalTransform>(root).unwrap().translation());
    }
    // Two seconds at the commanded 0.35 m/s: it walks (the clip's own speed varies round it).
    let d = roots[119] - roots[0];
    let walked = d.x.hypot(d.z);
    assert!((0.2..1.4).contains(&walked), "walked {walked} m in 2 s");
}

#[test]
fn the_readme_shows_the_snippet_line_for_line() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let snippet = include_str!("../docs/readme_snippet.rs");
    let lines: Vec<&str> = snippet.lines().collect();
    let first = lines.iter().position(|l| l.starts_with("use ")).unwrap();
    let last = lines.iter().rposition(|l| *l == "}").unwrap();
    let block = format!("```rust\n{}\n```", lines[first..=last].join("\n"));
    assert!(
        readme.contains(&block),
        "README.md's Bevy block differs from bindings/bevy/docs/readme_snippet.rs"
    );
}
