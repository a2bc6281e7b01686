//! Steering a heading-relative model (the shipped zombie walk): a circle is followed, velocity
//! commands are met on average in a stream, a facing is kept, alone or along a path (strafing,
//! on the shipped CMU walk), commands beyond the clip are clamped and reported, a stream's
//! blocks continue the course without a jump, and a world-root model refuses.

use std::f64::consts::FRAC_PI_2;
use std::ops::ControlFlow;
use std::path::PathBuf;

use sinmdm::motion::features::heading::{facing_against_travel, yaw};
use sinmdm::motion::math::Vec3;
use sinmdm::motion::{global_poses, root_track};
use sinmdm::steer::follow::{facing_following, path_following, velocity_following};
use sinmdm::steer::paths::{Shape, clip_speed, path, start_course};
use sinmdm::steer::{SteerFrame, SteerLimits};
use sinmdm::{Feet, Model, ModelOptions, Request, Stream, StreamOptions, Task, TaskError};

fn model(name: &str) -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../onnx-models")
        .join(name);
    Model::open(path, &ModelOptions::default()).expect("run scripts/setup.sh first")
}

fn zombie() -> Model {
    model("human_zombie_walk_fair.onnx")
}

fn go() -> impl FnMut(usize, usize) -> ControlFlow<()> {
    |_, _| ControlFlow::Continue(())
}

fn run(model: &mut Model, task: Task, count: usize) -> sinmdm::Generated {
    let request = Request {
        task,
        count,
        seed: 5,
        steps: Some(30),
        feet: Feet::Raw,
        method: Default::default(),
    };
    sinmdm::run(model, &request, &mut go()).unwrap()
}

/// One sample of `frames` frames steered by `commands` (ramp 10, seed 1, 20 steps), to plan.
fn steer_request(frames: usize, commands: Vec<SteerFrame>) -> Request {
    Request {
        task: Task::Steer {
            frames,
            commands,
            ramp: 10,
        },
        count: 1,
        seed: 1,
        steps: Some(20),
        feet: Feet::Raw,
        method: Default::default(),
    }
}

/// `count` samples of `commands.len()` frames steered by `commands` (ramp 10).
fn steer(model: &mut Model, commands: &[SteerFrame], count: usize) -> sinmdm::Generated {
    let task = Task::Steer {
        frames: commands.len(),
        commands: commands.to_vec(),
        ramp: 10,
    };
    run(model, task, count)
}

#[test]
fn a_steered_circle_stays_on_its_path_and_a_free_walk_does_not() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let height = metadata.layout.skeleton_height;
    let frames = 360;
    let speed = clip_speed(&metadata).unwrap();
    let commands = path(&metadata, Shape::Circle(3.0 * height), speed, frames).unwrap();
    let steered = steer(&mut model, &commands, 2);
    let free = run(&mut model, Task::Generate { frames }, 2);
    for i in 0..2 {
        let raw = steered.features.index_axis(ndarray::Axis(0), i);
        let p = path_following(&metadata.layout, raw, &commands).unwrap();
        println!("steered {i}: {p:?}");
        assert!(p.mean_distance < 0.15 && p.max_distance < 0.5, "{p:?}");
        assert!(p.progress > 0.95, "{p:?}");
        let mut angles = facing_against_travel(&metadata.layout, raw).unwrap();
        angles.sort_by(f64::total_cmp);
        assert!(
            angles[angles.len() / 2] <= 20.0,
            "{}",
            angles[angles.len() / 2]
        );
        let loose = path_following(
            &metadata.layout,
            free.features.index_axis(ndarray::Axis(0), i),
            &commands,
        )
        .unwrap();
        println!("free {i}: {loose:?}");
        assert!(loose.max_distance > 4.0 * p.max_distance, "{loose:?}");
    }
}

