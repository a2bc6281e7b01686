//! Foot planting against expectations that do not come from the pass itself: a synthetic leg
//! whose foot slides during a labelled contact span ends up with the foot still and every bone
//! its exact length; frames a task kept are bit for bit the input's; and on a real model, the
//! frames an in-between keeps are the network's raw motion after planting.

mod common;

use std::ops::ControlFlow;

use ndarray::s;
use sinmdm::Feet;
use sinmdm::bvh::read_bvh;
use sinmdm::motion::feet::{Kept, PlantOptions, plant_feet};
use sinmdm::motion::math::{self, Mat3, Vec3, axis_rotation};
use sinmdm::motion::{
    Axis, Channel, FeatureLayout, GlobalPose, Joint, LocalMotion, Skeleton, UpAxis, encode_for,
    global_poses,
};
use sinmdm::tasks::{Request, Span, Task};

const FRAMES: usize = 40;
/// The labelled contact span.
const SPAN: std::ops::Range<usize> = 10..30;

fn joint(name: &str, parent: Option<usize>, offset: [f64; 3], end_site: Option<[f64; 3]>) -> Joint {
    let mut channels = vec![
        Channel::Rotation(Axis::Z),
        Channel::Rotation(Axis::X),
        Channel::Rotation(Axis::Y),
    ];
    if parent.is_none() {
        channels.splice(0..0, [Axis::X, Axis::Y, Axis::Z].map(Channel::Position));
    }
    Joint {
        name: name.into(),
        parent,
        offset: Vec3(offset),
        channels,
        end_site: end_site.map(Vec3),
    }
}

/// Hips (travelling forward along +Z at 0.3 units/s) with a spine and one leg: hip, knee
/// (bent 80 degrees, so the hip-ankle distance stays well inside the leg's reach), ankle with a
/// toe End Site. The foot therefore slides forward with the hips in every frame.
fn sliding_leg() -> (FeatureLayout, LocalMotion) {
    let skeleton = Skeleton {
        joints: vec![
            joint("Hips", None, [0.0; 3], None),
            joint("Hip", Some(0), [0.1, 0.0, 0.0], None),
            joint("Knee", Some(1), [0.0, -0.45, 0.0], None),
            joint(
                "Ankle",
                Some(2),
                [0.0, -0.45, 0.0],
                Some([0.0, -0.05, 0.12]),
            ),
            joint("Spine", Some(0), [0.0, 0.5, 0.0], Some([0.0, 0.3, 0.0])),
        ],
    };
    let bend = 80f64.to_radians();
    let mut rotations: Vec<Mat3> = Vec::new();
    let mut translations: Vec<Vec3> = Vec::new();
    for f in 0..FRAMES {
        let t = f as f64 / 30.0;
        rotations.extend([
            math::IDENTITY,
            axis_rotation(0, -bend / 2.0 + 0.05 * (3.0 * t).sin()),
            axis_rotation(0, bend),
            axis_rotation(0, -bend / 2.0),
            math::IDENTITY,
        ]);
        translations.extend(
            [
                [0.0, 0.75, 0.3 * t],
                [0.1, 0.0, 0.0],
                [0.0, -0.45, 0.0],
                [0.0, -0.45, 0.0],
                [0.0, 0.5, 0.0],
            ]
            .map(Vec3),
        );
    }
    let motion = LocalMotion {
        skeleton: skeleton.clone(),
        fps: 30.0,
        rotations,
        translations,
    };
    let ground = global_poses(&motion)
        .iter()
        .map(|p| p.contact_point(3)[1])
        .fold(f64::INFINITY, f64::min)
        - 0.01;
    let layout = FeatureLayout {
        rest_translations: skeleton.joints.iter().map(|j| j.offset).collect(),
        skeleton,
        fps: 30.0,
        root: None,
        rotation_joints: vec![0, 1, 2, 3, 4],
        position_channels: vec![],
        contact_joints: vec![3],
        contact_speed_threshold: 0.2,
        skeleton_height: 1.3,
        up: UpAxis::PosY,
        ground: Some(ground),
    };
    (layout, motion)
}

