//! The feature layout survives serialisation (it will travel in the ONNX metadata), and the
//! engine poses rebuild the same skeleton as the decoder.

mod common;

use sinmdm::bvh::read_bvh;
use sinmdm::motion::math::{self, mat_from_quat};
use sinmdm::motion::{
    ColumnKind, EncodeOptions, FeatureLayout, Normalizer, decode, encode, global_poses, poses,
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
    let stats = Normalizer::fit(encoded.features.view());
    let z = stats.normalize(encoded.features.view());
    // Standardised rows have zero mean; varying rows have unit variance.
    for row in z.rows() {
        let mean = row.mean().unwrap();
        assert!(mean.abs() < 1e-3, "{mean}");
    }
    let back = stats.denormalize(z.view());
    let a = global_poses(&decode(&encoded.layout, encoded.features.view()).unwrap());
    let b = global_poses(&decode(&encoded.layout, back.view()).unwrap());
    let height = encoded.layout.skeleton_height;
    for (p, q) in a.iter().zip(&b) {
        for (x, y) in p.points().zip(q.points()) {
            assert!(math::norm(math::sub(x, y)) < 1e-4 * height);
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
    let skeleton = &motion.skeleton;
    for (pose, want) in frames.iter().zip(&reference) {
        // Independent FK from the quaternions ([x, y, z, w]) and translations alone.
        let mut positions: Vec<[f64; 3]> = Vec::new();
        let mut rotations = Vec::new();
        for (j, joint) in skeleton.joints.iter().enumerate() {
            let [x, y, z, w] = pose.rotations[j].map(f64::from);
            let local = mat_from_quat([w, x, y, z]);
            let t = pose.translations[j].map(f64::from);
            let (p, r) = match joint.parent {
                None => (t, local),
                Some(parent) => (
                    math::add(positions[parent], math::mat_vec(&rotations[parent], t)),
                    math::mat_mul(&rotations[parent], &local),
                ),
            };
            positions.push(p);
            rotations.push(r);
        }
        assert_eq!(pose.root_position, pose.translations[0]);
        for (p, q) in positions.iter().zip(&want.joints) {
            assert!(math::norm(math::sub(*p, *q)) < 1e-4 * encoded.layout.skeleton_height);
        }
    }
}
