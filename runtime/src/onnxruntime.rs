//! Finding and loading the onnxruntime shared library (`ort` with `load-dynamic`).
//!
//! A host that ships the library names it with [`load_onnxruntime`]. Otherwise the first model
//! opened looks for it: the `ORT_DYLIB_PATH` environment variable (the `ort` crate's own), then
//! the project's Python virtual environment made by `scripts/setup.sh`
//! (`.venv/.../onnxruntime/capi/`), looked for above the current directory and above the running
//! executable. Nothing of the machine the crate was built on is searched. A failed attempt is not
//! remembered: the next one searches (or loads) again.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use thiserror::Error;

/// The onnxruntime version the project pins (the PyPI wheel `onnxruntime==1.31.1`).
pub const ONNXRUNTIME_VERSION: &str = "1.31.1";

/// The onnxruntime library could not be found or loaded.
#[derive(Debug, Error, Clone)]
pub enum RuntimeLibraryError {
    /// No library in any searched place.
    #[error(
        "the onnxruntime {ONNXRUNTIME_VERSION} shared library was not found (looked in: {searched}); \
         run `scripts/setup.sh` in the sinmdm-rs checkout, or set ORT_DYLIB_PATH to the library file"
    )]
    NotFound {
        /// The places looked at.
        searched: String,
    },
    /// `ORT_DYLIB_PATH` names a file that does not exist.
    #[error("ORT_DYLIB_PATH is set to '{0}', which does not exist")]
    EnvPathMissing(PathBuf),
    /// The host named a library after another one was loaded (one per process).
    #[error("onnxruntime is already loaded from '{loaded}'; cannot load '{asked}' as well")]
    AlreadyLoaded {
        /// The library in use.
        loaded: PathBuf,
        /// The library asked for.
        asked: PathBuf,
    },
    /// The file exists but onnxruntime would not load from it.
    #[error("could not load onnxruntime from '{path}': {message}")]
    LoadFailed {
        /// The library file.
        path: PathBuf,
        /// What the loader said.
        message: String,
    },
}

/// File names the library has in the PyPI wheel on each platform.
fn library_names() -> &'static [&'static str] {
    if cfg!(target_os = "windows") {
        &["onnxruntime.dll"]
    } else if cfg!(target_os = "macos") {
        &["libonnxruntime.1.31.1.dylib", "libonnxruntime.dylib"]
    } else {
        &[
            "libonnxruntime.so.1.31.1",
            "libonnxruntime.so.1",
            "libonnxruntime.so",
        ]
    }
}

/// The onnxruntime library inside a virtual environment, if present.
fn in_venv(venv: &Path) -> Option<PathBuf> {
    let mut site_packages = vec![venv.join("Lib").join("site-packages")];
    if let Ok(entries) = std::fs::read_dir(venv.join("lib")) {
        let mut pythons: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("python"))
            })
            .collect();
        pythons.sort();
        site_packages.extend(pythons.into_iter().map(|p| p.join("site-packages")));
    }
    site_packages.into_iter().find_map(|sp| {
        let capi = sp.join("onnxruntime").join("capi");
        library_names()
            .iter()
            .map(|name| capi.join(name))
            .find(|p| p.is_file())
    })
}

/// Directories whose `.venv` may hold the library, nearest first.
fn candidate_roots() -> Vec<PathBuf> {
    let mut roots = Vec::new();
    if let Ok(dir) = std::env::current_dir() {
        roots.extend(dir.ancestors().map(Path::to_path_buf));
    }
    if let Ok(exe) = std::env::current_exe() {
        roots.extend(exe.ancestors().skip(1).map(Path::to_path_buf));
    }
    let mut seen = std::collections::HashSet::new();
    roots.retain(|r| seen.insert(r.clone()));
    roots
}

/// Where the onnxruntime shared library is, following the search order above.
pub fn locate_library() -> Result<PathBuf, RuntimeLibraryError> {
    locate_in(std::env::var_os("ORT_DYLIB_PATH"), &candidate_roots())
}

