//! FBX files written by Blender (tests/data/fbx, made from the shipped walk and fox cut to 1 s,
//! with Blender's leaf bones): our reader puts every joint where forward kinematics of the
//! source BVH puts it, within 1e-5 of the skeleton's height, every frame, folds the leaf bones
//! into End Sites, and gives the same up axis, height and contacts as the BVH.

use sinmdm::bvh::read_bvh;
use sinmdm_formats::ReadOptions;
use sinmdm_formats::fbx::read_fbx;

mod common;
use common::{assert_matches_bvh, fbx_fixture, first_frames, fixtures};

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