/// Speed and turn rate change every two seconds; averaged over each two seconds, a stream of
/// short blocks meets them within 15 % and 20 % (turn rates against at least 10 degrees/s).
#[test]
fn a_stream_meets_velocity_commands_on_average() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let fps = metadata.layout.fps;
    let speed = clip_speed(&metadata).unwrap();
    let schedule = [
        (1.0, 20.0),
        (0.7, -25.0),
        (1.2, 30.0),
        (0.9, -15.0),
        (1.1, 0.0),
        (0.8, 35.0),
    ];
    let window = (2.0 * fps) as usize;
    let commands: Vec<SteerFrame> = schedule
        .iter()
        .flat_map(|&(s, turn)| {
            std::iter::repeat_n(
                SteerFrame::Velocity {
                    forward: s * speed,
                    turn: f64::to_radians(turn),
                },
                window,
            )
        })
        .collect();
    let frames = commands.len();
    let options = StreamOptions {
        seed: 2,
        block_frames: Some(90),
        feet: Feet::Raw,
        ..StreamOptions::default()
    };
    let mut stream = Stream::new(&metadata, options).unwrap();
    stream.steer(&commands).unwrap();
    let chunk = stream.next(&mut model, frames).unwrap();
    assert!(stream.warnings().is_empty(), "{:?}", stream.warnings());
    let v = velocity_following(&metadata.layout, chunk.features.view(), &commands, window).unwrap();
    assert_eq!(v.forward.len(), schedule.len());
    for ((asked, got), (asked_turn, got_turn)) in v.forward.iter().zip(&v.turn) {
        println!(
            "speed {asked:.2} -> {got:.2}, turn {:.1} -> {:.1} degrees/s",
            asked_turn.to_degrees(),
            got_turn.to_degrees()
        );
        assert!(
            (got - asked).abs() <= 0.15 * asked,
            "speed {asked} -> {got}"
        );
        let floor = 10f64.to_radians();
        assert!(
            (got_turn - asked_turn).abs() <= 0.2 * asked_turn.abs().max(floor),
            "turn {asked_turn} -> {got_turn}"
        );
    }
}

#[test]
fn commands_beyond_the_clip_are_clamped_and_said() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let limits = SteerLimits::of(&metadata).unwrap();
    let fast = limits.forward.1 * 3.0;
    let commands = vec![
        SteerFrame::Velocity {
            forward: fast,
            turn: 0.0
        };
        240
    ];
    let request = steer_request(240, commands.clone());
    let plan = sinmdm::plan(&metadata, &request).unwrap();
    assert_eq!(plan.warnings().len(), 1, "{:?}", plan.warnings());
    assert!(
        plan.warnings()[0].contains("clamped"),
        "{:?}",
        plan.warnings()
    );
    let out = plan.run(&mut model, &mut go()).unwrap();
    let v = velocity_following(
        &metadata.layout,
        out.features.index_axis(ndarray::Axis(0), 0),
        &commands,
        60,
    )
    .unwrap();
    for (_, got) in &v.forward {
        assert!(
            *got < 1.2 * limits.forward.1,
            "{got} against {}",
            limits.forward.1
        );
    }
}

/// A free stream of short blocks: each block is decoded from the last final frame's position
/// and facing, so the root's step and turn at a seam look like any other frame's.
#[test]
fn a_heading_streams_blocks_continue_the_course() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let block = 60;
    let options = StreamOptions {
        seed: 4,
        block_frames: Some(block),
        feet: Feet::Raw,
        ..StreamOptions::default()
    };
    let mut stream = Stream::new(&metadata, options).unwrap();
    let chunk = stream.next(&mut model, 6 * block).unwrap();
    let poses = global_poses(&chunk.motion);
    let root = metadata.layout.root.as_ref().unwrap().joint;
    let steps: Vec<f64> = poses
        .windows(2)
        .map(|w| (w[1].joints[root] - w[0].joints[root]).norm())
        .collect();
    let mut inside: Vec<f64> = steps
        .iter()
        .enumerate()
        .filter(|(i, _)| (i + 1) % block != 0)
        .map(|(_, s)| *s)
        .collect();
    inside.sort_by(f64::total_cmp);
    let p99 = inside[inside.len() * 99 / 100];
    for seam in (block..6 * block).step_by(block) {
        let step = steps[seam - 1];
        assert!(
            step <= 1.5 * p99,
            "seam {seam}: step {step} against p99 {p99}"
        );
    }
    // Decoding the whole stream's features from the model's start gives the course the
    // stream handed out.
    let (positions, _) = root_track(&metadata.layout, chunk.features.view(), None).unwrap();
    let to_file = metadata.layout.up.file_from_canonical();
    for (f, pose) in poses.iter().enumerate() {
        let p = to_file * positions[f];
        let off = (pose.joints[root] - p).norm() / metadata.layout.skeleton_height;
        assert!(off < 1e-3, "frame {f}: {off}");
    }
}

#[test]
fn a_world_root_model_refuses_steering() {
    // The shipped fox does not travel, so the default gave it the world root.
    let mut fox = model("fox_survey_khronos.onnx");
    let metadata = fox.metadata().clone();
    assert!(SteerLimits::of(&metadata).is_none());
    let request = steer_request(60, vec![]);
    let e = sinmdm::run(&mut fox, &request, &mut go()).unwrap_err();
    assert!(matches!(e, TaskError::Steer(_)), "{e}");
    assert!(e.to_string().contains("heading-relative"), "{e}");
    let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
    assert!(stream.steer(&[SteerFrame::Free]).is_err());
}

