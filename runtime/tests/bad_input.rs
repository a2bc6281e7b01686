//! Bad BVH input gets a clear error that names the file and line (or joint), never a panic.

use sinmdm::bvh::{BvhErrorKind, parse_bvh, read_bvh};

/// A small valid clip (shared with the other crates' tests): a root with 6 channels, one child
/// with 3, an End Site, two frames.
const VALID: &str = include_str!("../../tests/data/two_joints.bvh");

fn error_of(text: &str) -> sinmdm::bvh::BvhError {
    parse_bvh(text, "clip.bvh").expect_err("the text should be rejected")
}

#[test]
fn the_valid_base_clip_parses() {
    let clip = parse_bvh(VALID, "clip.bvh").unwrap();
    assert_eq!(clip.frame_count(), 2);
    assert_eq!(clip.fps, 30.0);
    assert_eq!(
        clip.skeleton.joints[1].end_site,
        Some(sinmdm::motion::math::Vec3::new(0.0, 5.0, 0.0))
    );
}

#[test]
fn crlf_line_ends_parse_like_lf() {
    let crlf = VALID.replace('\n', "\r\n");
    assert_eq!(
        parse_bvh(&crlf, "a").unwrap(),
        parse_bvh(VALID, "a").unwrap()
    );
}

#[test]
fn empty_file() {
    let e = error_of("  \n\n");
    assert!(matches!(e.kind, BvhErrorKind::Empty));
    assert_eq!(e.to_string(), "clip.bvh: the file is empty");
}

#[test]
fn truncated_motion_block() {
    let cut = VALID.trim_end().rsplit_once('\n').unwrap().0;
    let e = error_of(cut);
    assert!(matches!(
        e.kind,
        BvhErrorKind::Truncated {
            announced: 2,
            found: 1
        }
    ));
    assert!(
        e.to_string()
            .starts_with("clip.bvh:19: truncated MOTION block"),
        "{e}"
    );
}

#[test]
fn wrong_number_of_values_on_a_line() {
    let e = error_of(&VALID.replace("1 90 0 0 0 0 20 0 0", "1 90 0 0 0 0 20 0"));
    assert!(matches!(
        e.kind,
        BvhErrorKind::WrongValueCount {
            frame: 1,
            expected: 9,
            found: 8
        }
    ));
    assert_eq!(e.line, Some(20));
}

#[test]
fn nan_and_infinity_name_the_line_and_channel() {
    let e = error_of(&VALID.replace("1 90 0 0 0 0 20 0 0", "1 90 0 0 0 0 NaN 0 0"));
    assert!(matches!(e.kind, BvhErrorKind::NonFinite { .. }));
    assert_eq!(e.line, Some(20));
    assert!(e.to_string().contains("Spine Zrotation"), "{e}");
    let e = error_of(&VALID.replace("OFFSET 0 10 0", "OFFSET 0 inf 0"));
    assert!(matches!(e.kind, BvhErrorKind::NonFinite { .. }));
    assert_eq!(e.line, Some(8));
    assert!(e.to_string().contains("OFFSET of joint 'Spine'"), "{e}");
}

#[test]
fn unknown_channel_name() {
    let e = error_of(&VALID.replace(
        "CHANNELS 3 Zrotation Xrotation Yrotation",
        "CHANNELS 3 Zrotation Xrot Yrotation",
    ));
    match &e.kind {
        BvhErrorKind::UnknownChannel { joint, name } => {
            assert_eq!((joint.as_str(), name.as_str()), ("Spine", "Xrot"));
        }
        other => panic!("wrong error {other:?}"),
    }
    assert_eq!(e.line, Some(9));
}

#[test]
fn a_joint_with_no_channels() {
    let e = error_of(&VALID.replace("\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n", ""));
    match &e.kind {
        BvhErrorKind::NoChannels { joint } => assert_eq!(joint, "Spine"),
        other => panic!("wrong error {other:?}"),
    }
    let zero = error_of(&VALID.replace("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 0"));
    assert!(matches!(zero.kind, BvhErrorKind::NoChannels { .. }));
}

#[test]
fn zero_frames() {
    let e = error_of(&VALID.replace("Frames: 2", "Frames: 0"));
    assert!(matches!(e.kind, BvhErrorKind::ZeroFrames));
    assert_eq!(e.line, Some(17));
}