fn labels() -> Vec<Vec<f32>> {
    vec![
        (0..FRAMES)
            .map(|f| if SPAN.contains(&f) { 1.0 } else { 0.0 })
            .collect(),
    ]
}

/// Labelled spans only: growing them over low frames is measured elsewhere. The stance travel
/// is smoothed over 0.1 s (3 frames), so that frames before the span lie beyond its reach and
/// can be checked untouched.
fn options() -> PlantOptions {
    PlantOptions {
        grow_within: 0.0,
        stance_smoothing_seconds: 0.1,
        ..PlantOptions::default()
    }
}

fn distance(a: Vec3, b: Vec3) -> f64 {
    (a - b).norm()
}

fn bone_lengths(pose: &GlobalPose, motion: &LocalMotion) -> Vec<f64> {
    motion
        .skeleton
        .joints
        .iter()
        .enumerate()
        .filter_map(|(j, joint)| Some(distance(pose.joints[j], pose.joints[joint.parent?])))
        .collect()
}

#[test]
fn a_sliding_foot_is_held_still_through_its_span_with_exact_bones() {
    for root_stance_share in [1.0, 0.5, 0.0] {
        let options = PlantOptions {
            root_stance_share,
            ..options()
        };
        sliding_foot_is_held(&options);
    }
}

#[test]
fn the_root_follows_its_share_of_the_stance() {
    // The stance's travel does not depend on the share, so half a share moves the hips by
    // exactly half of what a whole one does, frame by frame.
    let (layout, motion) = sliding_leg();
    let hips = |share: f64| -> Vec<Vec3> {
        let options = PlantOptions {
            root_stance_share: share,
            ..options()
        };
        let (planted, _) =
            plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).unwrap();
        global_poses(&planted).iter().map(|p| p.joints[0]).collect()
    };
    let (none, half, whole) = (hips(0.0), hips(0.5), hips(1.0));
    let mut moved = 0.0f64;
    for f in 0..none.len() {
        let full = whole[f] - none[f];
        let part = half[f] - none[f];
        moved = moved.max(full.norm());
        assert!(
            distance(part * 2.0, full) < 1e-9,
            "frame {f}: {part:?} against half of {full:?}"
        );
    }
    assert!(
        moved > 0.05 * layout.skeleton_height,
        "the stance moved the hips {moved}"
    );
}

