//! Where the onnxruntime library is looked for: steps 2 to 6 of the parent module's search,
//! each place with the library files found there.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use super::RuntimeLibraryError;
use super::own_library;

/// The usual file name of the library on this platform.
pub(super) fn usual_name() -> &'static str {
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
pub(super) fn checkout_roots() -> Vec<PathBuf> {
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
pub(super) struct Folders {
    pub(super) executable: Option<PathBuf>,
    pub(super) library: Option<PathBuf>,
}

impl Folders {
    pub(super) fn of_this_process() -> Folders {
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
pub(super) struct Place {
    /// The place in words ("next to the executable"), with why it gave nothing when it did.
    pub(super) what: String,
    /// The libraries to try there, in order.
    pub(super) found: Vec<Candidate>,
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
pub(super) fn places(
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
}
