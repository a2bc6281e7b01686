//! The feature layout survives serialisation (it will travel in the ONNX metadata), and the
//! engine poses rebuild the same skeleton as the decoder.

mod common;

use sinmdm::bvh::read_bvh;
use sinmdm::motion::math::{Vec3, mat_from_quat};
use sinmdm::motion::{
    ColumnKind, EncodeOptions, FeatureLayout, Normalizer, STD_FLOOR_SHARE, decode, encode,
    global_poses, poses,
};

#[test]
fn layout_round_trips_through_json_and_describes_every_column() {
    let clip = read_bvh(common::workspace().join("tests/data/bvh/fox_survey_khronos.bvh")).unwrap();
    let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
    let json = serde_json::to_string(&encoded.layout).unwrap();
    let back: FeatureLayout = serde_json::from_str(&json).unwrap();
    assert_eq!(back, encoded.layout);

    let columns = back.columns();
    assert_eq!(columns.len(), back.width());
    assert_eq!(columns.len(), encoded.features.nrows());
    // The fox: root dX Y dZ, 22 rotating joints, contacts last.
    assert_eq!(back.width(), 3 + 22 * 6 + back.contact_joints.len());
    assert!(matches!(columns[0].kind, ColumnKind::RootDisplacement(_)));
    assert!(matches!(columns.last().unwrap().kind, ColumnKind::Contact));
    let neck = back.skeleton.find("b_Neck_04").unwrap();
    let neck_columns = back.joint_columns(neck);
    assert_eq!(neck_columns.len(), 6);
    assert_eq!(
        back.column_name(&columns[neck_columns[0]]),
        "b_Neck_04.rot6d[0]"
    );
}

#[test]
fn normalised_features_decode_after_denormalising() {
    let clip =
        read_bvh(common::workspace().join("tests/data/bvh/human_hop_cmu_131_03.bvh")).unwrap();
    let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
    let stats = Normalizer::fit(encoded.features.view(), STD_FLOOR_SHARE);
    let z = stats.normalize(encoded.features.view());
    // Standardised rows have zero mean; rows whose spread is above the std floor have unit
    // variance, the floored (near-constant) ones less.
    let mut unit = 0;
    for (r, (zr, xr)) in z
        .rows()
        .into_iter()
        .zip(encoded.features.rows())
        .enumerate()
    {
        let mean = f64::from(zr.mean().unwrap());
        assert!(mean.abs() < 1e-3, "row {r}: mean {mean}");
        let variance = zr.mapv(|v| (f64::from(v) - mean).powi(2)).mean().unwrap();
        let raw_std = xr.mapv(f64::from).std(0.0);
        if raw_std >= f64::from(stats.std[r]) * (1.0 - 1e-4) {
            assert!(
                (variance - 1.0).abs() < 1e-3,
                "row {r}: variance {variance}"
            );
            unit += 1;
        } else {
            assert!(variance < 1.0, "floored row {r}: variance {variance}");
        }
    }
    assert!(
        unit > z.nrows() / 2,
        "only {unit} of {} rows vary",
        z.nrows()
    );
    let back = stats.denormalize(z.view());
    let a = global_poses(&decode(&encoded.layout, encoded.features.view()).unwrap());
    let b = global_poses(&decode(&encoded.layout, back.view()).unwrap());
    let height = encoded.layout.skeleton_height;
    for (p, q) in a.iter().zip(&b) {
        for (x, y) in p.points().zip(q.points()) {
            assert!((x - y).norm() < 1e-4 * height);
        }
    }
}

#[test]
fn engine_poses_rebuild_the_decoded_skeleton() {
    let clip =
        read_bvh(common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh")).unwrap();
    let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
    let motion = decode(&encoded.layout, encoded.features.view()).unwrap();
    let frames = poses(&motion);
    assert_eq!(frames.len(), motion.frame_count());
    let reference = global_poses(&motion);
    // The clip is 120 fps and the features 30 fps: every 4th original frame, whose root the
    // poses must put where the file has it.
    let original = global_poses(&clip.to_local());
    let height = encoded.layout.skeleton_height;
    let skeleton = &motion.skeleton;
    for (f, (pose, want)) in frames.iter().zip(&reference).enumerate() {
        // Independent FK from the quaternions ([x, y, z, w]) and translations alone.
        let mut positions: Vec<Vec3> = Vec::new();
        let mut rotations = Vec::new();
        for (j, joint) in skeleton.joints.iter().enumerate() {
            let q = pose.rotations[j];
            let local = mat_from_quat([q.x, q.y, q.z, q.w].map(f64::from));
            let t = Vec3(pose.translations[j].map(f64::from));
            let (p, r) = match joint.parent {
                None => (t, local),
                Some(parent) => (
                    (positions[parent] + (rotations[parent] * t)),
                    (rotations[parent] * local),
                ),
            };
            positions.push(p);
            rotations.push(r);
        }
        let root = Vec3(pose.root_position().map(f64::from));
        let file_root = original[4 * f].joints[0];
        assert!(
            (root - file_root).norm() < 1e-4 * height,
            "frame {f}: root {root:?}, file {file_root:?}"
        );
        for (p, q) in positions.iter().zip(&want.joints) {
            assert!((*p - *q).norm() < 1e-4 * encoded.layout.skeleton_height);
        }
    }
}

#[test]
fn poses_in_give_back_the_features_they_came_from() {
    use sinmdm::motion::{MotionError, features_from_poses};
    let clip = read_bvh(common::workspace().join("tests/data/bvh/fox_survey_khronos.bvh")).unwrap();
    let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
    let layout = &encoded.layout;
    let out = poses(&decode(layout, encoded.features.view()).unwrap());
    let back = features_from_poses(layout, &out).unwrap();
    // Every row but the contact labels (measured again from the feet) and the first frame's
    // displacement (nothing before it) comes back within f32 rounding.
    let contacts = layout.contact_rows();
    for row in (0..layout.width()).filter(|r| !contacts.contains(r)) {
        for frame in 1..back.ncols() {
            let (a, b) = (back[[row, frame]], encoded.features[[row, frame]]);
            assert!(
                (a - b).abs() < 1e-3 * (1.0 + b.abs()),
                "row {row} frame {frame}: {a} vs {b}"
            );
        }
    }
    // Bad poses name the frame and the joint.
    let mut bad = out.clone();
    bad[3].rotations[2] = sinmdm::Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 0.0,
    };
    let e = features_from_poses(layout, &bad).unwrap_err();
    assert!(matches!(e, MotionError::BadPose { frame: 3, .. }), "{e}");
    assert!(
        e.to_string().contains(&layout.skeleton.joints[2].name),
        "{e}"
    );
    bad[3].rotations.pop();
    assert!(
        features_from_poses(layout, &bad)
            .unwrap_err()
            .to_string()
            .contains("rotations")
    );
    assert_eq!(
        features_from_poses(layout, &[]).unwrap_err(),
        MotionError::NoPoses
    );
}