fn sliding_foot_is_held(options: &PlantOptions) {
    let (layout, motion) = sliding_leg();
    let h = layout.skeleton_height;
    let before = global_poses(&motion);
    let slide = distance(
        before[SPAN.end - 1].contact_point(3),
        before[SPAN.start].contact_point(3),
    );
    assert!(slide > 0.15, "the synthetic foot must slide ({slide})");
    let (planted, stats) =
        plant_feet(&layout, &motion, &labels(), &Kept::default(), options).unwrap();
    let after = global_poses(&planted);
    let held = after[SPAN.start].contact_point(3);
    for f in SPAN {
        let d = distance(after[f].contact_point(3), held);
        assert!(d <= 1e-6 * h, "frame {f}: the foot moved {d}");
    }
    for (b, a) in before.iter().zip(&after) {
        for (x, y) in bone_lengths(b, &motion)
            .iter()
            .zip(bone_lengths(a, &planted))
        {
            assert!((x - y).abs() < 1e-9, "a bone changed length: {x} -> {y}");
        }
        // The spine is the network's: it keeps its place on the hips ...
        let spine = |p: &GlobalPose| p.joints[4] - p.joints[0];
        assert!(distance(spine(b), spine(a)) < 1e-12);
        // ... and the hips keep their height; they move along the ground only to travel with
        // the stance foot, and not at all when told not to.
        assert!((b.joints[0][1] - a.joints[0][1]).abs() < 1e-12);
        if options.root_stance_share == 0.0 {
            assert!(distance(b.joints[0], a.joints[0]) < 1e-12);
        }
    }
    if options.root_stance_share > 0.0 {
        // The foot slid forward with the hips, so the hips were carried back by the stance,
        // by at most the slide.
        let back = before[SPAN.end - 1].joints[0][2] - after[SPAN.end - 1].joints[0][2];
        assert!(
            back > 0.0 && back <= slide + 1e-9,
            "{back} against a slide of {slide}"
        );
        assert!(stats.max_root_travel > 0.0);
    } else {
        assert_eq!(stats.max_root_travel, 0.0);
    }
    // Before the span (beyond its blend border and the stance's smoothing) the motion is
    // untouched; after it, moved along the ground by the root's travel at most.
    let blend = (PlantOptions::default().blend_seconds * 30.0).round() as usize;
    let smoothing = (options.stance_smoothing_seconds * 30.0).round() as usize;
    let untouched = SPAN.start.saturating_sub(blend.max(smoothing) + 1);
    assert!(untouched > 0, "no frame before the span to check");
    for f in 0..untouched {
        assert!(distance(after[f].contact_point(3), before[f].contact_point(3)) < 1e-12);
    }
    for f in SPAN.end + blend + 1..FRAMES {
        let moved = after[f].contact_point(3) - before[f].contact_point(3);
        let travel = after[f].joints[0] - before[f].joints[0];
        assert!(distance(moved, travel) < 1e-12, "frame {f}");
    }
    assert_eq!(stats.spans, 1);
    assert_eq!(stats.planted_frames, SPAN.len());
    assert_eq!(stats.lifted_frames, 0);
}

#[test]
fn spans_grow_over_low_frames_only_where_the_foot_is_slow() {
    // The synthetic foot stays on the ground (within 0.05 H) in every frame and slides at the
    // hips' pace, so a span may grow over the whole clip; whether it does is decided by the
    // foot's speed along the ground, measured here from the poses.
    let (layout, motion) = sliding_leg();
    let h = layout.skeleton_height;
    let ground = layout.ground.unwrap();
    let poses = global_poses(&motion);
    let toe = |f: usize| poses[f].contact_point(3);
    assert!(
        (0..FRAMES).all(|f| toe(f)[1] - ground < 0.05 * h),
        "the synthetic foot must stay low"
    );
    let fastest = (0..FRAMES - 1)
        .map(|f| {
            let (a, b) = (toe(f), toe(f + 1));
            (b[0] - a[0]).hypot(b[2] - a[2]) * 30.0 / h
        })
        .fold(0.0, f64::max);
    assert!(fastest > 0.0);
    let planted_frames = |grow_below_speed: f64| {
        let options = PlantOptions {
            grow_within: 0.05,
            grow_stance_quantile: None,
            grow_below_speed,
            ..options()
        };
        let (_, stats) =
            plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).expect("planting");
        (stats.spans, stats.planted_frames)
    };
    // Slower than the gate everywhere: the span grows over every low frame, the whole clip.
    assert_eq!(planted_frames(2.0 * fastest), (1, FRAMES));
    assert_eq!(planted_frames(f64::INFINITY), (1, FRAMES));
    // Faster than the gate everywhere: only the labelled span is held.
    assert_eq!(planted_frames(0.5 * fastest), (1, SPAN.len()));
}

