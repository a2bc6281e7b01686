//! Helpers shared by the format crate's integration tests.

use std::path::{Path, PathBuf};

use sinmdm::motion::{LocalMotion, global_poses};

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
pub fn positions_by_name(motion: &LocalMotion) -> Vec<Vec<(String, [f64; 3])>> {
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
