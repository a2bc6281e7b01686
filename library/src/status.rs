//! A task's status file (`status.json` in its folder), written atomically at each change, so
//! `sinmdm library status` always reads a whole one.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::LibraryError;

/// Where a task is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    /// Training, exporting or evaluating now (or killed while it was: see `host` and `pid`).
    Running,
    /// The model, its card and its evaluation are in the folder.
    Done,
    /// The task stopped on an error (in `error`).
    Failed,
}

/// What a task last said about itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskStatus {
    /// Where it is.
    pub state: State,
    /// The clip's task name.
    pub name: String,
    /// The clip file.
    pub clip: String,
    /// The fingerprint the task works for.
    pub fingerprint: String,
    /// Unix time the task (last) started.
    pub started: u64,
    /// Unix time it ended, if it has.
    #[serde(default)]
    pub finished: Option<u64>,
    /// Seconds of training the model took in all (over every resume), once done.
    #[serde(default)]
    pub training_seconds: Option<f64>,
    /// Training steps, once done.
    #[serde(default)]
    pub steps: Option<u64>,
    /// Why it failed.
    #[serde(default)]
    pub error: Option<String>,
    /// The machine that ran it.
    #[serde(default)]
    pub host: Option<String>,
    /// Its process.
    #[serde(default)]
    pub pid: Option<u32>,
}

/// Seconds since the Unix epoch.
pub fn now() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// This machine's name, if it can be read.
pub fn host() -> Option<String> {
    std::env::var("HOSTNAME")
        .ok()
        .or_else(|| std::fs::read_to_string("/etc/hostname").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
}

impl TaskStatus {
    /// Reads a status file; `None` when there is none.
    pub fn read(path: &Path) -> Result<Option<TaskStatus>, LibraryError> {
        match std::fs::read_to_string(path) {
            Ok(text) => serde_json::from_str(&text)
                .map(Some)
                .map_err(|e| LibraryError::Status {
                    path: path.to_path_buf(),
                    message: e.to_string(),
                }),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(LibraryError::io(path, e)),
        }
    }

    /// Writes the status file whole (temporary file, then rename).
    pub fn write(&self, path: &Path) -> Result<(), LibraryError> {
        let text = serde_json::to_string_pretty(self).expect("a status serialises");
        sinmdm::files::write_atomically(path, text.as_bytes())
            .map_err(|e| LibraryError::io(path, e))
    }
}
