//! BVH -> glTF -> our reader, and glTF -> BVH -> glTF, on every clip the project ships or
//! shares: world joint and End Site positions agree within 1e-5 of the skeleton's height, every
//! frame (forward kinematics of the source BVH, turned into glTF's +Y up and metres, is the
//! independent expectation).

use std::path::{Path, PathBuf};

use sinmdm::bvh::{parse_bvh, read_bvh, to_bvh_string};
use sinmdm::motion::math::Vec3;
use sinmdm::motion::up_detect::choose_up;
use sinmdm::motion::{LocalMotion, UpAxis, global_poses, skeleton_height};
use sinmdm_formats::ReadOptions;
use sinmdm_formats::gltf::{GltfWriteOptions, read_gltf, write_gltf};
use sinmdm_formats::{UnitGuess, read_clip};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The shipped clips, then the shared folder's (beside the checkout) that are not shipped.
fn clips() -> Vec<PathBuf> {
    let mut all: Vec<PathBuf> = std::fs::read_dir(root().join("tests/data/bvh"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    all.sort();
    assert!(all.len() >= 4, "the shipped clips are missing");
    let names: Vec<_> = all
        .iter()
        .map(|p| p.file_name().unwrap().to_owned())
        .collect();
    if let Ok(shared) = std::fs::read_dir(root().parent().unwrap().join("shared/data/bvh")) {
        let mut extra: Vec<PathBuf> = shared
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
            .filter(|p| !names.contains(&p.file_name().unwrap().to_owned()))
            .collect();
        extra.sort();
        all.extend(extra);
    }
    all
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Every frame's joint and End Site positions, flattened.
fn positions(motion: &LocalMotion) -> Vec<Vec<Vec3>> {
    global_poses(motion)
        .iter()
        .map(|pose| pose.points().collect())
        .collect()
}

/// The largest distance between corresponding points of two position sets of equal shape.
fn worst_distance(a: &[Vec<Vec3>], b: &[Vec<Vec3>]) -> f64 {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    let mut worst = 0.0f64;
    for (fa, fb) in a.iter().zip(b) {
        assert_eq!(fa.len(), fb.len(), "point counts differ");
        for (p, q) in fa.iter().zip(fb) {
            worst = worst.max((*p - *q).norm());
        }
    }
    worst
}

#[test]
fn bvh_to_gltf_and_back_keeps_every_joint_where_it_was() {
    for clip in clips() {
        let name = clip.file_name().unwrap().to_string_lossy().into_owned();
        let source = read_bvh(&clip).unwrap().to_local();
        let (up, _) = choose_up(&source, None);
        let height = skeleton_height(&global_poses(&sinmdm::motion::up::to_canonical(
            &source, up,
        )));
        let unit = UnitGuess::from_height(height).metres_per_unit();
        let options = GltfWriteOptions {
            up,
            metres_per_unit: unit,
            proxy_mesh: false,
        };
        // Expected: the source's points in glTF's frame and metres.
        let turn = up.canonical_from_file();
        let expected: Vec<Vec<Vec3>> = positions(&source)
            .into_iter()
            .map(|frame| frame.into_iter().map(|p| (turn * p) * unit).collect())
            .collect();
        let tolerance = 1e-5 * height * unit;
        for extension in ["glb", "gltf"] {
            let file = scratch(&format!("{name}.{extension}"));
            write_gltf(&file, &[("clip".into(), &source)], &options).unwrap();
            let read = read_gltf(&file, &ReadOptions::default()).unwrap();
            assert_eq!(read.clip.fps, source.fps, "{name}");
            let motion = read.clip.to_local();
            assert_eq!(motion.skeleton.len(), source.skeleton.len(), "{name}");
            let names: Vec<_> = motion.skeleton.joints.iter().map(|j| &j.name).collect();
            let source_names: Vec<_> = source.skeleton.joints.iter().map(|j| &j.name).collect();
            assert_eq!(names, source_names, "{name}");
            let worst = worst_distance(&expected, &positions(&motion));
            assert!(
                worst <= tolerance,
                "{name}.{extension}: {worst} m > {tolerance} m"
            );

            // glTF -> BVH -> glTF: the BVH text of what was read, written again as glTF.
            let bvh = parse_bvh(&to_bvh_string(&read.clip), "again.bvh").unwrap();
            let again = scratch(&format!("{name}.again.{extension}"));
            let same_frame = GltfWriteOptions {
                up: UpAxis::PosY,
                metres_per_unit: 1.0,
                proxy_mesh: false,
            };
            write_gltf(&again, &[("clip".into(), &bvh.to_local())], &same_frame).unwrap();
            let twice = read_gltf(&again, &ReadOptions::default()).unwrap();
            let worst = worst_distance(&expected, &positions(&twice.clip.to_local()));
            assert!(
                worst <= tolerance,
                "{name}.{extension} twice: {worst} m > {tolerance} m"
            );
            std::fs::remove_file(file).unwrap();
            std::fs::remove_file(again).unwrap();
        }
    }
}

#[test]
fn a_crowd_is_one_file_with_one_animation_each() {
    let walk = read_bvh(root().join("tests/data/bvh/human_walk_cmu_131_01.bvh"))
        .unwrap()
        .to_local();
    // Three "samples": the walk, its first half, and the walk mirrored in time.
    let frames = walk.frame_count();
    let joints = walk.skeleton.len();
    let mut half = walk.clone();
    half.rotations.truncate(frames / 2 * joints);
    half.translations.truncate(frames / 2 * joints);
    let mut reversed = walk.clone();
    for f in 0..frames {
        for j in 0..joints {
            reversed.rotations[f * joints + j] = walk.rotations[(frames - 1 - f) * joints + j];
            reversed.translations[f * joints + j] =
                walk.translations[(frames - 1 - f) * joints + j];
        }
    }
    let file = scratch("crowd.glb");
    let samples = [
        ("sample_000".to_string(), &walk),
        ("sample_001".to_string(), &half),
        ("sample_002".to_string(), &reversed),
    ];
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: 0.05,
        proxy_mesh: false,
    };
    write_gltf(&file, &samples, &options).unwrap();
    for (index, (name, motion)) in samples.iter().enumerate() {
        let by_name = ReadOptions {
            animation: Some(sinmdm_formats::AnimationChoice::Name(name.clone())),
            fps: None,
        };
        let (clip, source) = read_clip(&file, &by_name).unwrap();
        assert_eq!(source.animations.len(), 3);
        assert_eq!(source.animation.as_ref().unwrap().index, index);
        assert_eq!(clip.frame_count(), motion.frame_count());
        let expected: Vec<Vec<Vec3>> = positions(motion)
            .into_iter()
            .map(|f| f.into_iter().map(|p| p * 0.05).collect())
            .collect();
        let worst = worst_distance(&expected, &positions(&clip.to_local()));
        assert!(worst < 1e-5, "{name}: {worst}");
    }
    let err = read_clip(
        &file,
        &ReadOptions {
            animation: Some(sinmdm_formats::AnimationChoice::Index(3)),
            fps: None,
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("no animation 3"), "{err}");
    std::fs::remove_file(file).unwrap();
}

#[test]
fn a_gltf_with_a_side_car_buffer_reads_like_the_embedded_one() {
    let fox = read_bvh(root().join("tests/data/bvh/fox_survey_khronos.bvh"))
        .unwrap()
        .to_local();
    let options = GltfWriteOptions {
        up: UpAxis::PosY,
        metres_per_unit: 0.01,
        proxy_mesh: false,
    };
    let embedded = scratch("fox_embedded.gltf");
    write_gltf(&embedded, &[("Survey".into(), &fox)], &options).unwrap();
    // The same document with its buffer moved to a file beside it (a name with a space, so
    // the URI is percent-encoded).
    let mut document: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&embedded).unwrap()).unwrap();
    let uri = document["buffers"][0]["uri"].as_str().unwrap().to_string();
    let data = uri.split_once("base64,").unwrap().1;
    let bytes = sinmdm_formats::gltf::container::base64_decode(data).unwrap();
    std::fs::write(scratch("fox data.bin"), &bytes).unwrap();
    document["buffers"][0]["uri"] = serde_json::json!("fox%20data.bin");
    let side_car = scratch("fox_side_car.gltf");
    std::fs::write(&side_car, serde_json::to_vec(&document).unwrap()).unwrap();
    let a = read_gltf(&embedded, &ReadOptions::default()).unwrap().clip;
    let b = read_gltf(&side_car, &ReadOptions::default()).unwrap().clip;
    assert_eq!(a, b);
    // Without its buffer file, the error names the file it looked for.
    std::fs::remove_file(scratch("fox data.bin")).unwrap();
    let err = read_gltf(&side_car, &ReadOptions::default()).unwrap_err();
    assert!(err.to_string().contains("fox data.bin"), "{err}");
}
