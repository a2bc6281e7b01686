//! A static container above the body (a rig's root bone left below the figure while the hips
//! walk away, as Bandai's `joint_Root`; or tilted, as an exporter's Z-up armature node) is not
//! part of the body: planting neither lifts the figure off the floor to clear it nor moves it.

use std::path::Path;

use sinmdm::bvh::read_bvh;
use sinmdm::motion::feet::{Kept, PlantOptions, plant_feet};
use sinmdm::motion::math::{Mat3, Vec3, axis_rotation};
use sinmdm::motion::{
    Axis, Channel, FeatureLayout, Joint, LocalMotion, Skeleton, decode, encode, global_poses,
};

const WALK: &str = "../tests/data/bvh/human_walk_cmu_131_01.bvh";
/// Where the container sits, in file units: under the walk's floor (its feet rest near -0.2).
const CONTAINER_AT: Vec3 = Vec3([3.0, -10.0, 2.0]);
/// Frames of the walk kept (at its 120 fps: two seconds).
const FRAMES: usize = 240;

/// The container's turn: a quarter turn about X (its up axis lies along the world's Z), then a
/// third of one about the world's up, so no axis of it is the world's.
fn container_turn() -> Mat3 {
    axis_rotation(1, 60f64.to_radians()) * axis_rotation(0, -90f64.to_radians())
}

/// The first [`FRAMES`] of the walk, and the same motion with its hips inside a static container
/// at [`CONTAINER_AT`] turned by [`container_turn`]: the hips' translations and rotations are
/// given in the container's frame, so the body moves in the world exactly as the plain walk.
fn walk_and_walk_in_container() -> (LocalMotion, LocalMotion) {
    let mut plain = read_bvh(Path::new(WALK)).unwrap().to_local();
    let joints = plain.skeleton.len();
    plain.rotations.truncate(FRAMES * joints);
    plain.translations.truncate(FRAMES * joints);
    let turn = container_turn();
    let back = turn.transpose();
    let container = Joint {
        name: "Container".into(),
        parent: None,
        offset: Vec3([0.0; 3]),
        channels: [Axis::X, Axis::Y, Axis::Z]
            .map(Channel::Position)
            .into_iter()
            .chain([Axis::Z, Axis::X, Axis::Y].map(Channel::Rotation))
            .collect(),
        end_site: None,
    };
    let body = plain.skeleton.joints.iter().map(|j| Joint {
        parent: Some(j.parent.map_or(0, |p| p + 1)),
        ..j.clone()
    });
    let skeleton = Skeleton {
        joints: std::iter::once(container).chain(body).collect(),
    };
    let (mut rotations, mut translations) = (Vec::new(), Vec::new());
    for f in 0..FRAMES {
        let frame = f * joints..(f + 1) * joints;
        let (r, t) = (&plain.rotations[frame.clone()], &plain.translations[frame]);
        rotations.push(turn);
        translations.push(CONTAINER_AT);
        rotations.push(back * r[0]);
        translations.push(back * (t[0] - CONTAINER_AT));
        rotations.extend_from_slice(&r[1..]);
        translations.extend_from_slice(&t[1..]);
    }
    let wrapped = LocalMotion {
        skeleton,
        fps: plain.fps,
        rotations,
        translations,
    };
    (plain, wrapped)
}

/// A clip's layout, its own motion decoded from its features, and its contact labels.
fn encoded(motion: &LocalMotion) -> (FeatureLayout, LocalMotion, Vec<Vec<f32>>) {
    let clip = encode(&motion.to_channels(), &Default::default()).unwrap();
    let decoded = decode(&clip.layout, clip.features.view()).unwrap();
    let labels = clip.layout.contact_labels(clip.features.view());
    (clip.layout, decoded, labels)
}

/// The motion planted with its labels, the root carried with the stance (so that the root is
/// moved both along the ground and up).
fn planted(layout: &FeatureLayout, motion: &LocalMotion, labels: &[Vec<f32>]) -> LocalMotion {
    let options = PlantOptions {
        root_stance_share: 1.0,
        ..PlantOptions::default()
    };
    plant_feet(layout, motion, labels, &Kept::default(), &options)
        .unwrap()
        .0
}

#[test]
fn planting_leaves_a_container_where_the_file_put_it_and_the_body_on_its_floor() {
    let (plain, wrapped) = walk_and_walk_in_container();
    let (plain_layout, plain_motion, plain_labels) = encoded(&plain);
    let (layout, motion, labels) = encoded(&wrapped);
    assert_eq!(layout.skeleton.joints[layout.carrier()].name, "Hips");
    assert_eq!(labels, plain_labels, "the same feet in contact");
    let (h, plain_h) = (layout.skeleton_height, plain_layout.skeleton_height);
    assert!(
        (h - plain_h).abs() < 1e-6 * h,
        "height {h} against {plain_h}"
    );
    assert!(
        (layout.ground.unwrap() - plain_layout.ground.unwrap()).abs() < 1e-6 * h,
        "the ground is the feet's, not the container's: {:?} against {:?}",
        layout.ground,
        plain_layout.ground
    );

    let plain = global_poses(&planted(&plain_layout, &plain_motion, &plain_labels));
    let wrapped = global_poses(&planted(&layout, &motion, &labels));
    let mut farthest: f64 = 0.0;
    for (p, w) in plain.iter().zip(&wrapped) {
        // The container stays where every frame of the file put it.
        let container = w.joints[0];
        assert!((container - CONTAINER_AT).norm() < 1e-9, "{container:?}");
        // The body is the plain walk's planted body.
        for (a, b) in p.joints.iter().zip(&w.joints[1..]) {
            farthest = farthest.max((*a - *b).norm() / h);
        }
    }
    assert!(
        farthest < 1e-6,
        "the body in the container planted {farthest} H away from the plain walk's"
    );
}
