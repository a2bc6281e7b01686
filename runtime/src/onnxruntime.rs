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

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use thiserror::Error;

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

/// The usual file name of the library on this platform.
fn usual_name() -> &'static str {
    if cfg!(target_os = "windows") {
        "onnxruntime.dll"
    } else if cfg!(target_os = "macos") {
        "libonnxruntime.dylib"
    } else {
        "libonnxruntime.so"
    }
}

/// Whether a file name is the onnxruntime library's on this platform (versioned names too:
/// `libonnxruntime.so.1.31.1`, `libonnxruntime.1.31.1.dylib`).
fn is_library_name(name: &str) -> bool {
    if cfg!(target_os = "windows") {
        name.eq_ignore_ascii_case("onnxruntime.dll")
    } else if cfg!(target_os = "macos") {
        name.starts_with("libonnxruntime") && name.ends_with(".dylib")
    } else {
        name == "libonnxruntime.so" || name.starts_with("libonnxruntime.so.")
    }
}

/// The library files in a folder, shortest name first (the plain name before versioned ones).
fn in_folder(folder: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.file_name()
                    .is_some_and(|n| is_library_name(&n.to_string_lossy()))
        })
        .collect();
    found.sort_by_key(|p| (p.as_os_str().len(), p.clone()));
    found
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
        in_folder(&sp.join("onnxruntime").join("capi"))
            .into_iter()
            .next()
    })
}

/// Directories whose `.venv` may hold the library, nearest first.
fn checkout_roots() -> Vec<PathBuf> {
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

/// One place the search tries.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) enum Candidate {
    /// A file found in a folder (or named), loaded by its full path.
    File(PathBuf),
    /// A bare name handed to the system loader, which searches its own path.
    System(&'static str),
}

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Candidate::File(p) => write!(f, "{}", p.display()),
            Candidate::System(name) => write!(f, "{name}"),
        }
    }
}

/// The folders a program's own files sit in, searched before the system: the executable's
/// and the one of the library holding this code.
struct Folders {
    executable: Option<PathBuf>,
    library: Option<PathBuf>,
}

impl Folders {
    fn of_this_process() -> Folders {
        Folders {
            executable: std::env::current_exe()
                .ok()
                .and_then(|p| p.parent().map(Path::to_path_buf)),
            library: own_library::path().and_then(|p| p.parent().map(Path::to_path_buf)),
        }
    }
}

/// Bare names the system loader is asked for.
fn system_names() -> &'static [&'static str] {
    if cfg!(target_os = "windows") {
        &["onnxruntime.dll"]
    } else if cfg!(target_os = "macos") {
        &["libonnxruntime.dylib"]
    } else {
        &["libonnxruntime.so.1", "libonnxruntime.so"]
    }
}

/// One place the search looks, steps 2 to 6 of the module documentation, with the libraries
/// found there; a place with none is still named when nothing loads, so that the message
/// lists every place tried.
struct Place {
    /// The place in words ("next to the executable"), with why it gave nothing when it did.
    what: String,
    /// The libraries to try there, in order.
    found: Vec<Candidate>,
}

/// The place of a program's own folder (`None` when it cannot be known), searched unless it
/// is `searched_before` (the library's folder when it is the executable's).
fn folder_place(what: &str, folder: Option<&Path>, searched_before: Option<&Path>) -> Place {
    let Some(folder) = folder else {
        return Place {
            what: format!("{what}: its folder is unknown here"),
            found: Vec::new(),
        };
    };
    if searched_before == Some(folder) {
        return Place {
            what: format!("{what}: the executable's folder, {}", folder.display()),
            found: Vec::new(),
        };
    }
    let found: Vec<Candidate> = in_folder(folder).into_iter().map(Candidate::File).collect();
    Place {
        what: if found.is_empty() {
            format!("{what}: no {} in {}", usual_name(), folder.display())
        } else {
            what.to_string()
        },
        found,
    }
}

