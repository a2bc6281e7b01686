//! A file of the fuzzer's bytes for the readers that take a path: one per process, in memory
//! where the system has a memory file system.

use std::path::PathBuf;

/// Writes `data` to this process's scratch file named `name` and returns its path.
pub fn file(name: &str, data: &[u8]) -> PathBuf {
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let path = dir.join(format!("sinmdm-fuzz-{}-{name}", std::process::id()));
    std::fs::write(&path, data).expect("the scratch file can be written");
    path
}
