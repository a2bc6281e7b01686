//! The walk retargeted onto characters Blender made from the walk's own rig (see
//! `lab/scripts/make_retarget_fixtures.py`): one with other proportions, an A pose and rolled
//! bones under the same names, one with Unreal mannequin names as well. Played back, every
//! paired bone points where its joint points, the hips keep the hip-height ratio above the
//! ground, and the feet skate no more than the clip's.

use std::path::{Path, PathBuf};

use sinmdm::bvh::read_bvh;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::{LocalMotion, UpAxis, global_poses};
use sinmdm_formats::gltf::container::{glb_bytes, parse_glb};
use sinmdm_formats::gltf::{Retargeted, read_gltf, splice_retargeted};
use sinmdm_formats::retarget::{BoneMap, BoneMatch, Convention};
use sinmdm_formats::{AnimationChoice, ReadOptions, read_clip};

mod common;
use common::{fixtures, root};

/// How much longer the fixtures' legs are than the walk's (and so the hips' height).
const LEG_FACTOR: f64 = 1.2;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-retarget-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn the_walk() -> LocalMotion {
    read_bvh(fixtures().join("human_walk_cmu_131_01_2s.bvh"))
        .unwrap()
        .to_local()
}

/// Blender's reshaped rig with `change` made to each of its nodes, written as scratch file
/// `name`.
fn reshaped_rig_with(name: &str, mut change: impl FnMut(&mut serde_json::Value)) -> PathBuf {
    let rig = fixtures().join("human_walk_rig_other_proportions.glb");
    let asset = parse_glb(&rig, &std::fs::read(&rig).unwrap()).unwrap();
    let mut json = asset.json;
    json["nodes"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .for_each(&mut change);
    let character = scratch(name);
    std::fs::write(&character, glb_bytes(&json, &asset.buffers[0])).unwrap();
    character
}

/// A motion's joints: names, parents and every frame's positions.
struct Played {
    names: Vec<String>,
    parents: Vec<Option<usize>>,
    positions: Vec<Vec<Vec3>>,
}

impl Played {
    fn of(motion: &LocalMotion) -> Played {
        Played {
            names: motion
                .skeleton
                .joints
                .iter()
                .map(|j| j.name.clone())
                .collect(),
            parents: motion.skeleton.joints.iter().map(|j| j.parent).collect(),
            positions: global_poses(motion).into_iter().map(|p| p.joints).collect(),
        }
    }

    fn read(file: &Path, animation: &str) -> Played {
        let options = ReadOptions {
            animation: Some(AnimationChoice::Name(animation.into())),
            fps: None,
        };
        Played::of(&read_gltf(file, &options).unwrap().clip.to_local())
    }

    fn index(&self, name: &str) -> usize {
        self.names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no joint '{name}' in {:?}", self.names))
    }

    /// The 5th percentile of each frame's lowest height among `joints`.
    fn ground(&self, joints: &[usize]) -> f64 {
        let mut lowest: Vec<f64> = self
            .positions
            .iter()
            .map(|p| {
                joints
                    .iter()
                    .map(|&j| p[j][1])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        lowest.sort_by(f64::total_cmp);
        lowest[(0.05 * (lowest.len() - 1) as f64).round() as usize]
    }

    /// Mean speed over the ground, in hips' heights per second, of `feet` in the frames in
    /// which `stance` (another play's same feet) stands: within 5 % of its hips' height of the
    /// ground and slower than 0.3 of it a second.
    fn stance_slide(
        &self,
        feet: &[usize],
        hips: usize,
        stance: (&Played, &[usize], usize),
        fps: f64,
    ) -> f64 {
        let (other, other_feet, other_hips) = stance;
        let leg = |p: &Played, f: &[usize], h: usize| {
            let g = p.ground(f);
            (
                g,
                p.positions.iter().map(|q| q[h][1] - g).sum::<f64>() / p.positions.len() as f64,
            )
        };
        let (og, oleg) = leg(other, other_feet, other_hips);
        let (_, ours) = leg(self, feet, hips);
        let flat = |d: Vec3| (d[0] * d[0] + d[2] * d[2]).sqrt();
        let (mut sum, mut count) = (0.0, 0usize);
        for (k, (&f, &of)) in feet.iter().zip(other_feet).enumerate() {
            let _ = k;
            for i in 0..self.positions.len() - 1 {
                let o = &other.positions;
                let low = o[i][of][1] - og < 0.05 * oleg && o[i + 1][of][1] - og < 0.05 * oleg;
                let slow = flat(o[i + 1][of] - o[i][of]) * fps < 0.3 * oleg;
                if low && slow {
                    sum += flat(self.positions[i + 1][f] - self.positions[i][f]) * fps / ours;
                    count += 1;
                }
            }
        }
        sum / count.max(1) as f64
    }

    /// The mean over frames of the figure's vertical extent.
    fn height(&self) -> f64 {
        self.positions
            .iter()
            .map(|p| {
                let ys = p.iter().map(|v| v[1]);
                ys.clone().fold(f64::MIN, f64::max) - ys.fold(f64::MAX, f64::min)
            })
            .sum::<f64>()
            / self.positions.len() as f64
    }

    /// Share of frame pairs in which one of `feet` skates: within 5 % of a height of the
    /// ground and moving over it faster than 0.3 heights a second (eval's rule, on its own).
    /// The height is the hips' mean height above the ground, the leg length the travel is
    /// scaled by, so that a character with shorter arms is not held to a lower speed.
    fn skating(&self, feet: &[usize], hips: usize, fps: f64) -> f64 {
        let ground = self.ground(feet);
        let height = self
            .positions
            .iter()
            .map(|p| p[hips][1] - ground)
            .sum::<f64>()
            / self.positions.len() as f64;
        let pairs = self.positions.len() - 1;
        let mut skating = vec![false; pairs];
        for &f in feet {
            let speed: Vec<f64> = self
                .positions
                .windows(2)
                .map(|w| {
                    let d = w[1][f] - w[0][f];
                    (d[0] * d[0] + d[2] * d[2]).sqrt() * fps
                })
                .collect();
            let low = |i: usize| self.positions[i][f][1] - ground < 0.05 * height;
            for i in 0..pairs {
                let window = i.saturating_sub(2)..(i + 3).min(pairs);
                let mean = speed[window.clone()].iter().sum::<f64>() / window.len() as f64;
                if low(i) && low(i + 1) && speed[i] > 0.3 * height && mean > 0.3 * height {
                    skating[i] = true;
                }
            }
        }
        skating.iter().filter(|&&s| s).count() as f64 / pairs as f64
    }
}

/// The worst angle, in degrees, over frames and paired bones, between a character bone (from
/// its nearest paired ancestor) and its joints' bone in the clip.
fn worst_direction(target: &Played, source: &Played, map: &BoneMap) -> (f64, String) {
    let pair_of = |t: usize| {
        map.pairs
            .iter()
            .find(|(b, _)| *b == target.names[t])
            .map(|(_, j)| source.index(j))
    };
    let mut worst = (0.0, String::new());
    let mut bones = 0;
    let height = source.height();
    for (b, j) in &map.pairs {
        let (b, j) = (target.index(b), source.index(j));
        let mut at = target.parents[b];
        let (a, i) = loop {
            let Some(a) = at else { break (None, None) };
            if let Some(i) = pair_of(a) {
                break (Some(a), Some(i));
            }
            at = target.parents[a];
        };
        let (Some(a), Some(i)) = (a, i) else { continue };
        // A joint on its parent (CMU's Chest2 and lowerneck) has no direction to follow.
        let length = |p: &Vec<Vec3>| (p[j] - p[i]).norm();
        if source.positions.iter().map(length).fold(0.0, f64::max) < 1e-4 * height {
            continue;
        }
        bones += 1;
        for (t, s) in target.positions.iter().zip(&source.positions) {
            let (u, v) = (t[b] - t[a], s[j] - s[i]);
            let angle = (u.dot(v) / (u.norm() * v.norm()))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            if angle > worst.0 {
                worst = (angle, target.names[b].clone());
            }
        }
    }
    assert!(bones >= 10, "only {bones} bones compared");
    worst
}

/// Checks the retargeted walk in `out` against the clip, returning the report's figures.
fn check(out: &Path, walk: &LocalMotion, report: &Retargeted, hips: &str, feet: [&str; 4]) {
    check_scaled(out, walk, report, (hips, LEG_FACTOR), feet);
}

/// [`check`], the hips expected at `ratio` times the clip's height above the ground.
fn check_scaled(
    out: &Path,
    walk: &LocalMotion,
    report: &Retargeted,
    (hips, expected): (&str, f64),
    feet: [&str; 4],
) {
    let source = Played::of(walk);
    let target = Played::read(out, "walk");
    assert_eq!(target.positions.len(), source.positions.len());

    let (angle, bone) = worst_direction(&target, &source, &report.map);
    assert!(
        angle <= 1.0,
        "bone '{bone}' is {angle:.3} degrees off its joint"
    );

    // The hips above the ground, over the clip's: the legs' ratio, every frame.
    let pairs: Vec<(usize, usize)> = report
        .map
        .pairs
        .iter()
        .map(|(b, j)| (target.index(b), source.index(j)))
        .collect();
    let (tg, sg) = (
        target.ground(&pairs.iter().map(|p| p.0).collect::<Vec<_>>()),
        source.ground(&pairs.iter().map(|p| p.1).collect::<Vec<_>>()),
    );
    let (th, sh) = (target.index(hips), source.index("Hips"));
    for (t, s) in target.positions.iter().zip(&source.positions) {
        let ratio = (t[th][1] - tg) / (s[sh][1] - sg);
        assert!(
            (ratio / expected - 1.0).abs() <= 0.01,
            "the hips stand {ratio:.4}x the clip's, not {expected}x"
        );
    }
    let reported = report.hip_heights[0] / report.hip_heights[1];
    assert!((reported / expected - 1.0).abs() <= 0.01, "{reported}");

    // Feet: no more skating than the clip's, plus 0.02.
    let ours: Vec<usize> = feet.iter().map(|f| target.index(f)).collect();
    let theirs: Vec<usize> = ["LeftAnkle", "LeftToe", "RightAnkle", "RightToe"]
        .iter()
        .map(|f| source.index(f))
        .collect();
    let (skate_t, skate_s) = (
        target.skating(&ours, th, walk.fps),
        source.skating(&theirs, sh, walk.fps),
    );
    assert!(
        skate_t <= skate_s + 0.02,
        "the feet skate in {skate_t:.3} of the frames, the clip's in {skate_s:.3}"
    );
}

#[test]
fn the_walk_goes_onto_a_rig_of_other_proportions_under_the_same_names() {
    let walk = the_walk();
    let character = fixtures().join("human_walk_rig_other_proportions.glb");
    let out = scratch("other_proportions.glb");
    let report = splice_retargeted(
        &character,
        &out,
        &[("walk".into(), &walk)],
        UpAxis::PosY,
        &BoneMatch::Names,
    )
    .unwrap();
    let retargeted = report.retargeted.expect("another rig is retargeted");
    assert!(
        retargeted.reason.contains("another rig"),
        "{}",
        retargeted.reason
    );
    assert!(
        retargeted.dropped_joints.is_empty(),
        "{:?}",
        retargeted.dropped_joints
    );
    check(
        &out,
        &walk,
        &retargeted,
        "Hips",
        ["LeftAnkle", "LeftToe", "RightAnkle", "RightToe"],
    );
}

#[test]
fn the_walk_goes_onto_a_renamed_rig_by_an_automatic_map_and_by_the_same_map_saved() {
    let walk = the_walk();
    let character = fixtures().join("human_walk_rig_unreal_names.glb");
    let feet = ["foot_l", "ball_l", "foot_r", "ball_r"];

    // By name alone it is refused, and the error says the way round.
    let err = splice_retargeted(
        &character,
        &scratch("never.glb"),
        &[("walk".into(), &walk)],
        UpAxis::PosY,
        &BoneMatch::Names,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("--retarget auto"), "{err}");
    assert!(!scratch("never.glb").exists());

    let out = scratch("unreal_auto.glb");
    let report = splice_retargeted(
        &character,
        &out,
        &[("walk".into(), &walk)],
        UpAxis::PosY,
        &BoneMatch::Auto,
    )
    .unwrap();
    let auto = report.retargeted.expect("retargeted");
    assert_eq!(
        auto.conventions,
        Some((Convention::Unreal, Convention::JointNamedBvh))
    );
    for pair in [
        ("pelvis", "Hips"),
        ("thigh_l", "LeftHip"),
        ("hip_socket_l", "LHipJoint"),
        ("upperarm_r", "RightShoulder"),
        ("neck_01", "lowerneck"),
    ] {
        assert!(
            auto.map.pairs.contains(&(pair.0.into(), pair.1.into())),
            "{pair:?} not in {:?}",
            auto.map.pairs
        );
    }
    check(&out, &walk, &auto, "pelvis", feet);

    // The printed map, saved and read back, gives the same file.
    let saved = scratch("map.yaml");
    std::fs::write(&saved, auto.map.to_yaml()).unwrap();
    let map = BoneMap::read(&saved).unwrap();
    assert_eq!(map, auto.map);
    let again = scratch("unreal_map.glb");
    splice_retargeted(
        &character,
        &again,
        &[("walk".into(), &walk)],
        UpAxis::PosY,
        &BoneMatch::Map(map, saved),
    )
    .unwrap();
    assert_eq!(std::fs::read(&again).unwrap(), std::fs::read(&out).unwrap());
}

#[test]
fn a_mixamo_clip_goes_onto_another_mixamo_character_by_its_names_alone() {
    // The clip as Mixamo writes it (FBX, centimetres, `mixamorig:` names the reader drops), and
    // a character with the same `mixamorig:` names and other proportions.
    let fbx = root().join("tests/data/fbx/human_walk_cmu_131_01_mixamo_style.fbx");
    let (clip, _) = read_clip(&fbx, &ReadOptions::default()).unwrap();
    let mixamo = clip.to_local();
    let character = reshaped_rig_with("mixamo_character.glb", |node| {
        if let Some(name) = node["name"].as_str().filter(|n| !n.contains("Cube")) {
            node["name"] = serde_json::Value::String(format!("mixamorig:{name}"));
        }
    });

    let out = scratch("mixamo_on_mixamo.glb");
    let report = splice_retargeted(
        &character,
        &out,
        &[("walk".into(), &mixamo)],
        UpAxis::PosY,
        &BoneMatch::Names,
    )
    .unwrap();
    let retargeted = report.retargeted.expect("retargeted");
    assert!(
        retargeted.reason.contains("another rig"),
        "{}",
        retargeted.reason
    );
    // The FBX is in metres, 5.64 cm to the walk's unit; the character in the walk's units.
    let feet = ["LeftAnkle", "LeftToe", "RightAnkle", "RightToe"].map(|f| format!("mixamorig:{f}"));
    check_scaled(
        &out,
        &mixamo,
        &retargeted,
        ("mixamorig:Hips", LEG_FACTOR / 0.0564),
        [&feet[0], &feet[1], &feet[2], &feet[3]],
    );
}

#[test]
fn a_leg_that_is_not_the_clips_scaled_alike_bends_to_put_its_ankle_where_the_clips_is() {
    // The reshaped rig with shins 0.8x as long again: its legs cannot follow the clip's bones
    // and keep its feet, so its knees bend (and its hips turn) to put the ankles where the
    // clip's are, scaled as the travel is.
    let walk = the_walk();
    let character = reshaped_rig_with("short_shins.glb", |node| {
        if matches!(node["name"].as_str(), Some("LeftAnkle" | "RightAnkle")) {
            for v in node["translation"].as_array_mut().unwrap() {
                *v = serde_json::json!(v.as_f64().unwrap() * 0.8);
            }
        }
    });
    let out = scratch("short_shins_walk.glb");
    let report = splice_retargeted(
        &character,
        &out,
        &[("walk".into(), &walk)],
        UpAxis::PosY,
        &BoneMatch::Names,
    )
    .unwrap();
    let retargeted = report.retargeted.unwrap();
    assert_eq!(retargeted.planted_feet, ["LeftAnkle", "RightAnkle"]);
    let (source, target) = (Played::of(&walk), Played::read(&out, "walk"));
    let ratio = report.scale;
    let (hips_s, hips_t) = (source.index("Hips"), target.index("Hips"));
    let leg = retargeted.hip_heights[0];
    let mut worst = 0.0f64;
    for side in ["LeftAnkle", "RightAnkle"] {
        let (a_s, a_t) = (source.index(side), target.index(side));
        let reach = ["LeftHip", "LeftKnee"]
            .map(|j| target.index(&j.replace("Left", &side[..side.len() - 5])));
        for (s, t) in source.positions.iter().zip(&target.positions) {
            let want = (s[a_s] - s[hips_s]) * ratio;
            // Only where the shorter leg reaches.
            let span = (t[reach[1]] - t[reach[0]]).norm() + (t[a_t] - t[reach[1]]).norm();
            if (t[hips_t] + want - t[reach[0]]).norm() > 0.98 * span {
                continue;
            }
            worst = worst.max(((t[a_t] - t[hips_t]) - want).norm() / leg);
        }
    }
    assert!(
        worst < 1e-4,
        "an ankle is {worst:.2e} leg lengths off the clip's"
    );
    // The feet slide in their stance no more than the clip's do.
    let ankles = |p: &Played| ["LeftAnkle", "RightAnkle"].map(|a| p.index(a));
    let slide_t = target.stance_slide(
        &ankles(&target),
        hips_t,
        (&source, &ankles(&source), hips_s),
        walk.fps,
    );
    let slide_s = source.stance_slide(
        &ankles(&source),
        hips_s,
        (&source, &ankles(&source), hips_s),
        walk.fps,
    );
    assert!(
        slide_t <= slide_s * 1.05 + 1e-3,
        "{slide_t:.4} > {slide_s:.4}"
    );
    // Everything but the legs still points where the clip's bones point.
    let legs = ["Hip", "Knee", "Ankle", "Toe"];
    let upper = BoneMap {
        pairs: retargeted
            .map
            .pairs
            .iter()
            .filter(|(b, _)| !legs.iter().any(|l| b.ends_with(l)))
            .cloned()
            .collect(),
    };
    let (angle, bone) = worst_direction(&target, &source, &upper);
    assert!(
        angle <= 1.0,
        "bone '{bone}' is {angle:.3} degrees off its joint"
    );
}
