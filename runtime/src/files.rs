//! File output that never leaves a half-written file behind, and file input that never reads
//! more than a named limit or from anything but a regular file.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// The temporary file beside `path` that a file is written to before it takes its name
/// (`.NAME.PID.partial`, in the same folder so the rename is atomic).
pub fn temporary_path(path: &Path) -> std::io::Result<PathBuf> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("'{}' is not a file path", path.display()),
        )
    })?;
    Ok(dir.join(format!(
        ".{}.{}.partial",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Writes `bytes` to a temporary file beside `path`, flushes it to disk and renames it over
/// `path`. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let temp = temporary_path(path)?;
    let result = (|| {
        let mut file = std::fs::File::create(&temp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// The most bytes a reader takes from one kind of file, with the limit's name for messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileLimit {
    /// The most bytes read.
    pub bytes: u64,
    /// The constant that sets it (`MAX_BVH_BYTES`), so a message points at the rule.
    pub name: &'static str,
    /// What kind of file it bounds (`a BVH file`).
    pub what: &'static str,
}

/// The error for a file that is not a regular file, naming what it is.
fn not_regular(kind: std::fs::FileType) -> std::io::Error {
    let what = if kind.is_dir() {
        "a directory"
    } else {
        "a device, FIFO or socket"
    };
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("is {what}, not a regular file"),
    )
}

/// The size of `path` when it is a regular file no larger than `limit`: checked before a byte
/// is read, so a device (`/dev/zero`), a FIFO or a huge file costs nothing.
pub fn regular_file_size(path: &Path, limit: FileLimit) -> std::io::Result<u64> {
    let metadata = std::fs::metadata(path)?;
    if !metadata.is_file() {
        return Err(not_regular(metadata.file_type()));
    }
    check_size(metadata.len(), limit)?;
    Ok(metadata.len())
}

/// `size` bytes against `limit`.
fn check_size(size: u64, limit: FileLimit) -> std::io::Result<()> {
    if size > limit.bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "is {size} bytes, more than the {} {} may have ({})",
                limit.bytes, limit.what, limit.name
            ),
        ));
    }
    Ok(())
}

/// Reads at most `count` bytes from the start of the regular file `path` (all of it when
/// `count` is `None`), refusing anything that is not a regular file or is larger than `limit`.
/// Readers of files from strangers use it so a file cannot make them read a device, block on
/// a FIFO or allocate more than the limit.
pub fn read_regular_file(
    path: &Path,
    limit: FileLimit,
    count: Option<u64>,
) -> std::io::Result<Vec<u8>> {
    // Checked on the path first: opening a FIFO would block until something writes to it.
    regular_file_size(path, limit)?;
    let file = std::fs::File::open(path)?;
    // And again on what was opened, in case the path changed in between.
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(not_regular(metadata.file_type()));
    }
    check_size(metadata.len(), limit)?;
    let wanted = count.unwrap_or(metadata.len()).min(limit.bytes);
    let mut bytes = Vec::with_capacity(wanted.min(metadata.len()) as usize);
    // A file that grows while it is read (or a /proc file that says 0) still stops at the limit.
    let cap = match count {
        Some(count) => count.min(limit.bytes),
        None => limit.bytes.saturating_add(1),
    };
    file.take(cap).read_to_end(&mut bytes)?;
    check_size(bytes.len() as u64, limit)?;
    Ok(bytes)
}

/// The largest text file read (16 MiB): configurations, manifests, steering paths and beat
/// lists are written by hand or by a tool, and stay far below it.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// Reads the regular UTF-8 text file `path` of at most [`MAX_TEXT_BYTES`]; `what` names its
/// kind in the message (`"a training configuration"`).
pub fn read_text_file(path: &Path, what: &'static str) -> std::io::Result<String> {
    let limit = FileLimit {
        bytes: MAX_TEXT_BYTES,
        name: "MAX_TEXT_BYTES",
        what,
    };
    read_regular_text(path, limit)
}

/// Reads the regular UTF-8 text file `path` within `limit` ([`read_regular_file`], then UTF-8
/// checked, naming the first bad byte).
pub fn read_regular_text(path: &Path, limit: FileLimit) -> std::io::Result<String> {
    String::from_utf8(read_regular_file(path, limit, None)?).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("is not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_nothing_behind() {
        let dir = std::env::temp_dir().join(format!("sinmdm-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.txt");
        write_atomically(&target, b"hello").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"hello");
        // A directory where the file should go cannot be replaced: error, no temp file left.
        let blocked = dir.join("blocked");
        std::fs::create_dir_all(blocked.join("inner")).unwrap();
        assert!(write_atomically(&blocked, b"x").is_err());
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
            .collect();
        assert!(leftovers.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reads_regular_files_within_their_limit_only() {
        let dir = std::env::temp_dir().join(format!("sinmdm-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("ten.bin");
        std::fs::write(&file, [7u8; 10]).unwrap();
        let limit = |bytes| FileLimit {
            bytes,
            name: "MAX_TEST_BYTES",
            what: "a test file",
        };
        assert_eq!(read_regular_file(&file, limit(10), None).unwrap().len(), 10);
        assert_eq!(
            read_regular_file(&file, limit(10), Some(4)).unwrap(),
            [7; 4]
        );
        let err = read_regular_file(&file, limit(9), None).unwrap_err();
        assert_eq!(
            err.to_string(),
            "is 10 bytes, more than the 9 a test file may have (MAX_TEST_BYTES)"
        );
        let err = read_regular_file(&dir, limit(10), None).unwrap_err();
        assert!(err.to_string().contains("directory"), "{err}");
        #[cfg(unix)]
        {
            let err = read_regular_file(Path::new("/dev/zero"), limit(10), None).unwrap_err();
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn text_files_are_bounded_and_must_be_utf8() {
        let dir = std::env::temp_dir().join(format!("sinmdm-text-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("good.yaml");
        std::fs::write(&good, "steps: 3\n").unwrap();
        assert_eq!(read_text_file(&good, "a config").unwrap(), "steps: 3\n");
        let latin1 = dir.join("latin1.yaml");
        std::fs::write(&latin1, b"name: caf\xe9\n").unwrap();
        let err = read_text_file(&latin1, "a config").unwrap_err();
        assert_eq!(err.to_string(), "is not UTF-8 text (byte 9)");
        let huge = dir.join("huge.yaml");
        std::fs::File::create(&huge)
            .unwrap()
            .set_len(MAX_TEXT_BYTES + 1)
            .unwrap();
        let err = read_text_file(&huge, "a config").unwrap_err();
        assert!(
            err.to_string()
                .contains("a config may have (MAX_TEXT_BYTES)"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
