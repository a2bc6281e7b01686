//! BVH -> features -> BVH reproduces every joint's global position in every frame, for every
//! clip we have, and our reader agrees with an independent one (`bvh_anim`).

mod common;

use sinmdm::bvh::{parse_bvh, read_bvh, to_bvh_string};
use sinmdm::motion::{
    ChannelClip, EncodeOptions, GlobalPose, decode, encode, global_poses, skeleton_height,
};

use common::max_position_error;

#[test]
fn round_trip_at_the_clips_own_rate_reproduces_global_positions() {
    let clips = common::all_clips();
    assert!(clips.len() >= 4, "the shipped clips are missing");
    for path in clips {
        let clip = read_bvh(&path).unwrap();
        let options = EncodeOptions {
            fps: None,
            ..EncodeOptions::default()
        };
        let encoded = encode(&clip, &options).unwrap();
        let decoded = decode(&encoded.layout, encoded.features.view()).unwrap();
        let text = to_bvh_string(&decoded.to_channels());
        let reread = parse_bvh(&text, "roundtrip").unwrap();

        // Same skeleton: names, parents, offsets, channel lists and orders; same rate and length.
        assert_eq!(reread.skeleton, clip.skeleton, "{}", path.display());
        assert_eq!(reread.fps, clip.fps);
        assert_eq!(reread.frame_count(), clip.frame_count());

        let original = global_poses(&clip.to_local());
        let height = skeleton_height(&original);
        let error = max_position_error(&original, &global_poses(&reread.to_local()));
        assert!(
            error <= 1e-4 * height,
            "{}: error {error} exceeds 1e-4 x height {height}",
            path.display()
        );
        println!(
            "{}: max error {:.2e} x height",
            path.display(),
            error / height
        );
    }
}

#[test]
fn resampling_at_an_integer_ratio_keeps_every_kept_frame() {
    // 120 fps -> 30 fps keeps every 4th frame exactly (slerp/lerp at weight 0).
    let path = common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let clip = read_bvh(&path).unwrap();
    assert_eq!(clip.fps, 120.0);
    let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
    assert_eq!(encoded.layout.fps, 30.0);
    let frames = encoded.features.ncols();
    assert_eq!(frames, (clip.frame_count() - 1) / 4 + 1);
    let decoded = global_poses(&decode(&encoded.layout, encoded.features.view()).unwrap());
    let original = global_poses(&clip.to_local());
    let every_fourth: Vec<GlobalPose> = original.iter().step_by(4).cloned().collect();
    let height = skeleton_height(&original);
    assert!(max_position_error(&every_fourth, &decoded) <= 1e-4 * height);
}

#[test]
fn our_reader_agrees_with_bvh_anim() {
    for path in common::all_clips() {
        let ours: ChannelClip = read_bvh(&path).unwrap();
        let theirs = bvh_anim::from_bytes(std::fs::read(&path).unwrap()).unwrap();
        // bvh_anim lists End Sites as extra joints (flagged by having an end-site offset).
        let their_joints: Vec<_> = theirs
            .joints()
            .filter(|j| j.data().end_site().is_none() || !j.data().channels().is_empty())
            .collect();
        assert_eq!(
            their_joints.len(),
            ours.skeleton.len(),
            "{}",
            path.display()
        );
        for (mine, theirs) in ours.skeleton.joints.iter().zip(&their_joints) {
            let data = theirs.data();
            assert_eq!(mine.name, data.name().to_string());
            let offset = data.offset();
            for (a, b) in mine.offset.iter().zip([offset.x, offset.y, offset.z]) {
                assert!((a - f64::from(b)).abs() <= 1e-5 * (1.0 + a.abs()));
            }
            let names: Vec<String> = data
                .channels()
                .iter()
                .map(|c| c.channel_type().to_string())
                .collect();
            let my_names: Vec<String> = mine.channels.iter().map(|c| c.to_string()).collect();
            assert_eq!(my_names, names, "{} {}", path.display(), mine.name);
        }
        let their_frames: Vec<Vec<f32>> = theirs.frames().map(|f| f.as_slice().to_vec()).collect();
        assert_eq!(their_frames.len(), ours.frame_count());
        for (f, frame) in their_frames.iter().enumerate() {
            assert_eq!(
                ours.frame(f).len(),
                frame.len(),
                "{} frame {f}",
                path.display()
            );
            for (a, b) in ours.frame(f).iter().zip(frame) {
                assert!((a - f64::from(*b)).abs() <= 1e-6 * (1.0 + a.abs()));
            }
        }
        let their_fps = 1.0 / theirs.frame_time().as_secs_f64();
        assert!((their_fps - ours.fps).abs() / ours.fps < 1e-3);
    }
}
