//! The heading-relative root (SPEC section 2): every clip round-trips through it; a clip turned
//! about up gives the original's features (only the start facing moves); its facing agrees with
//! the travel of forward walks as measured independently; and the model file says which root
//! layout it holds, with old files unchanged.

mod common;

use sinmdm::bvh::{parse_bvh, read_bvh, to_bvh_string};
use sinmdm::motion::features::heading::{SideEvidence, facing_against_travel, wrap};
use sinmdm::motion::math::{self, Mat3};
use sinmdm::motion::up::{UP, reorient};
use sinmdm::motion::{
    ChannelClip, ColumnKind, EncodeOptions, EncodedClip, FeatureLayout, RootLayout, decode, encode,
    global_poses, skeleton_height,
};

use common::max_position_error;

fn heading() -> EncodeOptions {
    EncodeOptions {
        root: RootLayout::Heading,
        ..EncodeOptions::default()
    }
}

fn name(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// A copy of `clip` turned by `rotation`, written as a BVH file and read back.
fn turned(clip: &ChannelClip, rotation: &Mat3) -> ChannelClip {
    let copy = reorient(&clip.to_local(), rotation).to_channels();
    parse_bvh(&to_bvh_string(&copy), "turned.bvh").unwrap()
}

#[test]
fn every_clip_round_trips_through_the_heading_root() {
    let clips = common::all_clips();
    assert!(clips.len() >= 4);
    for path in clips {
        let clip = read_bvh(&path).unwrap();
        let options = EncodeOptions {
            fps: None,
            ..heading()
        };
        let encoded = encode(&clip, &options).unwrap();
        let root = encoded.layout.root.as_ref().unwrap();
        assert!(root.heading.is_some(), "{}", name(&path));
        assert_eq!(root.width(), 4);
        let kinds: Vec<ColumnKind> = encoded.layout.columns()[..4]
            .iter()
            .map(|c| c.kind)
            .collect();
        assert_eq!(
            kinds,
            [
                ColumnKind::RootForward,
                ColumnKind::RootLeftward,
                ColumnKind::RootTurn,
                ColumnKind::RootHeight
            ]
        );
        let decoded = decode(&encoded.layout, encoded.features.view()).unwrap();
        let original = global_poses(&clip.to_local());
        let height = skeleton_height(&original);
        let error = max_position_error(&original, &global_poses(&decoded));
        assert!(
            error <= 1e-4 * height,
            "{}: error {error} exceeds 1e-4 x height",
            name(&path)
        );
    }
}

/// Each clip turned about up by a quarter, a half and an odd angle gives the features of the
/// original within 1e-5 (lengths in skeleton heights), every row: the root's speeds, turn and
/// height and the root joint's rotation are all taken in the facing frame. Only the start
/// facing differs, by the angle.
#[test]
fn a_clip_turned_about_up_gives_the_same_features() {
    for path in common::all_clips() {
        let clip = read_bvh(&path).unwrap();
        let original = encode(&clip, &heading()).unwrap();
        let layout = &original.layout;
        let start = layout
            .root
            .as_ref()
            .unwrap()
            .heading
            .as_ref()
            .unwrap()
            .start;
        // A turn about the file's own up axis (the zombie walk is Z-up).
        let (to_file, to_canonical) = (
            layout.up.file_from_canonical(),
            layout.up.canonical_from_file(),
        );
        for degrees in [90.0f64, 180.0, -37.0] {
            let turn = to_file * math::axis_rotation(UP, degrees.to_radians()) * to_canonical;
            let copy = turned(&clip, &turn);
            let options = EncodeOptions {
                up: Some(layout.up),
                ..heading()
            };
            let encoded = encode(&copy, &options).unwrap();
            assert_eq!(encoded.layout.columns(), layout.columns());
            for (i, column) in layout.columns().iter().enumerate() {
                let scale = match column.kind {
                    ColumnKind::RootForward | ColumnKind::RootLeftward | ColumnKind::RootHeight => {
                        layout.skeleton_height
                    }
                    _ => 1.0,
                };
                let worst = original
                    .features
                    .row(i)
                    .iter()
                    .zip(encoded.features.row(i))
                    .map(|(a, b)| f64::from(a - b).abs() / scale)
                    .fold(0.0, f64::max);
                assert!(
                    worst < 1e-5,
                    "{} turned {degrees}: column {} differs by {worst}",
                    name(&path),
                    layout.column_name(column)
                );
            }
            let moved = encoded
                .layout
                .root
                .as_ref()
                .unwrap()
                .heading
                .as_ref()
                .unwrap()
                .start;
            let off = wrap(moved - start - degrees.to_radians()).abs();
            assert!(
                off < 1e-5,
                "{} turned {degrees}: start facing off by {off}",
                name(&path)
            );
        }
    }
}

fn encoded_heading(path: &std::path::Path) -> EncodedClip {
    encode(&read_bvh(path).unwrap(), &heading()).unwrap()
}

fn median_and_share_over_45(angles: &mut [f64]) -> (f64, f64) {
    angles.sort_by(f64::total_cmp);
    let over = angles.iter().filter(|&&a| a > 45.0).count() as f64 / angles.len() as f64;
    (angles[angles.len() / 2], over)
}

/// The facing rule read against figures measured independently of it (the steering issue's):
/// the shared zombie walk faces within 12 degrees of its travel at the median, with about 6 %
/// of its moving frames over 45 degrees; the CMU walk (a stylised walk with backward glides)
/// has 37 % of its moving frames over 45 degrees. The measures differ in detail (what counts as
/// moving, how the travel is smoothed), so the bounds leave room: here 11.6 degrees and 5.0 %,
/// and 31 %.
#[test]
fn facing_follows_the_travel_of_a_forward_walk() {
    let walk = common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let encoded = encoded_heading(&walk);
    let heading = encoded
        .layout
        .root
        .as_ref()
        .unwrap()
        .heading
        .clone()
        .unwrap();
    assert_eq!(heading.sides, SideEvidence::Names);
    let mut angles = facing_against_travel(&encoded.layout, encoded.features.view()).unwrap();
    let (median, over) = median_and_share_over_45(&mut angles);
    println!(
        "CMU walk: {} moving frames, median {median:.1} deg, {:.1} % over 45",
        angles.len(),
        over * 100.0
    );
    assert!((0.25..=0.45).contains(&over), "{over}");

    let zombie = common::workspace().join("../shared/data/bvh/human_zombie_walk_fair.bvh");
    if !zombie.exists() {
        println!("the shared zombie walk is not beside the checkout; skipped");
        return;
    }
    let encoded = encoded_heading(&zombie);
    let mut angles = facing_against_travel(&encoded.layout, encoded.features.view()).unwrap();
    let (median, over) = median_and_share_over_45(&mut angles);
    println!(
        "zombie walk: {} moving frames, median {median:.1} deg, {:.1} % over 45",
        angles.len(),
        over * 100.0
    );
    assert!(median <= 12.0, "{median}");
    assert!((0.02..=0.10).contains(&over), "{over}");
}

/// A world-root layout is written exactly as before (no `heading` field, schema 1); a heading
/// layout carries its facts and needs schema 2; both read back equal.
#[test]
fn the_model_file_says_which_root_it_holds() {
    let walk = common::workspace().join("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let clip = read_bvh(&walk).unwrap();
    let world = encode(&clip, &EncodeOptions::default()).unwrap().layout;
    let text = serde_json::to_string(&world).unwrap();
    assert!(!text.contains("heading"));
    let back: FeatureLayout = serde_json::from_str(&text).unwrap();
    assert_eq!(back, world);
    assert_eq!(back.root.as_ref().unwrap().layout(), RootLayout::World);

    let turned = encode(&clip, &heading()).unwrap().layout;
    let text = serde_json::to_string(&turned).unwrap();
    assert!(text.contains("\"heading\":{\"left\":"), "{text}");
    let mut back: FeatureLayout = serde_json::from_str(&text).unwrap();
    // JSON text keeps the start facing to the last bit or one below it.
    let start = |l: &FeatureLayout| l.root.as_ref().unwrap().heading.as_ref().unwrap().start;
    assert!((start(&back) - start(&turned)).abs() < 1e-15);
    back.root.as_mut().unwrap().heading.as_mut().unwrap().start = start(&turned);
    assert_eq!(back, turned);
    assert_eq!(back.root.as_ref().unwrap().layout(), RootLayout::Heading);
    assert_eq!(back.width(), world.width() + 1);
}

/// A clip the heading root cannot describe is refused with the reason, not encoded wrongly.
#[test]
fn a_clip_without_a_facing_pair_is_refused_by_name() {
    let text = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Spine\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: 3\nFrame Time: 0.0333333\n0 10 0 0 0 0 0 0 0\n1 10 0 0 0 0 0 0 0\n2 10 0 0 0 0 0 0 0\n";
    let clip = parse_bvh(text, "stick.bvh").unwrap();
    let e = encode(&clip, &heading()).unwrap_err().to_string();
    assert!(e.contains("no left/right pair of joints"), "{e}");
    assert!(e.contains("root_layout: world"), "{e}");
}

/// `auto` gives locomotion the heading root and the rest the world root with the reason. Which
/// clip travels was read independently of the runtime (the hips' ground channels straight from
/// each file: median 1-second travel 0.25-0.42 heights/s for the CMU walk and hop, the zombie
/// walk, Bandai's sad walk and the dog's walk, 1.02 for Bandai's happy walk, 6.2 for the dog's
/// run; 0.13 for Bandai's kick, 0.10 for the dance, 0 for the fox's survey).
#[test]
fn auto_gives_locomotion_the_heading_root() {
    let auto = EncodeOptions {
        root: RootLayout::Auto,
        ..EncodeOptions::default()
    };
    let travels = [
        "walk_cmu",
        "hop_cmu",
        "zombie",
        "dog_walk",
        "dog_run",
        "walk_happy",
        "walk_sad",
    ];
    let stays = ["fox_survey", "dance", "kick"];
    let mut seen = (0, 0);
    for path in common::all_clips() {
        let clip = read_bvh(&path).unwrap();
        let file = name(&path);
        let chosen = encode(&clip, &auto).unwrap();
        if travels.iter().any(|t| file.contains(t)) {
            let asked = encode(&clip, &heading()).unwrap();
            assert_eq!(chosen.layout, asked.layout, "{file}");
            assert_eq!(chosen.features, asked.features, "{file}");
            assert_eq!(chosen.world_root_reason, None, "{file}");
            seen.0 += 1;
        } else {
            assert!(
                stays.iter().any(|t| file.contains(t)),
                "{file} is in neither list"
            );
            let world = encode(&clip, &EncodeOptions::default()).unwrap();
            assert_eq!(chosen.layout, world.layout, "{file}");
            assert_eq!(chosen.features, world.features, "{file}");
            let why = chosen.world_root_reason.expect("the reason is kept");
            assert!(why.contains("nothing to steer"), "{file}: {why}");
            seen.1 += 1;
        }
    }
    assert!(seen.0 >= 2 && seen.1 >= 2, "{seen:?}");
    let text = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Spine\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: 61\nFrame Time: 0.0333333\n"
        .to_string()
        + &(0..61).map(|f| format!("{} 10 0 0 0 0 0 0 0\n", f as f64 * 0.5)).collect::<String>();
    // A stick that travels 15 units (its height 20) a second, but has no pair to face with.
    let stick = parse_bvh(&text, "stick.bvh").unwrap();
    let chosen = encode(&stick, &auto).unwrap();
    let why = chosen.world_root_reason.expect("the reason is kept");
    assert!(why.contains("no left/right pair of joints"), "{why}");
}
