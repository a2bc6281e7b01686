//! What can go wrong reading a library.

use std::path::PathBuf;

use thiserror::Error;

/// A manifest, task folder or report that could not be read or written.
#[derive(Debug, Error)]
pub enum LibraryError {
    /// A file could not be read or written. The reason is said in the message and not chained
    /// as a source, so a printer of causes (`{:#}`) says it once.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said, or the limit the file broke.
        reason: std::io::Error,
    },
    /// The manifest is not valid YAML of the manifest's shape.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: PathBuf,
        /// What is wrong, with its place in the file.
        message: String,
    },
    /// A task index that is not in the manifest, or none at all.
    #[error("{0}")]
    Index(String),
    /// A status file that is not a task's status.
    #[error("{path}: not a task status: {message}")]
    Status {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        message: String,
    },
}

impl LibraryError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> LibraryError {
        LibraryError::Io {
            path: path.into(),
            reason: source,
        }
    }
}
