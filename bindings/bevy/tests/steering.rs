//! Steering in a headless Bevy app: on the shipped zombie walk (heading-relative), a character
//! walking straight that is told to turn left, against the same run never told: the runs agree
//! until the commands reach the turn, and then the steered one turns left, within its steering
//! reach. The frames run back to back (a frame waits for motion when it must; the motion is the
//! same).

mod common;

use bevy_transform::components::{GlobalTransform, Transform};
use sinmdm::steer::SteerLimits;
use sinmdm::{Stream, StreamOptions};
use sinmdm_bevy::{CharacterOptions, MotionCharacter, MotionModel, Steering};

use common::{
    BEVY_FPS, HEADING_HALF_WINDOW, app_with, model_path, signed_angle, travel_headings, unwrapped,
};

/// Runs one frame of `app` and returns the root joint's world position, checking that the
/// character neither failed nor set its steering aside.
fn frame_root(app: &mut bevy_app::App, character: bevy_ecs::entity::Entity) -> bevy_math::Vec3 {
    app.update();
    let world = app.world();
    let c = world.get::<MotionCharacter>(character).unwrap();
    assert!(c.error().is_none(), "{:?}", c.error());
    assert!(c.steering_note().is_none(), "{:?}", c.steering_note());
    world
        .get::<GlobalTransform>(c.joints()[0])
        .unwrap()
        .translation()
}

/// Gives the character `steering` and returns its steering reach at that moment (model frames).
fn steer_now(
    app: &mut bevy_app::App,
    character: bevy_ecs::entity::Entity,
    steering: Steering,
) -> usize {
    let reach = app
        .world()
        .get::<MotionCharacter>(character)
        .unwrap()
        .steering_reach();
    app.world_mut().entity_mut(character).insert(steering);
    reach
}

/// Runs `frames` Bevy frames of a character of `model` walking straight at the clip's speed, told
/// at frame `turn_at` to turn at `turn` rad/s if given: its directions of travel, and its steering
/// reach when told (0 when never told).
fn run_told_to_turn(
    model: &MotionModel,
    options: &CharacterOptions,
    limits: &SteerLimits,
    turn_at: usize,
    frames: usize,
    turn: Option<f32>,
) -> (Vec<Option<f64>>, usize) {
    let (mut app, character) = app_with(model, options.clone(), Transform::IDENTITY);
    let frame = app
        .world()
        .get::<MotionCharacter>(character)
        .unwrap()
        .frame();
    let speed = Steering::clip_speed(&frame, limits);
    let straight = Steering::Velocity {
        forward: speed,
        turn: 0.0,
    };
    app.world_mut().entity_mut(character).insert(straight);
    let mut roots = Vec::new();
    let mut reach = 0;
    for k in 0..frames {
        if k == turn_at
            && let Some(turn) = turn
        {
            reach = steer_now(
                &mut app,
                character,
                Steering::Velocity {
                    forward: speed,
                    turn,
                },
            );
        }
        roots.push(frame_root(&mut app, character));
    }
    (travel_headings(&roots), reach)
}

