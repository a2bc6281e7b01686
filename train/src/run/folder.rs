//! The files of a training run's folder besides its checkpoints: the copies of the clip and the
//! configuration, and the loss log.

use std::path::{Path, PathBuf};

/// Copy of the clip inside the run folder, so a run resumes without the original file: this
/// name with the clip's own extension (`clip.bvh`, `clip.glb`, `clip.gltf`, `clip.fbx`).
pub const CLIP_COPY: &str = "clip";
/// The extensions a clip copy may have.
const CLIP_EXTENSIONS: [&str; 4] = ["bvh", "glb", "gltf", "fbx"];

/// The clip copy in run folder `run` for a clip at `clip` (its extension kept, lower-case).
pub(crate) fn clip_copy(run: &Path, clip: &Path) -> PathBuf {
    let extension = clip
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .filter(|e| CLIP_EXTENSIONS.contains(&e.as_str()))
        .unwrap_or_else(|| "bvh".into());
    run.join(format!("{CLIP_COPY}.{extension}"))
}

/// The clip copy a run folder holds, if any.
pub fn saved_clip(run: &Path) -> Option<PathBuf> {
    CLIP_EXTENSIONS
        .iter()
        .map(|e| run.join(format!("{CLIP_COPY}.{e}")))
        .find(|p| p.is_file())
}

/// Copy of the configuration inside the run folder.
pub const CONFIG_COPY: &str = "config.yaml";
/// The loss log inside the run folder.
pub const LOSS_LOG: &str = "loss.csv";
