//! The library manifest: a YAML file listing the clips, each with optional settings.
//!
//! ```yaml
//! out: library            # where the clips' folders go (default: `library` beside this file)
//! config: configs/tiny.yaml   # training configuration of every clip (default: the built-in one)
//! samples: 4              # samples of each model's evaluation (default 4)
//! clips:
//!   - clip: clips/walk.bvh      # paths are relative to this file
//!     name: walk                # the folder's name (default: the file's stem)
//!     animation: Walk           # glTF/FBX: which animation
//!     fps: 30                   # learn at this frame rate (default: the config's)
//!     up: z                     # the clip's up axis (default: read from the motion)
//!     contacts: [LeftFoot, RightFoot]
//!     window: 5                 # QnA window (default: the config's)
//!     config: configs/cpu.yaml  # this clip's own configuration
//! ```

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::LibraryError;

/// One clip of the library and its settings (paths as written in the manifest).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipEntry {
    /// The clip file (.bvh, .glb, .gltf, .fbx), relative to the manifest.
    pub clip: PathBuf,
    /// The task folder's name (letters, digits, `-`, `_`, `.`); default: the clip's file stem.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The animation of a glTF or FBX clip, by name or index.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<String>,
    /// The frame rate to learn the clip at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f64>,
    /// The clip's up axis (`x`, `y`, `z`, `-x`, `-y`, `-z`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<String>,
    /// Contact joints by name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contacts: Option<Vec<String>>,
    /// The QnA window (odd).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<usize>,
    /// This clip's training configuration, relative to the manifest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub config: Option<PathBuf>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestFile {
    #[serde(default)]
    out: Option<PathBuf>,
    #[serde(default)]
    config: Option<PathBuf>,
    #[serde(default)]
    samples: Option<usize>,
    clips: Vec<ClipEntry>,
}

/// A manifest read and checked, its paths resolved against its folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Manifest {
    /// The manifest file.
    pub path: PathBuf,
    /// Where the clips' folders go.
    pub out: PathBuf,
    /// The configuration of clips without their own (`None`: the built-in default).
    pub config: Option<PathBuf>,
    /// Samples of each model's evaluation.
    pub samples: usize,
    /// The clips, with their paths resolved and names set.
    pub clips: Vec<ClipEntry>,
}

/// The default number of evaluation samples per model.
pub const DEFAULT_SAMPLES: usize = 4;

fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && !name.starts_with('.')
        && !name.ends_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
}