#[test]
fn commands_that_are_not_finite_are_refused() {
    let model = zombie();
    let metadata = model.metadata().clone();
    let bad = vec![
        SteerFrame::Velocity {
            forward: 10.0,
            turn: 0.0,
        },
        SteerFrame::Velocity {
            forward: f64::NAN,
            turn: 0.0,
        },
    ];
    let request = steer_request(60, bad.clone());
    let e = sinmdm::plan(&metadata, &request).unwrap_err();
    assert!(e.to_string().contains("command 1"), "{e}");
    let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
    let e = stream.steer(&bad).unwrap_err();
    assert!(e.to_string().contains("not finite"), "{e}");
    let position = SteerFrame::Position(Vec3::new(0.0, f64::INFINITY, 0.0));
    assert!(stream.steer(&[position]).is_err());
}

/// The file-frame ground direction `angle` radians left of the model's start facing.
fn turned_from_start(metadata: &sinmdm::model_file::ModelMetadata, angle: f64) -> Vec3 {
    let (_, heading) = start_course(metadata).unwrap();
    metadata.layout.up.file_from_canonical() * (yaw(heading + angle) * Vec3::new(0.0, 0.0, 1.0))
}

/// A facing alone: the character turns to face a quarter turn left of where it started and
/// keeps that facing, walking where it faces as the clip does; a free run does not.
#[test]
fn a_facing_command_turns_the_character_and_leaves_its_walk_alone() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let frames = 300;
    let commands = vec![SteerFrame::Facing(turned_from_start(&metadata, FRAC_PI_2)); frames];
    let steered = steer(&mut model, &commands, 2);
    let free = run(&mut model, Task::Generate { frames }, 2);
    for i in 0..2 {
        let raw = steered.features.index_axis(ndarray::Axis(0), i);
        let f = facing_following(&metadata, raw, &commands).unwrap();
        println!("steered {i}: {f:?}");
        assert!(f.frames > 200, "{f:?}");
        assert!(f.median < 12.0 && f.p90 < 20.0, "{f:?}");
        let mut angles = facing_against_travel(&metadata.layout, raw).unwrap();
        angles.sort_by(f64::total_cmp);
        let median = angles[angles.len() / 2];
        assert!(median <= 20.0, "facing against travel {median}");
        let loose = facing_following(
            &metadata,
            free.features.index_axis(ndarray::Axis(0), i),
            &commands,
        )
        .unwrap();
        println!("free {i}: {loose:?}");
        assert!(loose.median > 45.0, "{loose:?}");
    }
}

/// A path with a facing of its own: the shipped CMU walk (which glides backwards and sideways
/// in its clip) walks a circle while facing one way, so it strafes and backs round it; the
/// zombie, which never went sideways that fast, is clamped and says so.
#[test]
fn a_circle_walked_facing_one_way_is_followed_within_the_clips_range() {
    let mut walk = model("human_walk_cmu.onnx");
    let metadata = walk.metadata().clone();
    let height = metadata.layout.skeleton_height;
    let speed = clip_speed(&metadata).unwrap();
    // Half a lap and two seconds: travel turns through 180 degrees while the facing holds.
    let half_lap = std::f64::consts::PI * 3.0 * height / speed;
    let frames = ((half_lap + 2.0) * metadata.layout.fps).ceil() as usize;
    let facing = turned_from_start(&metadata, 0.0);
    let circle = path(&metadata, Shape::Circle(3.0 * height), speed, frames).unwrap();
    let commands: Vec<SteerFrame> = circle
        .iter()
        .map(|c| SteerFrame::PositionFacing {
            position: c.position().unwrap(),
            facing,
        })
        .collect();
    let steered = steer(&mut walk, &commands, 2);
    for i in 0..2 {
        let raw = steered.features.index_axis(ndarray::Axis(0), i);
        let p = path_following(&metadata.layout, raw, &commands).unwrap();
        let f = facing_following(&metadata, raw, &commands).unwrap();
        println!("walk {i}: {p:?} {f:?}");
        assert!(p.mean_distance < 0.2 && p.max_distance < 1.0, "{p:?}");
        assert!(f.median < 10.0 && f.p90 < 20.0, "{f:?}");
        // Round the circle facing one way, travel and facing part: half the time it walks more
        // than sideways, backwards (the median of 0 to 180 degrees is 90).
        let mut angles = facing_against_travel(&metadata.layout, raw).unwrap();
        angles.sort_by(f64::total_cmp);
        assert!(
            angles[angles.len() / 2] > 60.0,
            "{}",
            angles[angles.len() / 2]
        );
    }
    let zombie = zombie();
    let metadata = zombie.metadata().clone();
    let height = metadata.layout.skeleton_height;
    let facing = turned_from_start(&metadata, 0.0);
    let commands: Vec<SteerFrame> = path(
        &metadata,
        Shape::Circle(3.0 * height),
        clip_speed(&metadata).unwrap(),
        frames,
    )
    .unwrap()
    .iter()
    .map(|c| SteerFrame::PositionFacing {
        position: c.position().unwrap(),
        facing,
    })
    .collect();
    let request = steer_request(600, commands);
    let plan = sinmdm::plan(&metadata, &request).unwrap();
    assert!(
        plan.warnings().iter().any(|w| w.contains("sideways")),
        "{:?}",
        plan.warnings()
    );
}

