//! The tasks through real onnxruntime on a small trained model (tests/data/models/walk_tiny.onnx,
//! configs/tiny.yaml on the CMU walk): what the mask keeps, crowds, harmonization, dance. The
//! requests they refuse are in task_refusals.rs.

use ndarray::{Array2, Array3, Axis};
use sinmdm::bvh::read_bvh;
use sinmdm::diffusion::sampler::low_pass;
use sinmdm::motion::encode_for;
use sinmdm::tasks::{self, Generated, Request, Span, Task};
use sinmdm::{Method, Model};

mod common;

use common::{tiny_model as model, walk_features as walk, workspace as root};

fn run(model: &mut Model, task: Task, count: usize, steps: usize) -> Generated {
    run_with(model, task, count, steps, Method::Ancestral)
}

fn run_with(
    model: &mut Model,
    task: Task,
    count: usize,
    steps: usize,
    method: Method,
) -> Generated {
    let request = Request {
        task,
        count,
        seed: 3,
        steps: Some(steps),
        feet: sinmdm::Feet::default(),
        method,
    };
    tasks::run(model, &request, &mut |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap()
}

#[test]
fn inbetween_keeps_the_reference_exactly_where_the_mask_is_one() {
    let methods = [
        Method::Ancestral,
        Method::Ddim { eta: 0.0 },
        Method::Ddim { eta: 0.7 },
        Method::DpmSolver2M,
    ];
    for method in methods {
        inbetween_keeps_the_reference(method);
    }
}

fn inbetween_keeps_the_reference(method: Method) {
    let mut m = model();
    let reference = walk(&m, 150);
    let y = m.metadata().normalizer.normalize(reference.view());
    let keep = vec![Span::new(0, 50), Span::new(100, 150)];
    let out = run_with(
        &mut m,
        Task::Inbetween {
            reference,
            keep,
            ramp: 10,
        },
        2,
        12,
        method,
    );
    assert_eq!(out.normalized.dim(), (2, y.nrows(), 150));
    for sample in out.normalized.outer_iter() {
        // Mask 1: frames at least 10 frames from the gap 50..100.
        for frame in (0..=40).chain(110..150) {
            assert_eq!(
                sample.column(frame),
                y.column(frame),
                "{method:?}: frame {frame} differs from the reference"
            );
        }
        // The gap itself is generated, not copied.
        let gap_diff: f32 = (55..95)
            .map(|f| (&sample.column(f) - &y.column(f)).mapv(f32::abs).sum())
            .sum();
        assert!(
            gap_diff > 1.0,
            "{method:?}: the gap equals the reference ({gap_diff})"
        );
    }
}

#[test]
fn expand_keeps_the_reference_in_the_middle() {
    let mut m = model();
    let reference = walk(&m, 80);
    let y = m.metadata().normalizer.normalize(reference.view());
    let out = run(
        &mut m,
        Task::Expand {
            reference,
            prefix: 30,
            suffix: 40,
            ramp: 6,
        },
        1,
        20,
    );
    let sample = out.normalized.index_axis(Axis(0), 0);
    assert_eq!(sample.ncols(), 150);
    for frame in 6..80 - 6 {
        assert_eq!(sample.column(30 + frame), y.column(frame), "frame {frame}");
    }
}

#[test]
fn compose_keeps_the_chosen_joints_and_generates_the_rest() {
    let mut m = model();
    let reference = walk(&m, 120);
    let y = m.metadata().normalizer.normalize(reference.view());
    let layout = m.metadata().layout.clone();
    let leg = layout.skeleton.find("LeftHip").expect("CMU skeleton");
    let joints = tasks::subtree(&layout, leg);
    let kept: Vec<usize> = joints
        .iter()
        .flat_map(|&j| layout.joint_columns(j))
        .collect();
    assert!(kept.len() >= 18, "a leg has several joints");
    let out = run(
        &mut m,
        Task::Compose {
            reference,
            joints,
            root: false,
            spans: vec![],
            ramp: 10,
        },
        1,
        20,
    );
    let sample = out.normalized.index_axis(Axis(0), 0);
    for &r in &kept {
        assert_eq!(sample.row(r), y.row(r), "column {r}");
    }
    let other = (0..y.nrows()).find(|r| !kept.contains(r)).unwrap();
    let diff = (&sample.row(other) - &y.row(other)).mapv(f32::abs).sum();
    assert!(diff > 0.1, "a free column equals the reference");
}

#[test]
fn a_crowd_of_eight_has_eight_different_samples() {
    let mut m = model();
    let out = run(&mut m, Task::Generate { frames: 90 }, 8, 20);
    assert_eq!(out.count(), 8);
    for a in 0..8 {
        for b in a + 1..8 {
            let d = (&out.normalized.index_axis(Axis(0), a)
                - &out.normalized.index_axis(Axis(0), b))
                .mapv(f32::abs)
                .sum()
                / out.normalized.index_axis(Axis(0), a).len() as f32;
            assert!(
                d > 0.05,
                "samples {a} and {b} differ by only {d} on average"
            );
        }
    }
    // Each sample decodes to a motion of the model's skeleton.
    let poses = out.poses(7).unwrap();
    assert_eq!(poses.len(), 90);
    assert_eq!(poses[0].rotations.len(), m.metadata().layout.skeleton.len());
}

#[test]
fn same_seed_same_motion_and_another_seed_another() {
    let mut m = model();
    let a = run(&mut m, Task::Generate { frames: 40 }, 1, 10);
    let b = run(&mut m, Task::Generate { frames: 40 }, 1, 10);
    assert_eq!(a.normalized, b.normalized);
    let request = Request {
        task: Task::Generate { frames: 40 },
        count: 1,
        seed: 4,
        steps: Some(10),
        feet: sinmdm::Feet::default(),
        method: Default::default(),
    };
    let c = tasks::run(&mut m, &request, &mut |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    assert_ne!(a.normalized, c.normalized);
}

fn low_pass_distance(sample: &Array3<f32>, content: &Array2<f32>, factor: usize) -> f32 {
    let content = content.clone().insert_axis(Axis(0));
    let a = low_pass(sample.view(), factor);
    let b = low_pass(content.view(), factor);
    (&a - &b).mapv(|v| v * v).mean().unwrap().sqrt()
}

fn harmonize(m: &mut Model, content: &Array2<f32>, free_share: f64, method: Method) -> Generated {
    run_with(
        m,
        Task::Harmonize {
            content: content.clone(),
            factor: 2,
            free_share,
        },
        1,
        50,
        method,
    )
}

#[test]
fn harmonization_follows_the_content_low_frequencies() {
    let mut m = model();
    // Style transfer: a walk model, the content a hop of the same CMU skeleton.
    let hop = read_bvh(root().join("tests/data/bvh/human_hop_cmu_131_03.bvh")).unwrap();
    let content = encode_for(&hop, &m.metadata().layout).unwrap();
    let y = m.metadata().normalizer.normalize(content.view());
    let free = run(
        &mut m,
        Task::Generate {
            frames: content.ncols(),
        },
        1,
        50,
    );
    let unguided = low_pass_distance(&free.normalized, &y, 2);
    // With the default free share the model has the last word (its prediction at t = 0), so
    // the output follows the content's slow motion, not exactly.
    for method in [Method::Ancestral, Method::DpmSolver2M] {
        let guided =
            low_pass_distance(&harmonize(&mut m, &content, 0.02, method).normalized, &y, 2);
        assert!(
            guided * 1.5 < unguided,
            "{method:?}: harmonized low-pass distance {guided} vs unguided {unguided}"
        );
    }
    // With no free steps the last replacement is with the clean content, so the output's
    // low-pass is the content's up to what one more low-pass changes (up(down) is not a
    // projection: applying it twice differs a little from applying it once).
    let strict = low_pass_distance(
        &harmonize(&mut m, &content, 0.0, Method::Ancestral).normalized,
        &y,
        2,
    );
    assert!(
        strict * 10.0 < unguided,
        "low-pass distance {strict} with no free steps, unguided {unguided}"
    );
}

#[test]
fn dance_lands_the_reference_beat_poses_exactly_on_the_music_beats() {
    use sinmdm::tasks::{BeatLevel, DanceBeats, KeyOrder, place_keyframes};
    let mut m = model();
    let reference = walk(&m, 200);
    let y = m.metadata().normalizer.normalize(reference.view());
    let root_rows = m
        .metadata()
        .layout
        .root
        .as_ref()
        .map_or(0, |r| r.axes.len());
    assert!(root_rows > 0, "the walk model has root features");
    for (order, root) in [(KeyOrder::Reference, true), (KeyOrder::Shuffled, false)] {
        let beats = DanceBeats {
            reference_beats: (0..7).map(|k| 20 + 25 * k).collect(),
            target_beats: (0..9).map(|k| 5 + 27 * k).collect(),
            frames: 240,
            hold: 3,
            ramp: 3,
            order,
            level: BeatLevel::Auto,
        };
        let placement = place_keyframes(200, &beats, 3).unwrap();
        assert_eq!(placement.level, BeatLevel::Every);
        assert_eq!(placement.keys.len(), 9);
        let out = run(
            &mut m,
            Task::Dance {
                reference: reference.clone(),
                beats,
                root,
            },
            2,
            12,
        );
        let first_kept = if root { 0 } else { root_rows };
        for sample in out.normalized.outer_iter() {
            for key in &placement.keys {
                let made = sample.column(key.target);
                let wanted = y.column(key.reference);
                let worst = (first_kept..y.nrows())
                    .map(|r| (made[r] - wanted[r]).abs())
                    .fold(0.0f32, f32::max);
                assert!(
                    worst <= 1e-5,
                    "{order:?}: output frame {} is {worst} from reference frame {}",
                    key.target,
                    key.reference
                );
                if !root {
                    let root_diff: f32 = (0..root_rows).map(|r| (made[r] - wanted[r]).abs()).sum();
                    assert!(
                        root_diff > 1e-4,
                        "the free root was copied at {}",
                        key.target
                    );
                }
            }
            // Between the windows the motion is generated, not copied.
            let between: f32 = (placement.keys[3].target + 6..placement.keys[4].target - 6)
                .map(|f| (&sample.column(f) - &y.column(f)).mapv(f32::abs).sum())
                .sum();
            assert!(between > 1.0, "{order:?}: the gap is a copy ({between})");
        }
    }
}
