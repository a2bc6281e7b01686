//! Motion spliced into a character's own GLB (Blender's export of the walk, with a skinned
//! cube): the character's file is kept as it was, and the new animation moves its bones where
//! Blender's own animation of the same motion moves them.

use std::path::{Path, PathBuf};

use serde_json::Value;
use sinmdm::bvh::read_bvh;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::{LocalMotion, UpAxis};
use sinmdm_formats::gltf::container::parse_glb;
use sinmdm_formats::gltf::{read_gltf, splice_into_character};
use sinmdm_formats::{AnimationChoice, ReadOptions};

mod common;
use common::{fixtures, positions_by_name};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-splice-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn character() -> PathBuf {
    fixtures().join("human_walk_cmu_131_01_skinned.glb")
}

/// World positions by joint name of animation `which` of `file`, every frame.
fn played(file: &Path, which: AnimationChoice) -> Vec<Vec<(String, Vec3)>> {
    let options = ReadOptions {
        animation: Some(which),
        fps: None,
    };
    positions_by_name(&read_gltf(file, &options).unwrap().clip.to_local())
}

/// The largest distance between same-named joints of two plays, and the figure's height.
fn worst_distance(a: &[Vec<(String, Vec3)>], b: &[Vec<(String, Vec3)>]) -> (f64, f64) {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    let mut worst = 0.0f64;
    let (mut low, mut high) = (f64::MAX, f64::MIN);
    for (fa, fb) in a.iter().zip(b) {
        for (name, p) in fa {
            let (_, q) = fb.iter().find(|(n, _)| n == name).expect("same joints");
            worst = worst.max((*p - *q).norm());
            low = low.min(q[1]);
            high = high.max(q[1]);
        }
    }
    (worst, high - low)
}

/// The document and binary chunk of a GLB file.
fn document(file: &Path) -> (Value, Vec<u8>) {
    let asset = parse_glb(file, &std::fs::read(file).unwrap()).unwrap();
    (asset.json, asset.buffers.into_iter().next().unwrap())
}

fn the_walk() -> LocalMotion {
    read_bvh(fixtures().join("human_walk_cmu_131_01_2s.bvh"))
        .unwrap()
        .to_local()
}

#[test]
fn a_spliced_walk_moves_the_character_as_blenders_own_animation_does() {
    let out = scratch("character_with_walk.glb");
    let walk = the_walk();
    // The same walk in other units (a model trained on it in metres, say): scaled back.
    let mut small = walk.clone();
    for joint in &mut small.skeleton.joints {
        joint.offset = joint.offset * 0.01;
        joint.end_site = joint.end_site.map(|e| e * 0.01);
    }
    for t in &mut small.translations {
        *t = *t * 0.01;
    }
    let report =
        splice_into_character(&character(), &out, &[("copy".into(), &walk)], UpAxis::PosY).unwrap();
    assert_eq!((report.kept_animations, report.added_animations), (1, 1));
    assert!(
        !report.same_frames,
        "Blender's bones have their own rest rotations"
    );
    assert!((report.scale - 1.0).abs() < 1e-4, "{}", report.scale);
    // Into the result again: appended after the first.
    let twice = scratch("character_with_two.glb");
    let report = splice_into_character(
        &out,
        &twice,
        &[("copy_in_metres".into(), &small)],
        UpAxis::PosY,
    )
    .unwrap();
    assert_eq!(report.kept_animations, 2);
    assert!((report.scale - 100.0).abs() < 1e-2, "{}", report.scale);
    let out = twice;

    let blender = played(&out, AnimationChoice::Index(0));
    for added in ["copy", "copy_in_metres"] {
        let ours = played(&out, AnimationChoice::Name(added.into()));
        let (worst, height) = worst_distance(&ours, &blender);
        assert!(worst <= 1e-5 * height, "{added}: {worst} > 1e-5 x {height}");
    }

    // Nothing of the character's file changed but the appended arrays and the buffer length.
    let (before, bin_before) = document(&character());
    let (mut after, bin_after) = document(&out);
    for key in ["accessors", "bufferViews", "animations"] {
        let kept = before[key].as_array().unwrap().len();
        let grown = after[key].as_array_mut().unwrap();
        assert!(grown.len() > kept, "{key} did not grow");
        if key == "animations" {
            assert_eq!(grown.len(), kept + 2);
        }
        grown.truncate(kept);
    }
    after["buffers"][0]["byteLength"] = before["buffers"][0]["byteLength"].clone();
    assert_eq!(after, before);
    assert_eq!(&bin_after[..bin_before.len()], &bin_before[..]);
}