#[test]
fn a_facing_with_no_direction_on_the_ground_is_refused() {
    let model = zombie();
    let metadata = model.metadata().clone();
    // The zombie's file frame is +Z up: facing +Z is facing nowhere on the ground.
    let up = metadata.layout.up.file_from_canonical() * Vec3::new(0.0, 1.0, 0.0);
    let commands = vec![SteerFrame::Free, SteerFrame::Facing(up)];
    let request = steer_request(60, commands.clone());
    let e = sinmdm::plan(&metadata, &request).unwrap_err();
    assert!(e.to_string().contains("command 1"), "{e}");
    assert!(e.to_string().contains("no direction on the ground"), "{e}");
    let mut stream = Stream::new(&metadata, StreamOptions::default()).unwrap();
    let e = stream.steer(&commands).unwrap_err();
    assert!(e.to_string().contains("no direction on the ground"), "{e}");
}

/// The root's mean ground speed over each two seconds of `motion` (file frame), in file units
/// per second (the chord of a two-second arc at 0.3 rad/s is within 1.5 % of its length).
fn ground_speed_per_two_seconds(
    metadata: &sinmdm::model_file::ModelMetadata,
    motion: &sinmdm::motion::clip::LocalMotion,
) -> Vec<f64> {
    let layout = &metadata.layout;
    let joints = layout.skeleton.len();
    let root = layout.root.as_ref().unwrap().joint;
    let to_canonical = layout.up.file_from_canonical().transpose();
    let ground = |f: usize| {
        let mut p = to_canonical * motion.translations[f * joints + root];
        p[sinmdm::motion::up::UP] = 0.0;
        p
    };
    let window = (2.0 * layout.fps).round() as usize;
    (0..motion.translations.len() / joints / window)
        .map(|w| {
            let (a, b) = (w * window, (w + 1) * window - 1);
            (ground(b) - ground(a)).norm() * layout.fps / (b - a) as f64
        })
        .collect()
}

/// A velocity command sets where the root goes, and foot planting (the default output) leaves
/// it there: carried along with the feet instead, the root would walk at the pace of the
/// model's strides, which can be half the commanded one. Each two seconds cover the commanded
/// speed within 12 %, in a batch run and in a stream of short blocks.
#[test]
fn planted_feet_keep_the_commanded_speed() {
    let mut model = zombie();
    let metadata = model.metadata().clone();
    let fps = metadata.layout.fps;
    let speed = clip_speed(&metadata).unwrap();
    let frames = (6.0 * fps) as usize;
    let commands = vec![
        SteerFrame::Velocity {
            forward: speed,
            turn: 0.3,
        };
        frames
    ];
    let check = |what: &str, motion: &sinmdm::motion::clip::LocalMotion| {
        let speeds = ground_speed_per_two_seconds(&metadata, motion);
        println!("{what}: {speeds:.2?} against {speed:.2}");
        assert_eq!(speeds.len(), 3);
        for (w, got) in speeds.iter().enumerate() {
            assert!(
                (got - speed).abs() <= 0.12 * speed,
                "{what}, seconds {}-{}: {got:.2} against the commanded {speed:.2}",
                2 * w,
                2 * w + 2
            );
        }
    };
    let request = Request {
        feet: Feet::Planted,
        ..steer_request(frames, commands.clone())
    };
    let batch = sinmdm::run(&mut model, &request, &mut go()).unwrap();
    check("batch", &batch.motion(0).unwrap());
    let options = StreamOptions {
        seed: 3,
        block_frames: Some(60),
        feet: Feet::Planted,
        ..StreamOptions::default()
    };
    let mut stream = Stream::new(&metadata, options).unwrap();
    stream.steer(&commands).unwrap();
    let chunk = stream.next(&mut model, frames).unwrap();
    check("stream", &chunk.motion);
}