#[test]
fn more_problems_each_with_a_clear_message() {
    let cases: &[(&str, &str, &str)] = &[
        ("HIERARCHY", "HIERARCHIE", "expected HIERARCHY"),
        (
            "Frame Time: 0.0333333",
            "Frame Time: 0",
            "Frame Time must be a positive",
        ),
        ("Frames: 2", "Frames: two", "'two' is not a number"),
        (
            "JOINT Spine",
            "JOINT Hips",
            "joint name 'Hips' is used twice",
        ),
        ("\tOFFSET 0 10 0", "\tOFFSET 0 10", "is not a number"),
        (
            "Zrotation Xrotation Yrotation\n\t\tEnd",
            "Zrotation Zrotation Yrotation\n\t\tEnd",
            "listed twice",
        ),
        (
            "1 90 0 0 0 0 20 0 0\n",
            "1 90 0 0 0 0 20 0 0\n2 90 0 0 0 0 20 0 0\n",
            "more frame lines",
        ),
        ("MOTION\n", "", "expected MOTION"),
        ("\t}\n}\nMOTION", "\t}\nMOTION", "closing joint 'Hips'"),
    ];
    for (from, to, message) in cases {
        assert!(VALID.contains(from), "{from}");
        let e = error_of(&VALID.replacen(from, to, 1));
        assert!(e.line.is_some(), "{e}");
        assert!(e.to_string().contains(message), "'{e}' lacks '{message}'");
    }
}

#[test]
fn missing_file_names_the_path() {
    let e = read_bvh("no/such/clip.bvh").unwrap_err();
    assert!(matches!(e.kind, BvhErrorKind::Io(_)));
    assert!(e.to_string().starts_with("no/such/clip.bvh: "), "{e}");
}

/// A chain of `joints` nested joints with two frames, as BVH text.
fn chain(joints: usize) -> String {
    let mut text = String::from("HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\n");
    text += "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
    for j in 1..joints {
        text +=
            &format!("JOINT j{j}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n");
    }
    text += "End Site\n{\nOFFSET 0 1 0\n}\n";
    text += &"}\n".repeat(joints);
    let frame = vec!["0"; 6 + 3 * (joints - 1)].join(" ");
    text += &format!("MOTION\nFrames: 2\nFrame Time: 0.0333333\n{frame}\n{frame}\n");
    text
}

#[test]
fn a_chain_of_the_most_joints_reads_and_a_longer_one_is_refused() {
    use sinmdm::bvh::MAX_BVH_JOINTS;
    let clip = parse_bvh(&chain(MAX_BVH_JOINTS), "chain.bvh").unwrap();
    assert_eq!(clip.skeleton.joints.len(), MAX_BVH_JOINTS);
    let e = parse_bvh(&chain(20_000), "deep.bvh").unwrap_err();
    assert!(matches!(e.kind, BvhErrorKind::OverLimit { .. }));
    assert!(
        e.to_string().contains(
            "joint 'j4096' is joint 4097: more than the 4096 a BVH file may have (MAX_BVH_JOINTS)"
        ),
        "{e}"
    );
}

#[test]
fn only_regular_files_are_read() {
    let dir = std::env::temp_dir().join(format!("sinmdm-bvh-dir-{}.bvh", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let e = read_bvh(&dir).unwrap_err();
    assert!(
        e.to_string().contains("is a directory, not a regular file"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    #[cfg(unix)]
    {
        let e = read_bvh("/dev/zero").unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
}

#[test]
fn bad_encoder_settings_are_errors() {
    use sinmdm::motion::{ContactConfig, EncodeOptions, MotionError, encode};
    let clip = parse_bvh(VALID, "clip.bvh").unwrap();
    let with = |contacts: ContactConfig, fps: Option<f64>| {
        encode(
            &clip,
            &EncodeOptions {
                fps,
                contacts,
                ..EncodeOptions::default()
            },
        )
    };
    let unknown = ContactConfig {
        joints: Some(vec!["LeftFoot".into()]),
        ..ContactConfig::default()
    };
    match with(unknown, None).unwrap_err() {
        MotionError::UnknownContactJoint { name, available } => {
            assert_eq!(name, "LeftFoot");
            assert_eq!(available, "Hips, Spine");
        }
        other => panic!("wrong error {other:?}"),
    }
    let negative = ContactConfig {
        speed_threshold: -1.0,
        ..ContactConfig::default()
    };
    assert!(matches!(
        with(negative, None).unwrap_err(),
        MotionError::BadContactSetting {
            what: "speed threshold",
            ..
        }
    ));
    assert!(matches!(
        with(ContactConfig::default(), Some(0.0)).unwrap_err(),
        MotionError::BadFrameRate(_)
    ));
}