#[test]
fn a_foot_that_swings_lower_than_the_fixed_band_is_held_only_where_it_stands() {
    // A shuffle: outside the labelled span the whole figure is 0.02 H higher, so the toe swings
    // within the fixed 0.05 H band but above every height it has while it stands.
    let (layout, mut motion) = sliding_leg();
    let h = layout.skeleton_height;
    let ground = layout.ground.unwrap();
    let joints = motion.skeleton.len();
    for f in (0..FRAMES).filter(|f| !SPAN.contains(f)) {
        motion.translations[f * joints].0[1] += 0.02 * h;
    }
    let poses = global_poses(&motion);
    let height = |f: usize| (poses[f].contact_point(3)[1] - ground) / h;
    let highest_stance = SPAN.map(height).fold(f64::MIN, f64::max);
    let lowest_swing = (0..FRAMES)
        .filter(|f| !SPAN.contains(f))
        .map(height)
        .fold(f64::MAX, f64::min);
    let highest_swing = (0..FRAMES).map(height).fold(f64::MIN, f64::max);
    assert!(
        highest_stance < lowest_swing && highest_swing < 0.05,
        "not a shuffle"
    );
    let planted_frames = |grow_stance_quantile: Option<f64>| {
        let options = PlantOptions {
            grow_within: 0.05,
            grow_stance_quantile,
            grow_below_speed: f64::INFINITY,
            ..options()
        };
        let (_, stats) =
            plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).expect("planting");
        (stats.spans, stats.planted_frames)
    };
    // The fixed band holds the swing, the whole clip; the band read from the stance does not.
    assert_eq!(planted_frames(None), (1, FRAMES));
    assert_eq!(planted_frames(Some(0.9)), (1, SPAN.len()));
    assert_eq!(
        PlantOptions::default().grow_stance_quantile,
        Some(0.9),
        "the default reads the band from the stance"
    );
    // Where the swing is as low as the stance (the figure not lifted), the stance's band lets
    // the span grow over the frames at its heights again.
    let (layout, motion) = sliding_leg();
    let options = PlantOptions {
        grow_within: 0.05,
        grow_stance_quantile: Some(0.9),
        grow_below_speed: f64::INFINITY,
        ..options()
    };
    let (_, stats) = plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).unwrap();
    assert!(
        stats.planted_frames > SPAN.len(),
        "{}",
        stats.planted_frames
    );
}

#[test]
fn a_foot_the_network_flicks_inside_its_span_is_let_go_there() {
    // The hips jump 0.15 sideways for frames 19 and 20 of the span 10..30: the toe moves
    // 0.15 in a frame (4.5 units/s, 3.5 H/s) from 18 to 19 and from 20 to 21, a step the
    // labels missed.
    let (layout, mut motion) = sliding_leg();
    let joints = motion.skeleton.len();
    for f in [19, 20] {
        motion.translations[f * joints].0[0] += 0.15;
    }
    let h = layout.skeleton_height;
    let poses = global_poses(&motion);
    let speed = |f: usize| {
        let (a, b) = (poses[f].contact_point(3), poses[f + 1].contact_point(3));
        (b[0] - a[0]).hypot(b[2] - a[2]) * 30.0 / h
    };
    let fast: Vec<usize> = SPAN.filter(|&f| speed(f) >= 2.5).collect();
    assert_eq!(fast, vec![18, 20]);
    let planted = |release_above_speed: f64| {
        let options = PlantOptions {
            release_above_speed,
            ..options()
        };
        let (_, stats) =
            plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).expect("planting");
        (stats.spans, stats.planted_frames)
    };
    // 10..18 and 21..30 are held; 19..20, one frame, is shorter than the 0.1 s a span needs.
    assert_eq!(planted(2.5), (2, 8 + 9));
    assert_eq!(PlantOptions::default().release_above_speed, 2.5);
    // Kept whole, the span holds the toe through the flick.
    assert_eq!(planted(f64::INFINITY), (1, SPAN.len()));
    // Where the toe goes at the flick: let go, it moves with the network's toe by at least a
    // third of the flick (the pieces ease out and back in over 0.1 s); held, it stays put.
    let sideways = |release_above_speed: f64| {
        let options = PlantOptions {
            release_above_speed,
            ..options()
        };
        let (out, _) = plant_feet(&layout, &motion, &labels(), &Kept::default(), &options).unwrap();
        let poses = global_poses(&out);
        poses[19].contact_point(3)[0] - poses[17].contact_point(3)[0]
    };
    assert!(sideways(2.5) > 0.05, "let go: {}", sideways(2.5));
    assert!(
        sideways(f64::INFINITY).abs() < 1e-3,
        "held: {}",
        sideways(f64::INFINITY)
    );
}

