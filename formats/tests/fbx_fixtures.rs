//! FBX files written by Blender (tests/data/fbx, made from the shipped walk and fox cut to 1 s,
//! with Blender's leaf bones): our reader puts every joint where forward kinematics of the
//! source BVH puts it, within 1e-5 of the skeleton's height, every frame, folds the leaf bones
//! into End Sites, and gives the same up axis, height and contacts as the BVH.

use sinmdm::bvh::read_bvh;
use sinmdm_formats::ReadOptions;
use sinmdm_formats::fbx::read_fbx;

mod common;
use common::{assert_matches_bvh, fbx_fixture, first_frames, fixtures, root, scaled};

#[test]
fn blender_fbx_files_put_every_joint_where_the_bvh_does() {
    for clip in ["human_walk_cmu_131_01", "fox_survey_khronos"] {
        let bvh = read_bvh(fixtures().join(format!("{clip}_2s.bvh"))).unwrap();
        for variant in ["armature", "skinned"] {
            let file = fbx_fixture(&format!("{clip}_{variant}.fbx"));
            let read = read_fbx(&file, &ReadOptions::default()).unwrap();
            let what = format!("{clip} {variant}");
            assert_eq!(read.clip.fps, bvh.fps, "{what}");
            assert_eq!(read.animations.len(), 1, "{what}");
            let frames = read.clip.frame_count();
            assert_eq!(frames, bvh.fps.round() as usize + 1, "{what}: one second");
            assert_matches_bvh(&read.clip, &first_frames(&bvh, frames), &what);
        }
    }
}

#[test]
fn a_mixamo_style_file_reads_as_its_bvh_in_metres() {
    // Written by lab/scripts/make_mixamo_style_fbx.py from the cut walk: ASCII, a 'mixamorig:'
    // namespace, centimetres (5.64 cm to the BVH unit), rest orientations in PreRotation, some
    // PostRotations, '_End' leaf bones.
    let file = root().join("tests/data/fbx/human_walk_cmu_131_01_mixamo_style.fbx");
    let read = read_fbx(&file, &ReadOptions::default()).unwrap();
    assert!((read.file_unit_meters - 0.01).abs() < 1e-12);
    assert_eq!(read.animations[0].name.as_deref(), Some("mixamo.com"));
    assert!(
        read.clip
            .skeleton
            .joints
            .iter()
            .all(|j| !j.name.contains(':'))
    );
    let bvh = read_bvh(fixtures().join("human_walk_cmu_131_01_2s.bvh")).unwrap();
    let source = scaled(&first_frames(&bvh, read.clip.frame_count()), 0.0564);
    assert_eq!(read.clip.frame_count(), 31);
    assert_matches_bvh(&read.clip, &source, "mixamo-style walk");
}