/// The places of the module documentation's steps 2 to 6, in order, or the error when
/// `ORT_DYLIB_PATH` names a missing file (then nothing else is tried).
fn places(
    env_path: Option<OsString>,
    folders: &Folders,
    roots: &[PathBuf],
) -> Result<Vec<Place>, RuntimeLibraryError> {
    if let Some(path) = env_path.filter(|p| !p.is_empty()) {
        let path = PathBuf::from(path);
        return if path.is_file() {
            Ok(vec![Place {
                what: "ORT_DYLIB_PATH".into(),
                found: vec![Candidate::File(path)],
            }])
        } else {
            Err(RuntimeLibraryError::EnvPathMissing(path))
        };
    }
    let venvs: Vec<Candidate> = roots
        .iter()
        .filter_map(|r| in_venv(&r.join(".venv")))
        .map(Candidate::File)
        .collect();
    Ok(vec![
        Place {
            what: "ORT_DYLIB_PATH: not set".into(),
            found: Vec::new(),
        },
        folder_place(
            "next to the executable",
            folders.executable.as_deref(),
            None,
        ),
        folder_place(
            "next to this library",
            folders.library.as_deref(),
            folders.executable.as_deref(),
        ),
        Place {
            what: "the system loader's search path".into(),
            found: system_names()
                .iter()
                .map(|n| Candidate::System(n))
                .collect(),
        },
        Place {
            what: if venvs.is_empty() {
                "a developer checkout's .venv: none in the working folder, the executable's \
                 or a folder above them"
                    .into()
            } else {
                "a developer checkout's .venv".into()
            },
            found: venvs,
        },
    ])
}

/// The libraries of [`places`] to try in turn, each once (what `load` tries, for the tests).
#[cfg(test)]
fn candidates(
    env_path: Option<OsString>,
    folders: &Folders,
    roots: &[PathBuf],
) -> Result<Vec<Candidate>, RuntimeLibraryError> {
    let mut list: Vec<Candidate> = places(env_path, folders, roots)?
        .into_iter()
        .flat_map(|p| p.found)
        .collect();
    let mut seen = std::collections::HashSet::new();
    list.retain(|c| seen.insert(c.clone()));
    Ok(list)
}

/// The path of the shared library (or executable) that holds this code.
#[cfg(unix)]
mod own_library {
    use std::ffi::{CStr, c_char, c_int, c_void};
    use std::path::PathBuf;

    #[repr(C)]
    struct DlInfo {
        dli_fname: *const c_char,
        dli_fbase: *mut c_void,
        dli_sname: *const c_char,
        dli_saddr: *mut c_void,
    }

    unsafe extern "C" {
        fn dladdr(address: *const c_void, info: *mut DlInfo) -> c_int;
    }

    pub(super) fn path() -> Option<PathBuf> {
        let mut info = DlInfo {
            dli_fname: std::ptr::null(),
            dli_fbase: std::ptr::null_mut(),
            dli_sname: std::ptr::null(),
            dli_saddr: std::ptr::null_mut(),
        };
        let address = path as fn() -> Option<PathBuf> as *const c_void;
        // SAFETY: dladdr only reads the address and fills `info`; the name it points to
        // belongs to the loader and is copied at once.
        let found = unsafe { dladdr(address, &mut info) };
        if found == 0 || info.dli_fname.is_null() {
            return None;
        }
        let name = unsafe { CStr::from_ptr(info.dli_fname) };
        let path = PathBuf::from(name.to_string_lossy().into_owned());
        path.is_absolute().then_some(path)
    }
}

/// The path of the DLL (or executable) that holds this code.
#[cfg(windows)]
mod own_library {
    use std::ffi::c_void;
    use std::os::windows::ffi::OsStringExt;
    use std::path::PathBuf;

    const FROM_ADDRESS: u32 = 0x4;
    const UNCHANGED_REFCOUNT: u32 = 0x2;

    #[link(name = "kernel32")]
    unsafe extern "system" {
        fn GetModuleHandleExW(flags: u32, address: *const u16, module: *mut *mut c_void) -> i32;
        fn GetModuleFileNameW(module: *mut c_void, name: *mut u16, size: u32) -> u32;
    }

    pub(super) fn path() -> Option<PathBuf> {
        let mut module = std::ptr::null_mut();
        let address = path as fn() -> Option<PathBuf> as *const u16;
        // SAFETY: the flags ask for the module holding `address` without touching its count.
        let ok =
            unsafe { GetModuleHandleExW(FROM_ADDRESS | UNCHANGED_REFCOUNT, address, &mut module) };
        if ok == 0 {
            return None;
        }
        let mut buffer = vec![0u16; 32_768];
        let length =
            unsafe { GetModuleFileNameW(module, buffer.as_mut_ptr(), buffer.len() as u32) };
        (length > 0 && (length as usize) < buffer.len())
            .then(|| PathBuf::from(std::ffi::OsString::from_wide(&buffer[..length as usize])))
    }
}

