//! Kinematic fidelity on controls whose answers are known, made from the project's clips: the
//! clip against itself (nothing to tell apart), the clip played at half its pace (every speed
//! halved), and one pose held (never moves: one mean speed away).

use std::path::Path;

use sinmdm::bvh::read_bvh;
use sinmdm::motion::resample::resample;
use sinmdm::motion::up::UpAxis;
use sinmdm::motion::{LocalMotion, global_poses, skeleton_height};
use sinmdm_eval::KinematicReport;

fn clip(name: &str) -> (LocalMotion, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/bvh")
        .join(name);
    let motion = resample(&read_bvh(path).unwrap().to_local(), 30.0);
    let height = skeleton_height(&global_poses(&motion));
    (motion, height)
}

/// `motion` played at `1 / factor` of its pace: resampled to `factor` times its rate, then
/// labelled with its own rate again.
fn slowed(motion: &LocalMotion, factor: f64) -> LocalMotion {
    let mut slow = resample(motion, motion.fps * factor);
    slow.fps = motion.fps;
    slow
}

/// `motion`'s first frame, held for as many frames.
fn held(motion: &LocalMotion) -> LocalMotion {
    let joints = motion.skeleton.len();
    let frames = motion.frame_count();
    let mut still = motion.clone();
    for f in 0..frames {
        for j in 0..joints {
            still.rotations[f * joints + j] = motion.rotations[j];
            still.translations[f * joints + j] = motion.translations[j];
        }
    }
    still
}

const CLIPS: [&str; 3] = [
    "human_walk_cmu_131_01.bvh",
    "fox_survey_khronos.bvh",
    "human_dance_rokoko_jesse.bvh",
];

#[test]
fn the_clip_against_itself_moves_exactly_like_it() {
    for name in CLIPS {
        let (motion, height) = clip(name);
        let report = KinematicReport::new(
            &motion,
            std::slice::from_ref(&motion),
            std::slice::from_ref(&motion),
            height,
            UpAxis::PosY,
        );
        let s = &report.planted;
        assert_eq!(s.speed_ratios, [1.0; 3], "{name}");
        assert_eq!(s.speed_distance, 0.0, "{name}");
        assert_eq!(s.acceleration_distance, 0.0, "{name}");
        assert_eq!(s.still_share, report.clip.still_share, "{name}");
        assert!(s.misses(report.clip.still_share).is_empty(), "{name}");
        assert!(report.clip.speed_percentiles[1] > 0.0, "{name}");
        let turning = &report.turning;
        assert_eq!(turning.planted.faster_than_clip, 0.0, "{name}");
        assert_eq!(turning.planted.fast, turning.clip.fast, "{name}");
    }
}

#[test]
fn half_the_pace_halves_every_speed_and_misses_the_goals() {
    for name in CLIPS {
        let (motion, height) = clip(name);
        let slow = slowed(&motion, 2.0);
        assert_eq!(slow.frame_count(), 2 * motion.frame_count() - 1);
        let report = KinematicReport::new(
            &motion,
            std::slice::from_ref(&slow),
            std::slice::from_ref(&slow),
            height,
            UpAxis::PosY,
        );
        let s = &report.raw;
        // Interpolated frames move half as far per frame; percentiles of a curve sampled twice
        // as densely shift a little, so within 5 %.
        for ratio in s.speed_ratios {
            assert!((ratio - 0.5).abs() < 0.025, "{name}: {:?}", s.speed_ratios);
        }
        // Half of every speed: the distance is half the mean, give or take the same shift.
        assert!(
            (s.speed_distance - 0.5).abs() < 0.025,
            "{name}: {}",
            s.speed_distance
        );
        // Accelerations fall to about a quarter, so about three quarters of the mean away
        // (interpolation puts the second difference on every other frame: at least half).
        assert!(
            s.acceleration_distance > 0.5,
            "{name}: {}",
            s.acceleration_distance
        );
        let missed: Vec<&str> = s
            .misses(report.clip.still_share)
            .iter()
            .map(|m| m.figure)
            .collect();
        assert!(missed.contains(&"speed p50 / clip's"), "{name}: {missed:?}");
        assert!(missed.contains(&"speed distance"), "{name}: {missed:?}");
        // A clip that turns turns half as fast, and never faster than it did.
        let turning = &report.turning;
        if name.contains("dance") {
            // The dance turns in place (about 110 degrees/s at its fastest percent).
            assert!(turning.clip.fast > 50.0, "{name}: {turning:?}");
        }
        if turning.clip.fast > 10.0 {
            let ratio = turning.raw.fast / turning.clip.fast;
            assert!((ratio - 0.5).abs() < 0.05, "{name}: {turning:?}");
        }
        assert_eq!(turning.raw.faster_than_clip, 0.0, "{name}: {turning:?}");
    }
}

#[test]
fn one_pose_held_is_still_throughout_and_a_whole_mean_away() {
    for name in CLIPS {
        let (motion, height) = clip(name);
        let still = held(&motion);
        let report = KinematicReport::new(
            &motion,
            std::slice::from_ref(&still),
            std::slice::from_ref(&still),
            height,
            UpAxis::PosY,
        );
        let s = &report.raw;
        assert_eq!(s.still_share, 1.0, "{name}");
        assert_eq!(s.speed_ratios, [0.0; 3], "{name}");
        assert!((s.speed_distance - 1.0).abs() < 1e-9, "{name}");
        assert!((s.acceleration_distance - 1.0).abs() < 1e-9, "{name}");
        assert_eq!(s.misses(report.clip.still_share).len(), 6, "{name}");
        assert_eq!(report.turning.raw.fast, 0.0, "{name}");
    }
}

/// `name`'s BVH text with a still ground joint added above its root (as some rigs have: a
/// `joint_Root` at the origin that never moves, the hips below it carrying the body).
fn with_ground_root(name: &str) -> LocalMotion {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/bvh")
        .join(name);
    let text = std::fs::read_to_string(path).unwrap();
    let (hierarchy, motion) = text.split_once("MOTION").unwrap();
    let hierarchy = hierarchy.replacen(
        "ROOT ",
        "ROOT ground\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\nJOINT ",
        1,
    );
    let mut lines = motion.lines();
    let mut text = format!("{}\n}}\nMOTION", hierarchy.trim_end());
    for line in lines.by_ref() {
        text.push_str(line);
        text.push('\n');
        if line.starts_with("Frame Time") {
            break;
        }
    }
    for line in lines.filter(|l| !l.trim().is_empty()) {
        text.push_str("0 0 0 0 0 0 ");
        text.push_str(line);
        text.push('\n');
    }
    resample(
        &sinmdm::bvh::parse_bvh(&text, "grounded.bvh")
            .unwrap()
            .to_local(),
        30.0,
    )
}

/// A still ground joint above the hips changes nothing: the body is measured from the joint
/// that carries it, so the body's travel is not counted as its motion.
#[test]
fn a_still_ground_joint_above_the_root_changes_nothing() {
    for name in ["human_walk_cmu_131_01.bvh", "fox_survey_khronos.bvh"] {
        let (motion, height) = clip(name);
        let grounded = with_ground_root(name);
        assert_eq!(grounded.skeleton.len(), motion.skeleton.len() + 1, "{name}");
        let plain = sinmdm_eval::Kinematics::of_motion(&motion, height);
        let ground = sinmdm_eval::Kinematics::of_motion(&grounded, height);
        assert_eq!(plain.speeds.len(), ground.speeds.len(), "{name}");
        let worst = plain
            .speeds
            .iter()
            .zip(&ground.speeds)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1e-9))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{name}: relative difference {worst}");
    }
}
