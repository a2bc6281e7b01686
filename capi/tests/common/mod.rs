//! What the C and C# programs must print, from the Rust API, and where the shared library is.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::PathBuf;

use sinmdm::motion::FeatureMatrix;
use sinmdm::{
    FeatureLayout, Feet, Generated, Model, ModelOptions, Pose, Request, Span, Stream,
    StreamOptions, Task, features_from_poses,
};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn model_path() -> PathBuf {
    repo().join("onnx-models/human_walk_cmu.onnx")
}

/// A shipped world-root model (the fox, which does not travel), which refuses steering.
pub fn world_root_model_path() -> PathBuf {
    repo().join("onnx-models/fox_survey_khronos.onnx")
}

/// The shipped heading-relative model the steering checks run on.
pub fn steer_model_path() -> PathBuf {
    repo().join("onnx-models/human_zombie_walk_fair.onnx")
}

/// The velocity commands the steering checks give: `frames` frames of `forward` units/s and
/// `turn` radians/s.
pub fn steer_commands(frames: usize, forward: f64, turn: f64) -> Vec<sinmdm::steer::SteerFrame> {
    vec![sinmdm::steer::SteerFrame::Velocity { forward, turn }; frames]
}

/// The facing commands the steering checks give (file frame of the zombie walk, +Z up): 20
/// frames facing (1, 0.5) on the ground, then 20 frames at positions `(0.5 i, 0.2 i)` facing
/// +Y (a path walked with a facing of its own).
pub fn facing_commands() -> Vec<sinmdm::steer::SteerFrame> {
    use sinmdm::motion::math::Vec3;
    use sinmdm::steer::SteerFrame;
    (0..40)
        .map(|i| {
            if i < 20 {
                SteerFrame::Facing(Vec3::new(1.0, 0.5, 0.0))
            } else {
                SteerFrame::PositionFacing {
                    position: Vec3::new(0.5 * i as f64, 0.2 * i as f64, 0.0),
                    facing: Vec3::new(0.0, 1.0, 0.0),
                }
            }
        })
        .collect()
}

/// The folder of the test binary's profile (`target/release`), where `libsinmdm_c.so` is,
/// with the shared library built now: `cargo test` builds the crate's rlib for the tests, not
/// its cdylib, which could otherwise be stale.
pub fn library_dir() -> PathBuf {
    static BUILT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BUILT
        .get_or_init(|| {
            let exe = std::env::current_exe().unwrap();
            let dir = exe.parent().unwrap().parent().unwrap().to_path_buf();
            let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
            let mut build = std::process::Command::new(cargo);
            build
                .args(["build", "--quiet", "-p", "sinmdm-c", "--lib"])
                .current_dir(repo());
            if dir.ends_with("release") {
                build.arg("--release");
            }
            if let Some(target) = dir.parent() {
                build.env("CARGO_TARGET_DIR", target);
            }
            let status = build
                .status()
                .expect("could not run cargo to build libsinmdm_c");
            assert!(status.success(), "building libsinmdm_c failed");
            assert!(
                dir.join("libsinmdm_c.so").is_file(),
                "no libsinmdm_c.so in {}",
                dir.display()
            );
            dir
        })
        .clone()
}