impl Manifest {
    /// Reads and checks a manifest: at least one clip, every name valid and unique (two tasks
    /// never share a folder), every clip file present.
    pub fn load(path: &Path) -> Result<Manifest, LibraryError> {
        let text = sinmdm::files::read_text_file(path, "a manifest")
            .map_err(|e| LibraryError::io(path, e))?;
        let bad = |message: String| LibraryError::Manifest {
            path: path.to_path_buf(),
            message,
        };
        let file: ManifestFile = serde_yaml::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if file.clips.is_empty() {
            return Err(bad("the manifest lists no clips".into()));
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let resolve = |p: &Path| {
            if p.is_absolute() {
                p.to_path_buf()
            } else {
                base.join(p)
            }
        };
        // Compared lower-cased: on a case-insensitive file system `Walk` and `walk` would share
        // a folder.
        let mut names = BTreeSet::new();
        let mut clips = Vec::with_capacity(file.clips.len());
        for (index, mut entry) in file.clips.into_iter().enumerate() {
            entry.clip = resolve(&entry.clip);
            entry.config = entry.config.as_deref().map(resolve);
            let name = match &entry.name {
                Some(n) => n.clone(),
                None => entry
                    .clip
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default(),
            };
            if !valid_name(&name) {
                return Err(bad(format!(
                    "clips[{index}]: '{name}' is not a folder name (letters, digits, '-', '_', '.'); set `name`"
                )));
            }
            if !names.insert(name.to_lowercase()) {
                return Err(bad(format!(
                    "clips[{index}]: the name '{name}' is taken by another clip; set `name` so that every task has a folder of its own"
                )));
            }
            if let Some(window) = entry.window
                && window % 2 == 0
            {
                return Err(bad(format!(
                    "clips[{index}] ({name}): window {window} must be odd"
                )));
            }
            if let Some(fps) = entry.fps
                && !(fps.is_finite() && fps > 0.0)
            {
                return Err(bad(format!(
                    "clips[{index}] ({name}): fps {fps} must be positive"
                )));
            }
            entry.name = Some(name);
            clips.push(entry);
        }
        let samples = file.samples.unwrap_or(DEFAULT_SAMPLES);
        if samples == 0 {
            return Err(bad("samples must be at least 1".into()));
        }
        Ok(Manifest {
            path: path.to_path_buf(),
            out: resolve(file.out.as_deref().unwrap_or(Path::new("library"))),
            config: file.config.as_deref().map(resolve),
            samples,
            clips,
        })
    }

    /// Clip `index`, or an error naming the range.
    pub fn entry(&self, index: usize) -> Result<&ClipEntry, LibraryError> {
        self.clips.get(index).ok_or_else(|| {
            LibraryError::Index(format!(
                "task index {index} is not in {}, which lists {} clips (0 to {})",
                self.path.display(),
                self.clips.len(),
                self.clips.len() - 1
            ))
        })
    }

    /// The name of clip entry `entry` (set by [`Manifest::load`]).
    pub fn name(entry: &ClipEntry) -> &str {
        entry.name.as_deref().unwrap_or("")
    }

    /// The folder of clip entry `entry`.
    pub fn folder(&self, entry: &ClipEntry) -> PathBuf {
        self.out.join(Manifest::name(entry))
    }
}

/// The task index: `given` (a command-line flag), else Slurm's `SLURM_ARRAY_TASK_ID`, else
/// Kubernetes' `JOB_COMPLETION_INDEX` (an Indexed Job's), read from `env`.
pub fn task_index(
    given: Option<usize>,
    env: impl Fn(&str) -> Option<String>,
) -> Result<usize, LibraryError> {
    if let Some(index) = given {
        return Ok(index);
    }
    for variable in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        if let Some(value) = env(variable) {
            return value.trim().parse().map_err(|_| {
                LibraryError::Index(format!("{variable} is '{value}', not a task index"))
            });
        }
    }
    Err(LibraryError::Index(
        "no task index: pass --index N, or run as a Slurm array task (SLURM_ARRAY_TASK_ID) or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX)".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    fn temp(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("sinmdm-manifest-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn paths_resolve_against_the_manifest_and_names_default_to_the_stem() {
        let dir = temp("resolve");
        let m = write(
            &dir,
            "lib.yaml",
            "config: c.yaml\nclips:\n  - clip: clips/walk.bvh\n  - clip: /abs/hop.glb\n    name: hop2\n    window: 5\n",
        );
        let manifest = Manifest::load(&m).unwrap();
        assert_eq!(manifest.out, dir.join("library"));
        assert_eq!(manifest.config, Some(dir.join("c.yaml")));
        assert_eq!(manifest.clips[0].clip, dir.join("clips/walk.bvh"));
        assert_eq!(Manifest::name(&manifest.clips[0]), "walk");
        assert_eq!(
            manifest.folder(&manifest.clips[1]),
            dir.join("library/hop2")
        );
        assert_eq!(manifest.samples, DEFAULT_SAMPLES);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn shared_names_unknown_fields_and_even_windows_are_refused() {
        let dir = temp("refuse");
        for (text, needle) in [
            (
                "clips:\n  - clip: a/walk.bvh\n  - clip: b/walk.bvh\n",
                "taken by another clip",
            ),
            (
                "clips:\n  - clip: a.bvh\n    colour: red\n",
                "unknown field `colour`",
            ),
            ("clips:\n  - clip: a.bvh\n    window: 4\n", "must be odd"),
            ("clips: []\n", "no clips"),
            (
                "clips:\n  - clip: a.bvh\n    name: ../x\n",
                "not a folder name",
            ),
        ] {
            let m = write(&dir, "lib.yaml", text);
            let e = Manifest::load(&m).unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_index_comes_from_the_flag_slurm_or_kubernetes() {
        let none = |_: &str| None;
        assert_eq!(task_index(Some(3), none).unwrap(), 3);
        let slurm = |v: &str| (v == "SLURM_ARRAY_TASK_ID").then(|| "7".to_string());
        assert_eq!(task_index(None, slurm).unwrap(), 7);
        let k8s = |v: &str| (v == "JOB_COMPLETION_INDEX").then(|| "2".to_string());
        assert_eq!(task_index(None, k8s).unwrap(), 2);
        assert!(task_index(None, none).is_err());
        let junk = |_: &str| Some("x".to_string());
        assert!(
            task_index(None, junk)
                .unwrap_err()
                .to_string()
                .contains("not a task index")
        );
    }
}