#[test]
fn a_model_read_from_the_character_itself_plays_back_its_animation() {
    // A clip read from the character's own file (as a model trained on it has): the reader
    // lines its joints' frames up with the world at rest, so it fits the character through
    // the bind pose, and splicing it back reproduces Blender's animation.
    let read = read_gltf(&character(), &ReadOptions::default())
        .unwrap()
        .clip
        .to_local();
    let out = scratch("character_again.glb");
    let report =
        splice_into_character(&character(), &out, &[("again".into(), &read)], UpAxis::PosY)
            .unwrap();
    assert!(!report.same_frames);
    assert!((report.scale - 1.0).abs() < 1e-4, "{}", report.scale);
    let (worst, height) = worst_distance(
        &played(&out, AnimationChoice::Name("again".into())),
        &played(&out, AnimationChoice::Index(0)),
    );
    assert!(worst <= 1e-5 * height, "{worst} > 1e-5 x {height}");
}

#[test]
fn a_skeleton_the_character_lacks_is_refused_by_name_and_another_rest_retargeted() {
    let mut walk = the_walk();
    walk.skeleton.joints[3].name = "Tail".into();
    let err = splice_into_character(
        &character(),
        &scratch("never.glb"),
        &[("x".into(), &walk)],
        UpAxis::PosY,
    )
    .unwrap_err();
    assert!(err.to_string().contains("no node named 'Tail'"), "{err}");
    assert!(!scratch("never.glb").exists());
    // Bones that point elsewhere under the same names: another rig, so the motion is
    // retargeted (formats/tests/retarget.rs checks how well).
    let mut bent = the_walk();
    for joint in &mut bent.skeleton.joints {
        joint.offset = Vec3::new(joint.offset[2], joint.offset[0], -joint.offset[1]);
    }
    let report = splice_into_character(
        &character(),
        &scratch("bent.glb"),
        &[("x".into(), &bent)],
        UpAxis::PosY,
    )
    .unwrap();
    let retargeted = report.retargeted.expect("retargeted");
    assert!(
        retargeted.reason.contains("another rig") && retargeted.reason.contains("points elsewhere"),
        "{}",
        retargeted.reason
    );
}

#[test]
fn a_namespaced_character_takes_a_model_without_the_namespace() {
    // The character's bones as Mixamo names them (`mixamorig:Hips`); the model's joints as
    // the FBX reader names them (`Hips`).
    let (mut json, bin) = document(&character());
    for node in json["nodes"].as_array_mut().unwrap() {
        if let Some(name) = node["name"].as_str() {
            node["name"] = Value::String(format!("mixamorig:{name}"));
        }
    }
    let namespaced = scratch("namespaced.glb");
    std::fs::write(
        &namespaced,
        sinmdm_formats::gltf::container::glb_bytes(&json, &bin),
    )
    .unwrap();
    let out = scratch("namespaced_out.glb");
    splice_into_character(
        &namespaced,
        &out,
        &[("walk".into(), &the_walk())],
        UpAxis::PosY,
    )
    .unwrap();
    let (worst, height) = worst_distance(
        &played(&out, AnimationChoice::Name("walk".into())),
        &played(&out, AnimationChoice::Index(0)),
    );
    assert!(worst <= 1e-5 * height, "{worst} > 1e-5 x {height}");
}

#[test]
fn a_gltf_character_is_refused_naming_the_way_round() {
    let dir = std::env::temp_dir().join(format!("sinmdm-splice-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gltf = dir.join("character.gltf");
    std::fs::write(&gltf, r#"{"asset": {"version": "2.0"}}"#).unwrap();
    let walk = read_gltf(&character(), &ReadOptions::default())
        .unwrap()
        .clip
        .to_local();
    let err = splice_into_character(
        &gltf,
        &dir.join("out.glb"),
        &[("walk".into(), &walk)],
        UpAxis::PosY,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("is not a .glb") && err.contains("glTF Binary"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