pub fn work_dir(name: &str) -> PathBuf {
    let dir = library_dir().join("c-abi-tests").join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn onnxruntime_path() -> PathBuf {
    sinmdm::init_onnxruntime().unwrap().path.clone()
}

pub fn hex(values: impl IntoIterator<Item = f32>) -> String {
    values
        .into_iter()
        .map(|v| format!(" {:08x}", v.to_bits()))
        .collect()
}

pub fn pose_lines(label: &str, poses: &[Pose], out: &mut BTreeMap<String, String>) {
    out.insert(
        format!("{label}.root"),
        hex(poses.iter().flat_map(|p| p.root_position())),
    );
    out.insert(
        format!("{label}.rotations"),
        hex(poses
            .iter()
            .flat_map(|p| p.rotations.iter().flat_map(|q| [q.x, q.y, q.z, q.w]))),
    );
    out.insert(
        format!("{label}.translations"),
        hex(poses
            .iter()
            .flat_map(|p| p.translations.iter().flatten().copied())),
    );
}

/// The lines of a stream of `model` (seed 11, 3 steps, blocks of 30 frames) steered by
/// `commands` (none: a free stream), read in chunks of 20 and 25 frames: `{label}20` and
/// `{label}25`.
fn stream_lines(
    model: &mut Model,
    label: &str,
    commands: &[sinmdm::steer::SteerFrame],
    out: &mut BTreeMap<String, String>,
) {
    let options = StreamOptions {
        seed: 11,
        steps: Some(3),
        block_frames: Some(30),
        ..StreamOptions::default()
    };
    let mut stream = Stream::new(model.metadata(), options).unwrap();
    if !commands.is_empty() {
        stream.steer(commands).unwrap();
    }
    let a = stream.next(model, 20).unwrap();
    let b = stream.next(model, 25).unwrap();
    pose_lines(&format!("{label}20"), &a.poses(), out);
    pose_lines(&format!("{label}25"), &b.poses(), out);
}

/// What the check program must print, from the Rust API.
pub fn expected() -> BTreeMap<String, String> {
    let mut model = Model::open(model_path(), &ModelOptions { threads: Some(1) }).unwrap();
    let mut out = BTreeMap::new();
    let go = &mut |_: usize, _: usize| ControlFlow::Continue(());
    let crowd = generate_lines(&mut model, go, &mut out);
    let layout = model.metadata().layout.clone();
    let reference = features_from_poses(&layout, &crowd.poses(0).unwrap()).unwrap();
    let between_reference = reference.clone();
    inbetween_lines(&mut model, reference, go, &mut out);
    dance_lines(&mut model, &layout, between_reference, go, &mut out);
    stream_lines(&mut model, "stream", &[], &mut out);
    steer_lines(go, &mut out);
    out
}

/// The generated samples' lines (`generate1`, `dpm2m`, `default_steps`); returns the crowd of
/// two whose first sample the in-between and the dance start from.
fn generate_lines(
    model: &mut Model,
    go: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    out: &mut BTreeMap<String, String>,
) -> Generated {
    let crowd = sinmdm::run(
        model,
        &Request {
            task: Task::Generate { frames: 40 },
            count: 2,
            seed: 7,
            steps: Some(4),
            feet: Feet::Planted,
            method: Default::default(),
        },
        go,
    )
    .unwrap();
    pose_lines("generate1", &crowd.poses(1).unwrap(), out);
    let quick = sinmdm::run(
        model,
        &Request {
            task: Task::Generate { frames: 40 },
            count: 1,
            seed: 5,
            steps: Some(8),
            feet: Feet::Raw,
            method: sinmdm::Method::DpmSolver2M,
        },
        go,
    )
    .unwrap();
    pose_lines("dpm2m", &quick.poses(0).unwrap(), out);
    // A zeroed `steps` in C is the library's default step count.
    let default_steps = sinmdm::run(
        model,
        &Request {
            task: Task::Generate { frames: 30 },
            count: 1,
            seed: 9,
            steps: Some(sinmdm::DEFAULT_STEPS),
            feet: Feet::Raw,
            method: Default::default(),
        },
        go,
    )
    .unwrap();
    pose_lines("default_steps", &default_steps.poses(0).unwrap(), out);
    crowd
}

/// The in-between of `reference`, kept at frames 0-10 and 30-40: `inbetween`.
fn inbetween_lines(
    model: &mut Model,
    reference: FeatureMatrix,
    go: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    out: &mut BTreeMap<String, String>,
) {
    let between = sinmdm::run(
        model,
        &Request {
            task: Task::Inbetween {
                reference,
                keep: vec![Span::new(0, 10), Span::new(30, 40)],
                ramp: 5,
            },
            count: 1,
            seed: 3,
            steps: Some(4),
            feet: Feet::Planted,
            method: Default::default(),
        },
        go,
    )
    .unwrap();
    pose_lines("inbetween", &between.poses(0).unwrap(), out);
}

/// The dance beats of `between_reference` (`dancebeats.status`) and its dance (`dance`).
fn dance_lines(
    model: &mut Model,
    layout: &FeatureLayout,
    between_reference: FeatureMatrix,
    go: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    out: &mut BTreeMap<String, String>,
) {
    // The reference's dance beats: the status and count the C ABI gives (0 and the count, or
    // SINMDM_INVALID_ARGUMENT, 2, and 0 when the motion has no regular beat).
    let motion = sinmdm::motion::decode(layout, between_reference.view()).unwrap();
    let summary = match sinmdm_beats::pulses::motion_beats(&motion) {
        Ok((_, regular)) => [0.0, regular.frames.len() as f32],
        Err(_) => [2.0, 0.0],
    };
    out.insert("dancebeats.status".into(), hex(summary));
    let dance = sinmdm::run(
        model,
        &Request {
            task: Task::Dance {
                reference: between_reference,
                beats: sinmdm::tasks::DanceBeats {
                    reference_beats: vec![8, 20, 32],
                    target_beats: vec![5, 17, 29, 41],
                    frames: 50,
                    hold: sinmdm::tasks::DANCE_HOLD,
                    ramp: 3,
                    order: sinmdm::tasks::KeyOrder::Shuffled,
                    level: sinmdm::tasks::BeatLevel::Auto,
                },
                root: true,
            },
            count: 1,
            seed: 3,
            steps: Some(4),
            feet: Feet::Planted,
            method: Default::default(),
        },
        go,
    )
    .unwrap();
    pose_lines("dance", &dance.poses(0).unwrap(), out);
}

/// The steered zombie walk's lines: `steer`, `steerfacing` and `steerstream`.
fn steer_lines(
    go: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    out: &mut BTreeMap<String, String>,
) {
    // Steering the zombie walk: 40 frames at 12 units/s turning 0.3 rad/s, one-shot; and a
    // stream told 10 units/s turning -0.2 rad/s for 60 frames, read in chunks of 20 and 25.
    let mut zombie = Model::open(steer_model_path(), &ModelOptions { threads: Some(1) }).unwrap();
    let mut steered = |commands: Vec<sinmdm::steer::SteerFrame>| {
        let request = Request {
            task: Task::Steer {
                frames: 40,
                commands,
                ramp: 5,
            },
            count: 1,
            seed: 3,
            steps: Some(4),
            feet: Feet::Planted,
            method: Default::default(),
        };
        sinmdm::run(&mut zombie, &request, go)
            .unwrap()
            .poses(0)
            .unwrap()
    };
    pose_lines("steer", &steered(steer_commands(40, 12.0, 0.3)), out);
    // The same with facing commands.
    pose_lines("steerfacing", &steered(facing_commands()), out);
    stream_lines(
        &mut zombie,
        "steerstream",
        &steer_commands(60, 10.0, -0.2),
        out,
    );
    // A character of a crowd is the same bits as its stream alone.
    stream_lines(
        &mut zombie,
        "crowdsteer",
        &steer_commands(60, 10.0, -0.2),
        out,
    );
}

/// `label hex hex ...` lines of a program's output, by label.
pub fn parse(stdout: &str) -> BTreeMap<String, String> {
    stdout
        .lines()
        .filter_map(|l| {
            let (label, rest) = l.split_once(' ')?;
            rest.chars()
                .all(|c| c.is_ascii_hexdigit() || c == ' ')
                .then(|| (label.to_string(), format!(" {rest}")))
        })
        .filter(|(label, _)| label.contains('.'))
        .collect()
}

/// Asserts that a program printed exactly the Rust API's values.
pub fn assert_same_values(stdout: &str) {
    let got = parse(stdout);
    let want = expected();
    assert_eq!(
        got.keys().collect::<Vec<_>>(),
        want.keys().collect::<Vec<_>>()
    );
    for (label, values) in &want {
        assert!(got[label] == *values, "{label} differs from the Rust API's");
    }
}
