//! Helpers shared by the format crate's integration tests.

// Each test file uses some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use sinmdm::motion::features::{EncodeOptions, FeatureLayout, encode};
use sinmdm::motion::math::Vec3;
use sinmdm::motion::{ChannelClip, LocalMotion, UpAxis, detect_up, global_poses};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The glTF fixtures made by Blender.
pub fn fixtures() -> PathBuf {
    root().join("tests/data/gltf")
}

/// Every frame's joint positions by joint name.
pub fn positions_by_name(motion: &LocalMotion) -> Vec<Vec<(String, Vec3)>> {
    global_poses(motion)
        .iter()
        .map(|pose| {
            motion
                .skeleton
                .joints
                .iter()
                .zip(&pose.joints)
                .map(|(j, p)| (j.name.clone(), *p))
                .collect()
        })
        .collect()
}

/// The FBX fixtures: `tests/data/fbx/NAME.gz` unpacked once into a folder of this test
/// process (FBX files keep every curve's keys apart, so they are stored compressed).
pub fn fbx_fixture(name: &str) -> PathBuf {
    use std::io::Read;
    let packed = root().join("tests/data/fbx").join(format!("{name}.gz"));
    let dir = std::env::temp_dir().join(format!("sinmdm-fbx-fixtures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(name);
    if !out.exists() {
        let mut bytes = Vec::new();
        flate2::read::GzDecoder::new(std::fs::File::open(&packed).unwrap())
            .read_to_end(&mut bytes)
            .unwrap();
        // Written aside and renamed, so a test running beside never reads half a file.
        let partial = dir.join(format!("{name}.partial-{:?}", std::thread::current().id()));
        std::fs::write(&partial, bytes).unwrap();
        std::fs::rename(&partial, &out).unwrap();
    }
    out
}

/// The first `frames` frames of a clip.
pub fn first_frames(
    clip: &sinmdm::motion::ChannelClip,
    frames: usize,
) -> sinmdm::motion::ChannelClip {
    let channels = clip.skeleton.channel_count();
    sinmdm::motion::ChannelClip {
        skeleton: clip.skeleton.clone(),
        fps: clip.fps,
        values: clip.values[..frames * channels].to_vec(),
    }
}

/// Largest distance between a joint of `got` and the same-named joint of `expected`, frame by
/// frame, and how many positions were compared.
pub fn worst_distance(got: &ChannelClip, expected: &ChannelClip) -> (f64, usize) {
    let got = positions_by_name(&got.to_local());
    let expected = positions_by_name(&expected.to_local());
    assert_eq!(got.len(), expected.len());
    let mut worst = 0.0f64;
    let mut compared = 0;
    for (frame_got, frame_expected) in got.iter().zip(&expected) {
        for (name, p) in frame_got {
            let (_, q) = frame_expected
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("no joint {name} in the BVH"));
            worst = worst.max((*p - *q).norm());
            compared += 1;
        }
    }
    (worst, compared)
}

/// Asserts that `clip`, read from a file another program wrote from the BVH clip `source`, has
/// its joints (the source's End Sites included), up axis, height and contact joints, and puts
/// every joint within 1e-5 of the height of where the source puts it, every frame.
pub fn assert_matches_bvh(clip: &ChannelClip, source: &ChannelClip, what: &str) {
    assert_eq!(clip.fps, source.fps, "{what}: frame rate");
    assert_eq!(clip.frame_count(), source.frame_count(), "{what}: frames");
    assert_eq!(clip.skeleton.len(), source.skeleton.len(), "{what}: joints");
    let ends = |c: &ChannelClip| {
        c.skeleton
            .joints
            .iter()
            .filter(|j| j.end_site.is_some())
            .count()
    };
    assert_eq!(ends(clip), ends(source), "{what}: End Sites");
    assert_eq!(detect_up(&clip.to_local()).axis, UpAxis::PosY, "{what}");

    let options = EncodeOptions::default();
    let ours = encode(clip, &options).unwrap().layout;
    let theirs = encode(source, &options).unwrap().layout;
    let height = theirs.skeleton_height;
    assert_eq!(ours.up, theirs.up, "{what}");
    assert!(
        (ours.skeleton_height - height).abs() <= 1e-5 * height,
        "{what}: height {} against {height}",
        ours.skeleton_height
    );
    let names = |l: &FeatureLayout| -> Vec<String> {
        l.contact_joints
            .iter()
            .map(|&j| l.skeleton.joints[j].name.clone())
            .collect()
    };
    assert_eq!(names(&ours), names(&theirs), "{what}: contacts");

    let (worst, compared) = worst_distance(clip, source);
    assert_eq!(
        compared,
        source.skeleton.len() * source.frame_count(),
        "{what}"
    );
    assert!(worst <= 1e-5 * height, "{what}: {worst} > 1e-5 x {height}");
}

/// `clip` with every length (offsets, End Sites, position channels) times `factor`.
pub fn scaled(clip: &ChannelClip, factor: f64) -> ChannelClip {
    use sinmdm::motion::Channel;
    let mut out = clip.clone();
    let mut is_position = Vec::new();
    for joint in &mut out.skeleton.joints {
        joint.offset = joint.offset * factor;
        joint.end_site = joint.end_site.map(|e| e * factor);
        is_position.extend(
            joint
                .channels
                .iter()
                .map(|c| matches!(c, Channel::Position(_))),
        );
    }
    for (i, value) in out.values.iter_mut().enumerate() {
        if is_position[i % is_position.len()] {
            *value *= factor;
        }
    }
    out
}

/// A small deterministic generator (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}