/// The search itself: `env_path` first, then `.venv` under each root in turn.
fn locate_in(
    env_path: Option<std::ffi::OsString>,
    roots: &[PathBuf],
) -> Result<PathBuf, RuntimeLibraryError> {
    if let Some(path) = env_path.filter(|p| !p.is_empty()) {
        let path = PathBuf::from(path);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(RuntimeLibraryError::EnvPathMissing(path))
        };
    }
    if let Some(found) = roots.iter().find_map(|r| in_venv(&r.join(".venv"))) {
        return Ok(found);
    }
    Err(RuntimeLibraryError::NotFound {
        searched: std::iter::once("ORT_DYLIB_PATH (unset)".to_string())
            .chain(roots.iter().map(|r| r.join(".venv").display().to_string()))
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// The loaded onnxruntime: the library's path and the process-wide environment every session
/// is created in.
pub struct OnnxRuntime {
    /// The shared library that was loaded.
    pub path: PathBuf,
    /// The onnxruntime environment (one per process); kept private so that `ort`'s release
    /// candidate stays out of the engine API.
    pub(crate) environment: ort::environment::Environment,
}

impl OnnxRuntime {
    /// The onnxruntime environment, for the project's own tests and benchmarks that open
    /// sessions beside the runtime's (not part of the engine API).
    #[doc(hidden)]
    pub fn environment(&self) -> &ort::environment::Environment {
        &self.environment
    }
}

impl std::fmt::Debug for OnnxRuntime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OnnxRuntime")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

static LOADED: OnceLock<OnnxRuntime> = OnceLock::new();
static LOADING: Mutex<()> = Mutex::new(());

/// The onnxruntime in use: the one already loaded, or the library found by the search above,
/// loaded now. Only a success is kept; after an error the next call tries again.
pub fn init() -> Result<&'static OnnxRuntime, RuntimeLibraryError> {
    load(None)
}

/// Loads onnxruntime from the library file `path` (a host that ships its own copy). Returns the
/// runtime already loaded if it came from the same file, and an error if from another.
pub fn load_onnxruntime(
    path: impl AsRef<Path>,
) -> Result<&'static OnnxRuntime, RuntimeLibraryError> {
    load(Some(path.as_ref()))
}

fn load(asked: Option<&Path>) -> Result<&'static OnnxRuntime, RuntimeLibraryError> {
    let check = |runtime: &'static OnnxRuntime| match asked {
        Some(asked) if !same_file(asked, &runtime.path) => {
            Err(RuntimeLibraryError::AlreadyLoaded {
                loaded: runtime.path.clone(),
                asked: asked.to_path_buf(),
            })
        }
        _ => Ok(runtime),
    };
    if let Some(runtime) = LOADED.get() {
        return check(runtime);
    }
    let _one_at_a_time = LOADING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(runtime) = LOADED.get() {
        return check(runtime);
    }
    let path = match asked {
        Some(p) if p.is_file() => p.to_path_buf(),
        Some(p) => {
            return Err(RuntimeLibraryError::LoadFailed {
                path: p.to_path_buf(),
                message: "no such file".into(),
            });
        }
        None => locate_library()?,
    };
    let failed = |message: String| RuntimeLibraryError::LoadFailed {
        path: path.clone(),
        message,
    };
    let environment = ort::init_from(&path)
        .map_err(|e| failed(e.to_string()))?
        .with_name("sinmdm")
        .with_telemetry(false)
        .build()
        .map_err(|e| failed(e.to_string()))?;
    Ok(LOADED.get_or_init(|| OnnxRuntime { path, environment }))
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_root(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("sinmdm-ort-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn finds_the_library_in_a_project_venv() {
        let root = temp_root("venv");
        let capi = root.join(".venv/lib/python3.12/site-packages/onnxruntime/capi");
        std::fs::create_dir_all(&capi).unwrap();
        let lib = capi.join(library_names()[0]);
        std::fs::write(&lib, b"").unwrap();
        let elsewhere = temp_root("empty");
        assert_eq!(
            locate_in(None, &[elsewhere.clone(), root.clone()]).unwrap(),
            lib
        );
        std::fs::remove_dir_all(root).unwrap();
        std::fs::remove_dir_all(elsewhere).unwrap();
    }

    #[test]
    fn the_environment_variable_wins_and_must_exist() {
        let missing = PathBuf::from("/nonexistent/libonnxruntime.so");
        let e = locate_in(Some(missing.clone().into()), &[]).unwrap_err();
        assert!(matches!(e, RuntimeLibraryError::EnvPathMissing(p) if p == missing));
    }

    #[test]
    fn not_found_says_what_to_run() {
        let root = temp_root("none");
        let e = locate_in(None, std::slice::from_ref(&root)).unwrap_err();
        let message = e.to_string();
        assert!(message.contains("scripts/setup.sh"), "{message}");
        assert!(message.contains("ORT_DYLIB_PATH"), "{message}");
        std::fs::remove_dir_all(root).unwrap();
    }
}