#[test]
fn a_steering_command_turns_the_character_left_within_its_reach() {
    let model = MotionModel::open(model_path("human_zombie_walk_fair.onnx"), Some(1)).unwrap();
    let metadata = model.metadata().clone();
    let fps = metadata.layout.fps;
    let limits = SteerLimits::of(&metadata).expect("the zombie walk is heading-relative");
    let stream = StreamOptions {
        seed: 3,
        block_frames: Some(60),
        ..StreamOptions::default()
    };
    let probe = Stream::new(&metadata, stream.clone()).unwrap();
    let (ramp, lookahead) = (probe.sizes().ramp, probe.lookahead());
    let options = CharacterOptions {
        stream,
        ..CharacterOptions::for_fps(fps)
    };
    let turn_at = (4.0 * BEVY_FPS) as usize;
    let frames = turn_at + (8.0 * BEVY_FPS) as usize;
    let (straight, _) = run_told_to_turn(&model, &options, &limits, turn_at, frames, None);
    let (turned, reach) = run_told_to_turn(&model, &options, &limits, turn_at, frames, Some(0.8));
    let (straight, turned) = (unwrapped(&straight), unwrapped(&turned));
    // The model frames a change can take to show, in Bevy frames.
    let reach_bevy = (reach as f64 / fps * BEVY_FPS).ceil() as usize;
    assert!(reach > 0 && turn_at + reach_bevy < frames, "reach {reach}");
    // How far left of the straight run the steered one travels (both unwrapped from the same
    // start, so a left turn past half a turn keeps counting).
    let measured = HEADING_HALF_WINDOW..frames - HEADING_HALF_WINDOW;
    let left = |k: usize| match (straight[k], turned[k]) {
        (Some(a), Some(b)) => b - a,
        _ => panic!("frame {k}: the root stood still"),
    };
    // The runs are the same motion until the first block that sees the turn: it settles the
    // ramp of frames before its commands start, and the steering's low-pass reaches back half
    // a second more; a direction of travel is measured over half a second either side.
    let allowance = ((ramp as f64 / fps + 0.5) * BEVY_FPS) as usize + HEADING_HALF_WINDOW;
    let same_until = turn_at + reach_bevy - allowance;
    let first_apart = measured
        .clone()
        .find(|&k| left(k).abs() > 1e-3)
        .expect("the steered character never turned away");
    let departs = measured
        .clone()
        .find(|&k| left(k) > 20f64.to_radians())
        .expect("the steered character never turned 20 degrees left");
    let end = left(measured.end - 1);
    let seconds_turning = (measured.end - 1 - (turn_at + reach_bevy)) as f64 / BEVY_FPS;
    eprintln!(
        "steering reach {reach} model frames ({reach_bevy} Bevy frames; the stream's lookahead {lookahead}); the runs part {} Bevy frames after the change (bound {}), travel 20 degrees left after {}; {:.0} degrees left at the end ({:.0} commanded over the {seconds_turning:.1} s after the reach)",
        first_apart - turn_at,
        same_until - turn_at,
        departs - turn_at,
        end.to_degrees(),
        (0.8 * seconds_turning).to_degrees()
    );
    assert!(
        first_apart >= same_until,
        "the runs part before the commands reach the turn"
    );
    assert!(
        departs <= turn_at + reach_bevy + allowance,
        "turned after {} Bevy frames, reach {reach_bevy}",
        departs - turn_at
    );
    // And within the stream's lookahead (two blocks and a ramp).
    let lookahead_bevy = (lookahead as f64 / fps * BEVY_FPS) as usize;
    assert!(
        departs <= turn_at + lookahead_bevy,
        "turned after {} Bevy frames, the stream's lookahead {lookahead_bevy}",
        departs - turn_at
    );
    // Left all the way (strides sway the two runs apart by a few degrees either way once they
    // part, a turn the wrong way would go on), and by at least half the commanded angle.
    assert!(
        measured.clone().all(|k| left(k) > -20f64.to_radians()),
        "it turned right"
    );
    assert!(
        end > 0.4 * seconds_turning,
        "turned {end} rad, commanded {}",
        0.8 * seconds_turning
    );
}

/// A facing command: the zombie walks freely for two seconds, then is told to face 120 degrees
/// left of where it is going (in Bevy's axes); within its steering reach and a second and a
/// half to turn, it walks that way.
#[test]
fn a_facing_command_turns_the_character_to_walk_that_way() {
    let model = MotionModel::open(model_path("human_zombie_walk_fair.onnx"), Some(1)).unwrap();
    let metadata = model.metadata().clone();
    let fps = metadata.layout.fps;
    let options = CharacterOptions {
        stream: StreamOptions {
            seed: 4,
            block_frames: Some(60),
            ..StreamOptions::default()
        },
        ..CharacterOptions::for_fps(fps)
    };
    let (mut app, character) = app_with(&model, options, Transform::IDENTITY);
    let face_at = (2.0 * BEVY_FPS) as usize;
    let frames = face_at + (10.0 * BEVY_FPS) as usize;
    let mut roots: Vec<bevy_math::Vec3> = Vec::new();
    let mut wanted = None;
    let mut reach = 0;
    for k in 0..frames {
        if k == face_at {
            let d = roots[k - 1] - roots[k - 1 - 2 * HEADING_HALF_WINDOW];
            let going = f64::from(d.x).atan2(f64::from(d.z));
            let heading = going + 120f64.to_radians();
            wanted = Some(heading);
            let direction = bevy_math::Vec3::new(heading.sin() as f32, 0.3, heading.cos() as f32);
            reach = steer_now(&mut app, character, Steering::Face { direction });
        }
        roots.push(frame_root(&mut app, character));
    }
    let wanted = wanted.unwrap();
    let settled = face_at + ((reach as f64 / fps + 1.5) * BEVY_FPS).ceil() as usize;
    assert!(settled + 2 * BEVY_FPS as usize <= frames, "reach {reach}");
    let mut off: Vec<f64> = travel_headings(&roots)[settled..]
        .iter()
        .flatten()
        .map(|h| signed_angle(*h, wanted).abs().to_degrees())
        .collect();
    off.sort_by(f64::total_cmp);
    assert!(off.len() > BEVY_FPS as usize, "it stood still");
    let median = off[off.len() / 2];
    eprintln!(
        "told to face 120 degrees left; from {} Bevy frames after (reach {reach} model frames) its travel is {median:.1} degrees off at the median, {:.1} at the 90th percentile",
        settled - face_at,
        off[off.len() * 9 / 10]
    );
    assert!(
        median < 25.0,
        "travel {median} degrees off the facing asked"
    );
}
