//! Finding and loading the onnxruntime shared library (`ort` with `load-dynamic`).
//!
//! The search, in order; the first library that loads and is recent enough wins:
//! 1. the file a host names with [`load_onnxruntime`] (then nothing else is tried);
//! 2. the file named by the `ORT_DYLIB_PATH` environment variable (`ort`'s own; then nothing
//!    else is tried);
//! 3. next to the running executable (where a game ships it);
//! 4. next to the library that holds this code, when that is not the executable (the C ABI's
//!    `sinmdm_c` inside an engine's plugin folder);
//! 5. by bare name through the system loader's own search (`LD_LIBRARY_PATH`, the `ldconfig`
//!    cache, `DYLD_LIBRARY_PATH`, or on Windows its DLL search order, which reaches System32,
//!    where Windows may keep an onnxruntime.dll of its own and of another release: a program
//!    ships its own next to its executable so that it is found first);
//! 6. a developer checkout's `.venv` (made by the project's set-up script), above the working
//!    directory or the executable.
//!
//! A library older than [`ONNXRUNTIME_OLDEST`] is refused and the search goes on. When nothing
//! loads, the error names every place of steps 2 to 6 in order, with what each gave, so a host
//! can tell which it meant to use. Nothing of the machine the crate was built on is searched. A
//! failed attempt is not remembered: the next one searches (or loads) again.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use thiserror::Error;

use search::{Candidate, Folders, Place, checkout_roots, places, usual_name};

mod own_library;
mod search;

/// The onnxruntime version the project pins and tests with (the PyPI wheel
/// `onnxruntime==1.31.1`).
pub const ONNXRUNTIME_VERSION: &str = "1.31.1";

/// The oldest onnxruntime release the runtime works with (the C API level it asks for).
pub const ONNXRUNTIME_OLDEST: &str = "1.17";

/// The onnxruntime library could not be found or loaded.
#[derive(Debug, Error, Clone)]
pub enum RuntimeLibraryError {
    /// No library that loads in any searched place.
    #[error(
        "onnxruntime (release {ONNXRUNTIME_OLDEST} or later, tested with {ONNXRUNTIME_VERSION}) was not found; \
         ship {file} next to the program's executable, or set ORT_DYLIB_PATH to the library file. \
         Tried, in order: {searched}"
    )]
    NotFound {
        /// The usual file name on this platform.
        file: &'static str,
        /// The places tried, each with what went wrong there.
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
    /// The file exists but onnxruntime would not load from it (or it is too old).
    #[error("could not load onnxruntime from '{path}': {message}")]
    LoadFailed {
        /// The library file.
        path: PathBuf,
        /// What the loader said.
        message: String,
    },
}

/// The loaded onnxruntime: the library's path and the process-wide environment every session
/// is created in.
pub struct OnnxRuntime {
    /// The shared library that was loaded.
    pub path: PathBuf,
    /// Its release as the library reports it (`"1.31.1"`); `None` where it could not be asked.
    pub version: Option<String>,
    /// The place of the search that gave it (`"next to the executable"`, `"ORT_DYLIB_PATH"`, ...),
    /// so a host can tell which of several copies it runs.
    pub found_in: String,
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
    let places = match asked {
        Some(p) if p.is_file() => vec![Place {
            what: "the library asked for".into(),
            found: vec![Candidate::File(
                std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()),
            )],
        }],
        Some(p) => {
            return Err(RuntimeLibraryError::LoadFailed {
                path: p.to_path_buf(),
                message: "no such file".into(),
            });
        }
        None => places(
            std::env::var_os("ORT_DYLIB_PATH"),
            &Folders::of_this_process(),
            &checkout_roots(),
        )?,
    };
    let (mut tried, mut messages, mut seen) =
        (Vec::new(), Vec::new(), std::collections::HashSet::new());
    for place in &places {
        if place.found.is_empty() {
            tried.push(place.what.clone());
        }
        for candidate in place.found.iter().filter(|c| seen.insert(*c)) {
            let path = match candidate {
                Candidate::File(p) => p.clone(),
                Candidate::System(name) => PathBuf::from(name),
            };
            match start_environment(&path) {
                Ok(environment) => {
                    let version = crate::onnxruntime_version::library_version(&path);
                    let found_in = place.what.clone();
                    return Ok(LOADED.get_or_init(|| OnnxRuntime {
                        path,
                        version,
                        found_in,
                        environment,
                    }));
                }
                Err(Attempt::NotLoaded(message)) => {
                    tried.push(format!("{}: {candidate} ({message})", place.what));
                    messages.push(message);
                }
                // The library loaded (and stays loaded: one per process) but would not start:
                // trying another would only reuse it.
                Err(Attempt::Failed(message)) => {
                    return Err(RuntimeLibraryError::LoadFailed { path, message });
                }
            }
        }
    }
    let list: Vec<&Candidate> = places.iter().flat_map(|p| &p.found).collect();
    match (asked, list.as_slice()) {
        (Some(p), _) => Err(RuntimeLibraryError::LoadFailed {
            path: p.to_path_buf(),
            message: messages.join("; "),
        }),
        (None, [Candidate::File(p)])
            if std::env::var_os("ORT_DYLIB_PATH").is_some_and(|v| !v.is_empty()) =>
        {
            Err(RuntimeLibraryError::LoadFailed {
                path: p.clone(),
                message: messages.join("; "),
            })
        }
        _ => Err(RuntimeLibraryError::NotFound {
            file: usual_name(),
            searched: tried.join("; "),
        }),
    }
}

/// Why a candidate library did not give an environment.
enum Attempt {
    /// It could not be loaded (missing, not a library, too old): the search goes on.
    NotLoaded(String),
    /// It loaded but the environment would not start: the process keeps it, so the search ends.
    Failed(String),
}

/// Loads the library at `path` (a bare name goes to the system loader) and makes the process's
/// environment; the loader's or onnxruntime's words on failure (a release older than
/// [`ONNXRUNTIME_OLDEST`] is refused before it is kept).
fn start_environment(path: &Path) -> Result<ort::environment::Environment, Attempt> {
    // ort resolves a bare name against the executable's folder and asks for that folder, which
    // cannot be had everywhere; there the system loader is not tried.
    if !path.is_absolute() && std::env::current_exe().is_err() {
        return Err(Attempt::NotLoaded(
            "the executable's folder is unknown here, so the system loader is not asked".into(),
        ));
    }
    ort::init_from(path)
        .map_err(|e| Attempt::NotLoaded(e.to_string()))?
        .with_name("sinmdm")
        .with_telemetry(false)
        .build()
        .map_err(|e| Attempt::Failed(e.to_string()))
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

    #[test]
    fn not_found_speaks_to_whoever_ships_the_program() {
        let e = RuntimeLibraryError::NotFound {
            file: usual_name(),
            searched: "x".into(),
        };
        let message = e.to_string();
        assert!(
            message.contains("next to the program's executable"),
            "{message}"
        );
        assert!(message.contains("ORT_DYLIB_PATH"), "{message}");
        assert!(message.contains(ONNXRUNTIME_OLDEST), "{message}");
        assert!(!message.contains("setup"), "{message}");
    }
}