#[test]
fn nothing_goes_below_the_ground() {
    let (mut layout, motion) = sliding_leg();
    // A ground above the toes' lowest point: the pass must lift them to it.
    let toes = global_poses(&motion)[0].contact_point(3)[1];
    layout.ground = Some(toes + 0.05);
    let (planted, stats) =
        plant_feet(&layout, &motion, &labels(), &Kept::default(), &options()).unwrap();
    let lowest = global_poses(&planted)
        .iter()
        .flat_map(|p| p.points().collect::<Vec<_>>())
        .map(|p| p[1])
        .fold(f64::INFINITY, f64::min);
    assert!(lowest >= toes + 0.05 - 1e-9, "lowest point {lowest}");
    assert!(stats.max_lift >= 0.0);
}

#[test]
fn kept_frames_are_the_input_bit_for_bit() {
    let (layout, motion) = sliding_leg();
    let joints = motion.skeleton.len();
    // The task kept every joint and the root in frames 0..15, inside the span's start.
    let kept = Kept {
        joints: (0..FRAMES).map(|f| vec![f < 15; joints]).collect(),
        root: (0..FRAMES).map(|f| f < 15).collect(),
    };
    let (planted, _) = plant_feet(&layout, &motion, &labels(), &kept, &options()).unwrap();
    for f in 0..15 {
        for j in 0..joints {
            let k = f * joints + j;
            assert!(math::mat_max_abs_diff(&planted.rotations[k], &motion.rotations[k]) <= 1e-9);
            assert!(distance(planted.translations[k], motion.translations[k]) <= 1e-9);
        }
    }
    // ... and the rest of the span is still planted.
    let after = global_poses(&planted);
    let held = after[16].contact_point(3);
    assert!(distance(after[SPAN.end - 1].contact_point(3), held) < 1e-6);
}

#[test]
fn labels_of_the_wrong_shape_are_refused() {
    let (layout, motion) = sliding_leg();
    let short = vec![vec![1.0; FRAMES - 1]];
    assert!(plant_feet(&layout, &motion, &short, &Kept::default(), &options()).is_err());
    assert!(plant_feet(&layout, &motion, &[], &Kept::default(), &options()).is_err());
}

#[test]
fn an_inbetween_keeps_its_frames_after_planting() {
    let root = common::workspace();
    let mut model = common::tiny_model();
    let clip = read_bvh(root.join("tests/data/bvh/human_walk_cmu_131_01.bvh")).unwrap();
    let reference = encode_for(&clip, &model.metadata().layout)
        .unwrap()
        .slice(s![.., ..120])
        .to_owned();
    let request = Request {
        task: Task::Inbetween {
            reference,
            keep: vec![Span::new(0, 40), Span::new(80, 120)],
            ramp: 5,
        },
        count: 1,
        seed: 5,
        steps: Some(5),
        feet: Feet::Planted,
        method: Default::default(),
    };
    let generated =
        sinmdm::run(&mut model, &request, &mut |_, _| ControlFlow::Continue(())).unwrap();
    assert_eq!(generated.feet(), Feet::Planted);
    let raw = generated.raw_motion(0).unwrap();
    let (planted, stats) = generated.planted_motion(0).unwrap();
    assert_eq!(generated.motion(0).unwrap(), planted);
    let joints = raw.skeleton.len();
    // Kept frames: the hard-kept parts of both spans (the ramp's soft frames are generated).
    for f in (0..35).chain(85..120) {
        for j in 0..joints {
            let k = f * joints + j;
            assert!(
                math::mat_max_abs_diff(&planted.rotations[k], &raw.rotations[k]) <= 1e-9,
                "frame {f} joint {j} turned"
            );
            assert!(distance(planted.translations[k], raw.translations[k]) <= 1e-9);
        }
    }
    // The gap was worked on (the walk's feet touch the ground there).
    assert!(stats.spans > 0, "{stats:?}");
}
