//! What the readers open and how much of it: each kind of file has a named size limit checked
//! before a byte is read, only regular files are read, and a `.gltf` file's side-car buffers
//! must lie in its own folder unless the caller opts out. A file from a stranger can then not
//! make a reader take a device, a FIFO or a file elsewhere on the machine, or allocate more
//! than these limits.

use std::path::{Component, Path, PathBuf};

use sinmdm::files::{FileLimit, read_regular_file};

use crate::error::FormatError;

/// The largest `.glb` or `.gltf` file read (1 GiB): the bound of [`MAX_JOINT_FRAMES`]'s
/// transforms stored as keys.
///
/// [`MAX_JOINT_FRAMES`]: crate::MAX_JOINT_FRAMES
pub const MAX_GLTF_BYTES: u64 = 1 << 30;
/// The most bytes all buffers of one glTF asset may declare together (1 GiB), so a file cannot
/// name one large side-car file a thousand times.
pub const MAX_GLTF_BUFFER_BYTES: u64 = 1 << 30;
/// The largest `.fbx` file read (1 GiB); ufbx's own memory grows with the file.
pub const MAX_FBX_BYTES: u64 = 1 << 30;

/// The size limit of `.glb` and `.gltf` files.
pub const GLTF_LIMIT: FileLimit = FileLimit {
    bytes: MAX_GLTF_BYTES,
    name: "MAX_GLTF_BYTES",
    what: "a glTF file",
};
/// The size limit of a glTF side-car buffer, all of them together.
pub const GLTF_BUFFER_LIMIT: FileLimit = FileLimit {
    bytes: MAX_GLTF_BUFFER_BYTES,
    name: "MAX_GLTF_BUFFER_BYTES",
    what: "a glTF file's buffers",
};
/// The size limit of `.fbx` files.
pub const FBX_LIMIT: FileLimit = FileLimit {
    bytes: MAX_FBX_BYTES,
    name: "MAX_FBX_BYTES",
    what: "an FBX file",
};

/// Which files besides the one named a reader may open.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FileAccess {
    /// Read a `.gltf` file's side-car buffers outside its folder (`../other/data.bin`). Off by
    /// default: a downloaded file could otherwise make the tool read any file the user can.
    pub allow_outside_folder: bool,
}

/// Reads the whole regular file `path`, no larger than `limit`.
pub(crate) fn read_file(path: &Path, limit: FileLimit) -> Result<Vec<u8>, FormatError> {
    read_regular_file(path, limit, None).map_err(|reason| FormatError::Io {
        path: path.to_path_buf(),
        reason,
    })
}

/// Why `uri` (percent-decoded: `decoded`) may not be opened beside `gltf`, or the path it names.
/// Only paths relative to the glTF file's folder are read; one that leaves the folder (by `..`
/// or by a symbolic link) only when `access` allows it.
pub(crate) fn side_car_path(gltf: &Path, uri: &str, access: FileAccess) -> Result<PathBuf, String> {
    if let Some(scheme) = uri_scheme(uri) {
        return Err(format!(
            "names '{uri}', a {scheme}: URI; only data: URIs and paths relative to the glTF file are read"
        ));
    }
    let decoded = percent_decode(uri);
    let relative = Path::new(&decoded);
    if relative.is_absolute() || decoded.starts_with(['/', '\\']) || relative.has_root() {
        return Err(format!(
            "names '{uri}', an absolute path; only data: URIs and paths relative to the glTF file are read"
        ));
    }
    let folder = match gltf.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let side = folder.join(relative);
    if access.allow_outside_folder {
        return Ok(side);
    }
    let outside = || {
        format!(
            "names '{uri}', which is outside the glTF file's folder; such files are read only when asked (--allow-outside-folder)"
        )
    };
    // By its words: `..` above the folder.
    let mut depth = 0usize;
    for component in relative.components() {
        match component {
            Component::ParentDir => depth = depth.checked_sub(1).ok_or_else(outside)?,
            Component::Normal(_) => depth += 1,
            _ => {}
        }
    }
    // By where it leads: a symbolic link out of the folder.
    if let (Ok(folder), Ok(target)) = (folder.canonicalize(), side.canonicalize())
        && !target.starts_with(&folder)
    {
        return Err(outside());
    }
    Ok(side)
}

/// The scheme of `uri` (`file`, `https`), if it has one: letters, digits, `+`, `-` and `.`
/// before a colon, starting with a letter.
fn uri_scheme(uri: &str) -> Option<&str> {
    let (scheme, _) = uri.split_once(':')?;
    let mut chars = scheme.chars();
    (chars.next()?.is_ascii_alphabetic()
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.')))
    .then_some(scheme)
}

/// `%20` and the like in a relative URI, decoded.
pub(crate) fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let Ok(v) = u8::from_str_radix(&uri[i + 1..i + 3], 16)
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_car_paths_stay_in_the_folder() {
        let gltf = Path::new("assets/fox.gltf");
        let strict = FileAccess::default();
        let open = FileAccess {
            allow_outside_folder: true,
        };
        assert_eq!(
            side_car_path(gltf, "fox%20data.bin", strict).unwrap(),
            Path::new("assets/fox data.bin")
        );
        assert_eq!(
            side_car_path(gltf, "bin/../fox.bin", strict).unwrap(),
            Path::new("assets/bin/../fox.bin")
        );
        for uri in ["../secret.bin", "bin/../../secret.bin", "%2E%2E/secret.bin"] {
            let err = side_car_path(gltf, uri, strict).unwrap_err();
            assert!(
                err.contains("outside the glTF file's folder"),
                "{uri}: {err}"
            );
            assert!(side_car_path(gltf, uri, open).is_ok(), "{uri}");
        }
        for uri in [
            "/dev/zero",
            "%2Fetc/passwd",
            "file:///etc/passwd",
            "https://x/y.bin",
        ] {
            let err = side_car_path(gltf, uri, open).unwrap_err();
            assert!(err.contains(uri), "{err}");
        }
        assert_eq!(uri_scheme("C:/x.bin"), Some("C"));
        assert_eq!(uri_scheme("a b:c"), None);
    }
}
