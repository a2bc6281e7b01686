//! glTF files written by Blender (tests/data/gltf, made from the shipped walk and fox cut to
//! 2 s, a still bone at each End Site): our reader puts every joint where forward kinematics of
//! the source BVH puts it, within 1e-5 of the skeleton's height, every frame, folds the still
//! end bones into End Sites, and gives the same up axis, height and contacts as the BVH.

use sinmdm::bvh::read_bvh;
use sinmdm_formats::ReadOptions;
use sinmdm_formats::gltf::read_gltf;

mod common;
use common::{assert_matches_bvh, fixtures};

#[test]
fn blender_files_put_every_joint_where_the_bvh_does() {
    for clip in ["human_walk_cmu_131_01", "fox_survey_khronos"] {
        let source = read_bvh(fixtures().join(format!("{clip}_2s.bvh"))).unwrap();
        for variant in ["armature", "skinned"] {
            let file = fixtures().join(format!("{clip}_{variant}.glb"));
            let read = read_gltf(&file, &ReadOptions::default()).unwrap();
            assert_matches_bvh(&read.clip, &source, &format!("{clip} {variant}"));
        }
    }
}
