//! Any clip as it comes: re-oriented copies of every clip (Z-up, X-up, -Z-up, turned about up)
//! are detected with the right up axis and encode to the features of the original; a Z-up copy
//! round-trips in its own frame; in-place cycles keep their contacts; weak evidence is reported.

mod common;

use sinmdm::bvh::{parse_bvh, read_bvh, to_bvh_string};
use sinmdm::motion::ground::travelling_root;
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::up::{UP, UpAxis, reorient};
use sinmdm::motion::{
    ChannelClip, ColumnKind, Confidence, EncodeOptions, EncodedClip, decode, detect_up, encode,
    global_poses, skeleton_height,
};

/// The clip written as BVH text and read back, as another tool would hand it over.
fn through_file(clip: &ChannelClip) -> ChannelClip {
    parse_bvh(&to_bvh_string(clip), "copy.bvh").unwrap()
}

/// A copy of `clip` turned by `rotation` and written as a file.
fn turned(clip: &ChannelClip, rotation: &Mat3) -> ChannelClip {
    through_file(&reorient(&clip.to_local(), rotation).to_channels())
}

fn name(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// The up axis each clip is known to have: the shared zombie walk was captured Z-up, every
/// other clip is Y-up.
fn known_up(path: &std::path::Path) -> UpAxis {
    if name(path) == "human_zombie_walk_fair.bvh" {
        UpAxis::PosZ
    } else {
        UpAxis::PosY
    }
}

/// A clip as a Y-up file: one captured with another up axis is re-oriented first, as
/// `sinmdm reorient --to y` does, so that the tests below can turn it into every other frame.
fn read_y_up(path: &std::path::Path) -> ChannelClip {
    let clip = read_bvh(path).unwrap();
    match known_up(path) {
        UpAxis::PosY => clip,
        up => turned(&clip, &up.canonical_from_file()),
    }
}

/// Largest difference between two feature arrays, column by column.
fn max_diff(a: &EncodedClip, b: &EncodedClip) -> f32 {
    assert_eq!(a.features.dim(), b.features.dim());
    a.features
        .iter()
        .zip(&b.features)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

#[test]
fn every_clip_is_read_with_its_own_up_axis_and_confidence() {
    let clips = common::all_clips();
    assert!(clips.len() >= 4, "the shipped clips are missing");
    for path in clips {
        let found = detect_up(&read_bvh(&path).unwrap().to_local());
        assert_eq!(
            found.axis,
            known_up(&path),
            "{}: {}",
            name(&path),
            found.describe()
        );
        assert_eq!(
            found.confidence,
            Confidence::Sure,
            "{}: {}",
            name(&path),
            found.describe()
        );
    }
}

#[test]
fn re_oriented_copies_are_detected_and_encode_to_the_same_features() {
    let clips = common::all_clips();
    assert!(clips.len() >= 4, "the shipped clips are missing");
    for path in clips {
        let clip = read_y_up(&path);
        let original = encode(&clip, &EncodeOptions::default()).unwrap();
        for up in [UpAxis::PosZ, UpAxis::PosX, UpAxis::NegZ] {
            let copy = turned(&clip, &up.file_from_canonical());
            let found = detect_up(&copy.to_local());
            assert_eq!(
                found.axis,
                up,
                "{} as {up}: {}",
                name(&path),
                found.describe()
            );
            assert_eq!(found.confidence, Confidence::Sure, "{}", found.describe());
            let encoded = encode(&copy, &EncodeOptions::default()).unwrap();
            assert_eq!(encoded.layout.up, up);
            assert_eq!(
                encoded.layout.contact_joints,
                original.layout.contact_joints
            );
            assert_eq!(
                encoded.layout.root,
                original.layout.root.clone().map(|mut r| {
                    // The start position is the same up to the text round trip.
                    r.start_position = encoded.layout.root.as_ref().unwrap().start_position;
                    r
                })
            );
            let start_a = original.layout.root.as_ref().map(|r| r.start_position);
            let start_b = encoded.layout.root.as_ref().map(|r| r.start_position);
            if let (Some(a), Some(b)) = (start_a, start_b) {
                let h = original.layout.skeleton_height;
                assert!((a - b).norm() < 1e-6 * h, "{a:?} {b:?}");
            }
            let h = original.layout.skeleton_height;
            assert!(
                (encoded.layout.skeleton_height - h).abs() < 1e-6 * h,
                "{}: height {} against {h}",
                name(&path),
                encoded.layout.skeleton_height
            );
            let diff = max_diff(&original, &encoded);
            assert!(
                diff < 1e-5,
                "{} as {up}: features differ by {diff}",
                name(&path)
            );
        }
    }
}

#[test]
fn a_turn_about_up_changes_only_the_root_heading() {
    for path in common::all_clips() {
        let clip = read_y_up(&path);
        let original = encode(&clip, &EncodeOptions::default()).unwrap();
        for degrees in [90.0f64, 180.0] {
            let turn = math::axis_rotation(UP, degrees.to_radians());
            let copy = turned(&clip, &turn);
            let found = detect_up(&copy.to_local());
            assert_eq!(found.axis, UpAxis::PosY, "{}", found.describe());
            let encoded = encode(&copy, &EncodeOptions::default()).unwrap();
            assert_eq!(
                encoded.layout.contact_joints,
                original.layout.contact_joints
            );
            let layout = &original.layout;
            let columns = layout.columns();
            let root = layout.root.as_ref().map(|r| r.joint);
            let top = 0;
            for (i, column) in columns.iter().enumerate() {
                let (a, b) = (original.features.row(i), encoded.features.row(i));
                let matches = |x: &dyn Fn(usize) -> f64| {
                    (0..a.len())
                        .map(|f| (x(f) - f64::from(b[f])).abs())
                        .fold(0.0, f64::max)
                };
                let worst = match column.kind {
                    // Ground displacements turn with the clip: compare the turned vector.
                    ColumnKind::RootDisplacement(axis) if root.is_some() => {
                        let dx = original.features.row(i - axis.index() / 2 * 2);
                        let dz = original.features.row(i - axis.index() / 2 * 2 + 2);
                        let k = axis.index();
                        matches(&|f| {
                            let v = turn * Vec3::new(f64::from(dx[f]), 0.0, f64::from(dz[f]));
                            v[k]
                        }) / layout.skeleton_height
                    }
                    // The top joint's heading turns (and the travelling joint's, taken in the
                    // canonical frame when it hangs below a container): premultiplied.
                    ColumnKind::Rotation6d(_)
                        if column.joint == top || root == Some(column.joint) =>
                    {
                        continue;
                    }
                    _ => matches(&|f| f64::from(a[f])),
                };
                assert!(
                    worst < 1e-5,
                    "{} turned {degrees}: column {} differs by {worst}",
                    name(&path),
                    layout.column_name(column)
                );
            }
        }
    }
}

#[test]
fn a_z_up_copy_round_trips_in_its_own_frame() {
    for path in common::all_clips() {
        let clip = read_y_up(&path);
        let copy = turned(&clip, &UpAxis::PosZ.file_from_canonical());
        let options = EncodeOptions {
            fps: None,
            ..EncodeOptions::default()
        };
        let encoded = encode(&copy, &options).unwrap();
        let written = through_file(
            &decode(&encoded.layout, encoded.features.view())
                .unwrap()
                .to_channels(),
        );
        assert_eq!(written.skeleton, copy.skeleton, "{}", name(&path));
        let before = global_poses(&copy.to_local());
        let after = global_poses(&written.to_local());
        let worst = common::max_position_error(&before, &after);
        let height = encoded.layout.skeleton_height;
        assert!(
            worst <= 1e-4 * height,
            "{}: {worst} > 1e-4 x {height}",
            name(&path)
        );
        // And it is Z-up: the body's vertical extent is along Z.
        let body = encoded.layout.body();
        let z_extent: f64 = after
            .iter()
            .map(|p| {
                let zs: Vec<f64> = body.points(p).map(|q| q[2]).collect();
                zs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - zs.iter().copied().fold(f64::INFINITY, f64::min)
            })
            .sum::<f64>()
            / after.len() as f64;
        assert!(
            (z_extent - height).abs() < 1e-6 * height,
            "{z_extent} {height}"
        );
    }
}

/// The clip with the root's travel on the ground removed (in a Y-up file: its X and Z
/// positions held at frame 0's), as a game's in-place cycle has it.
fn in_place_copy(clip: &ChannelClip) -> ChannelClip {
    let mut local = clip.to_local();
    let joints = local.skeleton.len();
    let root = travelling_root(&local.skeleton, &global_poses(&local));
    let start = local.translations[root];
    for f in 0..local.frame_count() {
        let t = &mut local.translations[f * joints + root];
        t[0] = start[0];
        t[2] = start[2];
    }
    through_file(&local.to_channels())
}

#[test]
fn no_shipped_or_shared_clip_is_taken_for_an_in_place_cycle() {
    for path in common::all_clips() {
        let encoded = encode(&read_bvh(&path).unwrap(), &EncodeOptions::default()).unwrap();
        assert!(!encoded.in_place, "{} is not in place", name(&path));
    }
}

#[test]
fn in_place_cycles_keep_their_contacts() {
    let walks_and_dogs: Vec<_> = common::all_clips()
        .into_iter()
        .filter(|p| {
            let n = name(p);
            // The zombie walk turns round half way: held in place it is no treadmill (its feet
            // drift one way, then the other), which the in-place measure does not model.
            (n.contains("walk") || n.starts_with("dog_")) && n != "human_zombie_walk_fair.bvh"
        })
        .collect();
    assert!(!walks_and_dogs.is_empty());
    for path in walks_and_dogs {
        let clip = read_y_up(&path);
        let travelling = encode(&clip, &EncodeOptions::default()).unwrap();
        let options = EncodeOptions {
            contacts: sinmdm::motion::ContactConfig {
                joints: Some(
                    travelling
                        .layout
                        .contact_joints
                        .iter()
                        .map(|&j| travelling.layout.skeleton.joints[j].name.clone())
                        .collect(),
                ),
                ..Default::default()
            },
            ..EncodeOptions::default()
        };
        let cycle = encode(&in_place_copy(&clip), &options).unwrap();
        assert!(
            cycle.in_place,
            "{}: not recognised as in place",
            name(&path)
        );
        for (k, (a, b)) in travelling
            .contact_share
            .iter()
            .zip(&cycle.contact_share)
            .enumerate()
        {
            let joint = &travelling.layout.skeleton.joints[travelling.layout.contact_joints[k]];
            assert!(
                (a - b).abs() <= 0.10,
                "{} {}: {:.0}% in contact travelling, {:.0}% in place",
                name(&path),
                joint.name,
                a * 100.0,
                b * 100.0
            );
        }
    }
}

#[test]
fn weak_evidence_is_reported_not_hidden() {
    let clip =
        read_bvh(common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh")).unwrap();
    // A single frame.
    let mut one = clip.clone();
    let width = one.skeleton.channel_count();
    one.values.truncate(width);
    let found = detect_up(&one.to_local());
    assert_eq!(found.confidence, Confidence::Unsure, "{}", found.describe());
    assert!(found.describe().contains("UNSURE"));
    // A figure lying at 45 degrees: no axis fits.
    let tilt = math::axis_rotation(2, 45f64.to_radians());
    let found = detect_up(&turned(&clip, &tilt).to_local());
    assert_eq!(found.confidence, Confidence::Unsure, "{}", found.describe());
    // An explicit axis wins and skips the detection.
    let options = EncodeOptions {
        up: Some(UpAxis::PosY),
        ..EncodeOptions::default()
    };
    let encoded = encode(&one, &options).unwrap();
    assert!(encoded.up_detection.is_none());
    assert_eq!(encoded.layout.up, UpAxis::PosY);
    // The skeleton height is measured along the given axis: a Z-up copy read as Z-up has the
    // original's height, read as Y-up it has its depth.
    let copy = turned(&clip, &UpAxis::PosZ.file_from_canonical());
    let height = skeleton_height(&global_poses(&clip.to_local()));
    let as_z = EncodeOptions {
        up: Some(UpAxis::PosZ),
        fps: None,
        ..EncodeOptions::default()
    };
    let as_y = EncodeOptions {
        up: Some(UpAxis::PosY),
        ..as_z.clone()
    };
    let z = encode(&copy, &as_z).unwrap().layout.skeleton_height;
    let y = encode(&copy, &as_y).unwrap().layout.skeleton_height;
    assert!((z - height).abs() < 1e-6 * height, "{z} {height}");
    assert!(
        y < 0.8 * height,
        "read as Y-up the copy is {y} high, the figure {height}"
    );
}

/// The clip below a static container joint (as some rigs have it), with the body turned by
/// `turn` inside the container's frame: a Z-up rig whose container is not rotated.
fn in_container(clip: &ChannelClip, turn: &Mat3) -> ChannelClip {
    use sinmdm::motion::{Axis, Channel, Joint, Skeleton};
    let mut joints = vec![Joint {
        name: "container".into(),
        parent: None,
        offset: Vec3::ZERO,
        channels: vec![
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::X),
            Channel::Rotation(Axis::Y),
        ],
        end_site: None,
    }];
    for joint in &clip.skeleton.joints {
        let mut joint = joint.clone();
        joint.parent = Some(joint.parent.map_or(0, |p| p + 1));
        joints.push(joint);
    }
    let width = clip.skeleton.channel_count();
    let values = (0..clip.frame_count())
        .flat_map(|f| {
            [0.0; 3]
                .into_iter()
                .chain(clip.values[f * width..(f + 1) * width].iter().copied())
        })
        .collect();
    let wrapped = ChannelClip {
        skeleton: Skeleton { joints },
        fps: clip.fps,
        values,
    };
    let mut local = wrapped.to_local();
    let n = local.skeleton.len();
    for f in 0..local.frame_count() {
        let k = f * n + 1;
        local.rotations[k] = turn * local.rotations[k];
        local.translations[k] = turn * local.translations[k];
    }
    through_file(&local.to_channels())
}

#[test]
fn a_z_up_rig_below_a_static_container_reads_like_its_y_up_twin() {
    let clip =
        read_bvh(common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh")).unwrap();
    let y_up = in_container(&clip, &math::IDENTITY);
    let z_up = in_container(&clip, &UpAxis::PosZ.file_from_canonical());
    let found = detect_up(&z_up.to_local());
    assert_eq!(found.axis, UpAxis::PosZ, "{}", found.describe());
    assert_eq!(found.confidence, Confidence::Sure, "{}", found.describe());
    let a = encode(&y_up, &EncodeOptions::default()).unwrap();
    let b = encode(&z_up, &EncodeOptions::default()).unwrap();
    assert_eq!(a.layout.root.as_ref().unwrap().joint, 1);
    assert_eq!(b.layout.root.as_ref().unwrap().joint, 1);
    assert_eq!(a.layout.contact_joints, b.layout.contact_joints);
    let h = a.layout.skeleton_height;
    assert!((a.layout.skeleton_height - b.layout.skeleton_height).abs() < 1e-6 * h);
    // Every column but the container's own (constant) rotation is the same.
    for (i, column) in a.layout.columns().iter().enumerate() {
        if column.joint == 0 {
            continue;
        }
        let worst = a
            .features
            .row(i)
            .iter()
            .zip(b.features.row(i))
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f32::max);
        assert!(
            worst < 1e-5,
            "{} differs by {worst}",
            a.layout.column_name(column)
        );
    }
    // And the Z-up rig round-trips in its own frame.
    let options = EncodeOptions {
        fps: None,
        ..EncodeOptions::default()
    };
    let encoded = encode(&z_up, &options).unwrap();
    let back = decode(&encoded.layout, encoded.features.view()).unwrap();
    let worst = common::max_position_error(&global_poses(&z_up.to_local()), &global_poses(&back));
    assert!(worst <= 1e-4 * h, "{worst}");
}