/// Elsewhere the folder of the library holding this code is not looked up.
#[cfg(not(any(unix, windows)))]
mod own_library {
    pub(super) fn path() -> Option<std::path::PathBuf> {
        None
    }
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

    fn temp_root(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("sinmdm-ort-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn no_folders() -> Folders {
        Folders {
            executable: None,
            library: None,
        }
    }

    fn files(list: &[Candidate]) -> Vec<PathBuf> {
        list.iter()
            .filter_map(|c| match c {
                Candidate::File(p) => Some(p.clone()),
                Candidate::System(_) => None,
            })
            .collect()
    }

    #[test]
    fn the_search_order_is_executable_library_system_then_checkouts() {
        let root = temp_root("order");
        let (exe, lib, venv) = (
            root.join("game"),
            root.join("plugins"),
            root.join("checkout"),
        );
        let capi = venv.join(".venv/lib/python3.12/site-packages/onnxruntime/capi");
        for dir in [&exe, &lib, &capi] {
            std::fs::create_dir_all(dir).unwrap();
        }
        let name = usual_name();
        for dir in [&exe, &lib, &capi] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        std::fs::write(exe.join("unrelated.txt"), b"").unwrap();
        let folders = Folders {
            executable: Some(exe.clone()),
            library: Some(lib.clone()),
        };
        let list = candidates(None, &folders, std::slice::from_ref(&venv)).unwrap();
        assert_eq!(
            files(&list),
            vec![exe.join(name), lib.join(name), capi.join(name)]
        );
        let system = list
            .iter()
            .position(|c| matches!(c, Candidate::System(_)))
            .unwrap();
        assert_eq!(
            system, 2,
            "the system loader comes after both folders: {list:?}"
        );
        assert!(matches!(list.last(), Some(Candidate::File(p)) if p == &capi.join(name)));
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn a_search_that_finds_nothing_names_every_place_in_order() {
        let root = temp_root("nothing");
        let (exe, lib) = (root.join("game"), root.join("plugins"));
        for dir in [&exe, &lib] {
            std::fs::create_dir_all(dir).unwrap();
        }
        let folders = Folders {
            executable: Some(exe.clone()),
            library: Some(lib.clone()),
        };
        let list = places(None, &folders, std::slice::from_ref(&root)).unwrap();
        let what: Vec<&str> = list.iter().map(|p| p.what.as_str()).collect();
        assert_eq!(what.len(), 5, "{what:?}");
        assert_eq!(what[0], "ORT_DYLIB_PATH: not set");
        assert_eq!(
            what[1],
            format!(
                "next to the executable: no {} in {}",
                usual_name(),
                exe.display()
            )
        );
        assert_eq!(
            what[2],
            format!(
                "next to this library: no {} in {}",
                usual_name(),
                lib.display()
            )
        );
        assert_eq!(what[3], "the system loader's search path");
        assert!(
            what[4].starts_with("a developer checkout's .venv: none"),
            "{what:?}"
        );
        let with_libraries: Vec<usize> = (0..5).filter(|&i| !list[i].found.is_empty()).collect();
        assert_eq!(with_libraries, vec![3], "only the system loader is asked");
        // The executable's folder is searched once, and named again as this library's.
        let shared = Folders {
            executable: Some(exe.clone()),
            library: Some(exe.clone()),
        };
        let list = places(None, &shared, &[]).unwrap();
        assert_eq!(
            list[2].what,
            format!(
                "next to this library: the executable's folder, {}",
                exe.display()
            )
        );
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn the_environment_variable_wins_and_must_exist() {
        let missing = PathBuf::from("/nonexistent/libonnxruntime.so");
        let e = candidates(Some(missing.clone().into()), &no_folders(), &[]).unwrap_err();
        assert!(matches!(e, RuntimeLibraryError::EnvPathMissing(p) if p == missing));
    }

    #[test]
    fn the_library_holding_this_code_is_found() {
        let own = own_library::path().expect("dladdr names this test binary");
        assert!(own.is_file(), "{}", own.display());
    }

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
