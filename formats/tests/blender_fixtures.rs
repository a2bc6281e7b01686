//! glTF files written by Blender (tests/data/gltf, made from the shipped walk and fox cut to
//! 2 s): our reader puts every joint where forward kinematics of the source BVH puts it, within
//! 1e-5 of the skeleton's height, every frame, and reads the same up axis and frame rate.

use sinmdm::bvh::read_bvh;
use sinmdm::motion::math;
use sinmdm::motion::{UpAxis, detect_up};
use sinmdm_formats::gltf::{GltfReadOptions, read_gltf};

mod common;
use common::{fixtures, positions_by_name};

#[test]
fn blender_files_put_every_joint_where_the_bvh_does() {
    for clip in ["human_walk_cmu_131_01", "fox_survey_khronos"] {
        let source = read_bvh(fixtures().join(format!("{clip}_2s.bvh")))
            .unwrap()
            .to_local();
        let expected = positions_by_name(&source);
        let height = {
            let ys: Vec<f64> = expected.iter().flatten().map(|(_, p)| p[1]).collect();
            ys.iter().cloned().fold(f64::MIN, f64::max)
                - ys.iter().cloned().fold(f64::MAX, f64::min)
        };
        for variant in ["armature", "skinned"] {
            let file = fixtures().join(format!("{clip}_{variant}.glb"));
            let read = read_gltf(&file, &GltfReadOptions::default()).unwrap();
            assert_eq!(read.clip.fps, source.fps, "{clip} {variant}");
            let motion = read.clip.to_local();
            assert_eq!(
                motion.frame_count(),
                source.frame_count(),
                "{clip} {variant}"
            );
            assert_eq!(detect_up(&motion).axis, UpAxis::PosY);
            let got = positions_by_name(&motion);
            let mut compared = 0;
            let mut worst = 0.0f64;
            for (frame_got, frame_expected) in got.iter().zip(&expected) {
                for (name, p) in frame_got {
                    let (_, q) = frame_expected
                        .iter()
                        .find(|(n, _)| n == name)
                        .unwrap_or_else(|| panic!("{clip} {variant}: no joint {name} in the BVH"));
                    worst = worst.max(math::norm(math::sub(*p, *q)));
                    compared += 1;
                }
            }
            // Every joint but the static leaves, which became End Sites.
            assert!(
                compared >= (source.skeleton.len() - 2) * source.frame_count(),
                "{clip} {variant}: only {compared} positions compared"
            );
            assert!(
                worst <= 1e-5 * height,
                "{clip} {variant}: {worst} > 1e-5 x {height}"
            );
        }
    }
}
