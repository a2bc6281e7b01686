//! A converter's bind pose in a clip's first frame is found and dropped before encoding, and no
//! captured first frame is taken for one: the encoded clip equals the encoding of the same file
//! with that frame's line deleted from its text.

mod common;

use sinmdm::bvh::{parse_bvh, read_bvh};
use sinmdm::motion::bind_pose::{BIND_POSE_MIN_DEGREES, leading_bind_pose, typical_turn};
use sinmdm::motion::{EncodeOptions, encode, encode_for_model};

/// The BVH text with its first frame's line removed and the frame count lowered by one.
fn without_first_frame_line(text: &str) -> String {
    let motion = text.find("MOTION").expect("a MOTION section");
    let (head, tail) = text.split_at(motion);
    let mut lines: Vec<&str> = tail.lines().collect();
    let frames_at = lines
        .iter()
        .position(|l| l.trim_start().starts_with("Frames:"))
        .unwrap();
    let count: usize = lines[frames_at]
        .split(':')
        .nth(1)
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let frames_line = format!("Frames: {}", count - 1);
    let first_frame = frames_at + 2; // after "Frame Time:"
    lines.remove(first_frame);
    lines[frames_at] = &frames_line;
    format!("{head}{}\n", lines.join("\n"))
}

#[test]
fn the_cmu_release_t_pose_is_dropped_as_if_the_file_lacked_it() {
    let path = common::workspace().join("lab/clips/human_dance_cmu_93_03.bvh");
    let text = std::fs::read_to_string(&path).unwrap();
    let clip = parse_bvh(&text, "with T-pose").unwrap();
    let found = leading_bind_pose(&clip.to_local()).expect("the T-pose frame is found");
    assert!(found.jump_degrees >= BIND_POSE_MIN_DEGREES, "{found:?}");
    assert!(found.describe().contains(&found.joint));

    let options = EncodeOptions::default();
    let with = encode(&clip, &options).unwrap();
    assert_eq!(with.bind_pose.as_ref(), Some(&found));
    let trimmed = parse_bvh(&without_first_frame_line(&text), "without").unwrap();
    assert_eq!(trimmed.frame_count() + 1, clip.frame_count());
    let without = encode(&trimmed, &options).unwrap();
    assert!(without.bind_pose.is_none(), "{:?}", without.bind_pose);
    assert_eq!(with.features, without.features);
    assert_eq!(with.layout, without.layout);
    // Read as a reference for a model of this skeleton (eval's --clip, the tasks'), the file
    // lines up with the clip the model learned, not with one a frame longer.
    let reference = encode_for_model(&clip, &with.layout, None).unwrap();
    assert_eq!(reference.features, without.features);
}

#[test]
fn no_captured_first_frame_is_taken_for_a_bind_pose() {
    let mut clips = common::shipped_clips();
    let lab = common::workspace().join("lab/clips");
    for entry in std::fs::read_dir(&lab).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "bvh")
            && !path.ends_with("human_dance_cmu_93_03.bvh")
        {
            clips.push(path);
        }
    }
    assert!(clips.len() >= 10, "{clips:?}");
    // A thumb that flips by 180 degrees (CMU's) counts as noise, not as motion.
    assert_eq!(typical_turn(&[1.0, 1.0, 1.0, 1.0, 180.0]), 1.0);
    for path in clips {
        let clip = read_bvh(&path).unwrap();
        let found = leading_bind_pose(&clip.to_local());
        assert!(found.is_none(), "{}: {found:?}", path.display());
    }
}

#[test]
fn a_rest_pose_put_before_a_walk_is_found_and_its_removal_restores_the_walk() {
    // The walk's own first frame, with every joint's rotation zeroed (the skeleton's rest pose,
    // as a converter writes it), put before the walk.
    let path = common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let walk = read_bvh(&path).unwrap();
    let width = walk.skeleton.channel_count();
    let starts = walk.skeleton.channel_starts();
    let mut rest = walk.values[..width].to_vec();
    for (j, joint) in walk.skeleton.joints.iter().enumerate() {
        for (c, channel) in joint.channels.iter().enumerate() {
            if matches!(channel, sinmdm::motion::skeleton::Channel::Rotation(_)) {
                rest[starts[j] + c] = 0.0;
            }
        }
    }
    let mut posed = walk.clone();
    posed.values = [rest, walk.values.clone()].concat();
    let found = leading_bind_pose(&posed.to_local()).expect("the rest pose is found");
    assert!(found.jump_degrees >= BIND_POSE_MIN_DEGREES);
    let options = EncodeOptions::default();
    let a = encode(&posed, &options).unwrap();
    let b = encode(&walk, &options).unwrap();
    assert!(a.bind_pose.is_some() && b.bind_pose.is_none());
    assert_eq!(a.features, b.features);
}
