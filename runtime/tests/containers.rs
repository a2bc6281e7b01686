//! A static container above the body (a rig's root bone left below the figure while the hips
//! walk away, as Bandai's `joint_Root`; or turned, as an exporter's armature node) is not part
//! of the body: planting neither lifts the figure off the floor to clear it nor moves it.

use sinmdm::bvh::parse_bvh;
use sinmdm::motion::feet::{Kept, PlantOptions, plant_feet};
use sinmdm::motion::math::{Mat3, Vec3, axis_rotation};
use sinmdm::motion::{FeatureLayout, LocalMotion, decode, encode, global_poses};

const WALK: &str = "../tests/data/bvh/human_walk_cmu_131_01.bvh";
/// Where the container sits, in file units: under the walk's floor (its feet rest near -0.2).
const CONTAINER_HEIGHT: f64 = -10.0;
/// How far the container is turned about the up axis, in degrees.
const CONTAINER_TURN: f64 = 90.0;
/// Frames of the walk kept (at its 120 fps: two seconds).
const FRAMES: usize = 240;

/// The first [`FRAMES`] of the walk's text, its hips placed in a container at
/// [`CONTAINER_HEIGHT`] turned by [`CONTAINER_TURN`] about +Y, with the hips' height raised to
/// match: the body moves as the walk turned by the container, at the walk's own height.
fn walk_in_container(text: &str) -> (String, String) {
    let (hierarchy, motion) = text.split_once("MOTION").expect("a BVH text");
    let body = hierarchy
        .trim_start()
        .strip_prefix("HIERARCHY")
        .unwrap()
        .trim_start()
        .strip_prefix("ROOT")
        .unwrap();
    let wrapped_hierarchy = format!(
        "HIERARCHY\nROOT Container\n{{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT{body}}}\n"
    );
    let rows: Vec<&str> = motion
        .lines()
        .filter(|l| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with("Frame")
        })
        .take(FRAMES)
        .collect();
    let header = format!("MOTION\nFrames: {FRAMES}\nFrame Time: .0083333\n");
    let mut plain = format!("{}\n{header}", hierarchy.trim_end());
    let mut wrapped = format!("{wrapped_hierarchy}{header}");
    for row in rows {
        plain.push_str(row.trim());
        plain.push('\n');
        let mut values: Vec<f64> = row.split_whitespace().map(|v| v.parse().unwrap()).collect();
        values[1] -= CONTAINER_HEIGHT;
        wrapped.push_str(&format!("0 {CONTAINER_HEIGHT} 0 0 0 {CONTAINER_TURN}"));
        for v in values {
            wrapped.push_str(&format!(" {v}"));
        }
        wrapped.push('\n');
    }
    (plain, wrapped)
}

/// The clip's own motion, decoded from its features, planted with its own contact labels.
fn planted(layout: &FeatureLayout, motion: &LocalMotion, labels: &[Vec<f32>]) -> LocalMotion {
    let options = PlantOptions {
        root_stance_share: 1.0,
        ..PlantOptions::default()
    };
    plant_feet(layout, motion, labels, &Kept::default(), &options)
        .unwrap()
        .0
}

fn encoded(text: &str, name: &str) -> (FeatureLayout, LocalMotion, Vec<Vec<f32>>) {
    let channels = parse_bvh(text, name).unwrap();
    let clip = encode(&channels, &Default::default()).unwrap();
    let motion = decode(&clip.layout, clip.features.view()).unwrap();
    let labels = clip
        .layout
        .contact_rows()
        .iter()
        .map(|&r| clip.features.row(r).to_vec())
        .collect();
    (clip.layout, motion, labels)
}

#[test]
fn planting_leaves_a_container_where_the_file_put_it_and_the_body_on_its_floor() {
    let (plain_text, wrapped_text) = walk_in_container(&std::fs::read_to_string(WALK).unwrap());
    let (plain_layout, plain_motion, plain_labels) = encoded(&plain_text, "walk.bvh");
    let (layout, motion, labels) = encoded(&wrapped_text, "walk_in_container.bvh");
    assert_eq!(
        layout.contact_joints.len(),
        plain_layout.contact_joints.len()
    );
    assert_eq!(layout.skeleton.joints[layout.carrier()].name, "Hips");
    assert!(
        (layout.ground.unwrap() - plain_layout.ground.unwrap()).abs() < 1e-6,
        "the ground is the feet's, not the container's: {:?} against {:?}",
        layout.ground,
        plain_layout.ground
    );

    let plain = global_poses(&planted(&plain_layout, &plain_motion, &plain_labels));
    let wrapped = global_poses(&planted(&layout, &motion, &labels));
    let turn: Mat3 = axis_rotation(1, CONTAINER_TURN.to_radians());
    let h = layout.skeleton_height;
    let mut farthest: f64 = 0.0;
    for (p, w) in plain.iter().zip(&wrapped) {
        // The container stays where every frame of the file put it.
        let container = w.joints[0];
        assert!(
            (container - Vec3([0.0, CONTAINER_HEIGHT, 0.0])).norm() < 1e-9,
            "{container:?}"
        );
        // The body is the plain walk's planted body, turned as the container is.
        for (a, b) in p.joints.iter().zip(&w.joints[1..]) {
            farthest = farthest.max((turn * *a - *b).norm() / h);
        }
    }
    assert!(
        farthest < 1e-6,
        "the body in the container planted {farthest} H away from the plain walk's"
    );
}
