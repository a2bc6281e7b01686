//! The loss log: `loss.csv` in the run folder, one row per step, kept in step with checkpoints.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{TrainError, io};

/// Header of `loss.csv`.
pub const HEADER: &str = "step,loss,learning_rate,seconds";

/// Rows waiting to be appended to `loss.csv`.
#[derive(Debug)]
pub struct LossLog {
    path: PathBuf,
    pending: String,
}

impl LossLog {
    /// Starts a new log at `path` (header only).
    pub fn create(path: &Path) -> Result<LossLog, TrainError> {
        sinmdm::files::write_atomically(path, format!("{HEADER}\n").as_bytes())
            .map_err(io("write the loss log", path))?;
        Ok(LossLog {
            path: path.to_path_buf(),
            pending: String::new(),
        })
    }

    /// Reopens the log of a resumed run, dropping rows after `step` (written after the
    /// checkpoint the run resumes from).
    pub fn resume(path: &Path, step: u64) -> Result<LossLog, TrainError> {
        let kept: Vec<(u64, String)> = match std::fs::read_to_string(path) {
            Ok(text) => text
                .lines()
                .skip(1)
                .filter_map(|l| Some((l.split(',').next()?.parse().ok()?, l.to_string())))
                .filter(|(s, _)| *s <= step)
                .collect(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => return Err(io("read the loss log", path)(e)),
        };
        let mut text = format!("{HEADER}\n");
        for (_, line) in kept {
            text.push_str(&line);
            text.push('\n');
        }
        sinmdm::files::write_atomically(path, text.as_bytes())
            .map_err(io("write the loss log", path))?;
        Ok(LossLog {
            path: path.to_path_buf(),
            pending: String::new(),
        })
    }

    /// Queues one row.
    pub fn push(&mut self, step: u64, loss: f64, learning_rate: f64, seconds: f64) {
        self.pending.push_str(&format!(
            "{step},{loss:.6e},{learning_rate:.6e},{seconds:.3}\n"
        ));
    }

    /// Appends the queued rows to the file.
    pub fn flush(&mut self) -> Result<(), TrainError> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let mut file = std::fs::OpenOptions::new()
            .append(true)
            .open(&self.path)
            .map_err(io("append to the loss log", &self.path))?;
        file.write_all(self.pending.as_bytes())
            .and_then(|_| file.sync_data())
            .map_err(io("append to the loss log", &self.path))?;
        self.pending.clear();
        Ok(())
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Reads `(step, loss)` pairs from a loss log.
pub fn read(path: &Path) -> Result<Vec<(u64, f64)>, TrainError> {
    let text = std::fs::read_to_string(path).map_err(io("read the loss log", path))?;
    Ok(text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut parts = l.split(',');
            Some((parts.next()?.parse().ok()?, parts.next()?.parse().ok()?))
        })
        .collect())
}
