//! Feet and smoothness metrics (SPEC section 9) on synthetic two-joint figures whose answers
//! are known: a hip 1 unit above a foot whose End Site touches the ground (H = 1.1).

use sinmdm::bvh::parse_bvh;
use sinmdm::motion::{ContactConfig, EncodeOptions, LocalMotion, decode, encode};
use sinmdm_eval::{FeetReference, FeetScores};

const FPS: f64 = 30.0;
const FRAMES: usize = 60;

/// A clip whose hip is at `hip(i)` (x, y) in frame `i`, the leg hanging straight down.
fn clip(hip: impl Fn(usize) -> (f64, f64)) -> (sinmdm::motion::FeatureLayout, LocalMotion) {
    figure(None, hip)
}

/// [`clip`], its hips inside a static container joint at the height `container` when given
/// (the hips' channels then relative to it, so the body moves the same).
fn figure(
    container: Option<f64>,
    hip: impl Fn(usize) -> (f64, f64),
) -> (sinmdm::motion::FeatureLayout, LocalMotion) {
    let body = "Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT Foot\n {\n  OFFSET 0 -1 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 -0.1 0\n  }\n }\n}\n";
    let mut text = match container {
        None => format!("HIERARCHY\nROOT {body}MOTION\n"),
        Some(_) => format!(
            "HIERARCHY\nROOT Container\n{{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\nJOINT {body}}}\nMOTION\n"
        ),
    };
    text.push_str(&format!("Frames: {FRAMES}\nFrame Time: {}\n", 1.0 / FPS));
    for i in 0..FRAMES {
        let (x, y) = hip(i);
        match container {
            None => text.push_str(&format!("{x} {y} 0 0 0 0 0 0 0\n")),
            Some(c) => text.push_str(&format!("0 {c} 0 0 0 0 {x} {} 0 0 0 0 0 0 0\n", y - c)),
        }
    }
    let channels = parse_bvh(&text, "synthetic.bvh").unwrap();
    let encoded = encode(
        &channels,
        &EncodeOptions {
            fps: None,
            contacts: ContactConfig {
                joints: Some(vec!["Foot".into()]),
                ..ContactConfig::default()
            },
            ..EncodeOptions::default()
        },
    )
    .unwrap();
    let motion = decode(&encoded.layout, encoded.features.view()).unwrap();
    (encoded.layout, motion)
}

fn standing() -> (sinmdm::motion::FeatureLayout, LocalMotion) {
    clip(|_| (0.0, 1.1))
}

fn scores(motion: &LocalMotion) -> FeetScores {
    let (layout, reference) = standing();
    FeetReference::new(&layout, &reference).scores(motion)
}

#[test]
fn a_still_figure_neither_skates_nor_sinks_nor_shakes() {
    let (layout, still) = standing();
    assert!((layout.skeleton_height - 1.1).abs() < 1e-6);
    let reference = FeetReference::new(&layout, &still);
    assert!(reference.ground().abs() < 1e-6, "{}", reference.ground());
    let s = reference.scores(&still);
    assert_eq!(s.skating_ratio, 0.0);
    assert!(s.max_penetration < 1e-6);
    assert_eq!(s.penetrating_frames, 0.0);
    assert!(s.jitter < 1e-3, "{}", s.jitter);
}

#[test]
fn a_foot_sliding_on_the_ground_skates_in_every_frame_pair() {
    // 0.05 units per frame = 1.5 units/s = 1.36 H/s, well above 0.3 H/s.
    let (_, sliding) = clip(|i| (0.05 * i as f64, 1.1));
    assert_eq!(scores(&sliding).skating_ratio, 1.0);
    // Slower than the threshold: 0.2 H/s.
    let (_, creeping) = clip(|i| (0.2 * 1.1 / FPS * i as f64, 1.1));
    assert_eq!(scores(&creeping).skating_ratio, 0.0);
    // Fast, but a tenth of H above the ground: not on the ground, so not skating.
    let (_, flying) = clip(|i| (0.05 * i as f64, 1.1 + 0.11));
    assert_eq!(scores(&flying).skating_ratio, 0.0);
}

#[test]
fn a_dip_below_the_ground_is_measured_in_heights_and_frames() {
    let (_, dipping) = clip(|i| (0.0, if i == 30 { 1.1 - 0.11 } else { 1.1 }));
    let s = scores(&dipping);
    assert!(
        (s.max_penetration - 0.1).abs() < 1e-5,
        "{}",
        s.max_penetration
    );
    assert!((s.penetrating_frames - 1.0 / FRAMES as f64).abs() < 1e-12);
}

#[test]
fn jitter_of_a_constant_acceleration_is_that_acceleration_in_heights() {
    // x = a t^2 / 2: every joint's second difference is a / f^2, so the jitter is a / H.
    let a = 0.6;
    let (_, accelerating) = clip(|i| {
        let t = i as f64 / FPS;
        (0.5 * a * t * t, 1.1 + 0.5)
    });
    let s = scores(&accelerating);
    assert!((s.jitter - a / 1.1).abs() < 1e-3 * a, "{}", s.jitter);
}

#[test]
fn a_container_under_the_floor_is_no_part_of_the_body() {
    // A rig's root bone 5 units under a figure that walks: it neither sinks through the floor
    // nor stretches the skeleton's height.
    let (layout, walking) = figure(Some(-5.0), |i| (0.01 * i as f64, 1.1));
    assert!(
        (layout.skeleton_height - 1.1).abs() < 1e-6,
        "{}",
        layout.skeleton_height
    );
    let reference = FeetReference::new(&layout, &walking);
    assert!(reference.ground().abs() < 1e-6, "{}", reference.ground());
    let s = reference.scores(&walking);
    assert!(s.max_penetration < 1e-6, "{}", s.max_penetration);
    assert_eq!(s.penetrating_frames, 0.0);
}
