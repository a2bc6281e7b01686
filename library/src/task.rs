//! A clip's task folder and what is in it:
//!
//! ```text
//! <out>/<name>/
//!   fingerprint    what the model in this folder was made from (see crate::fingerprint)
//!   status.json    the task's state (see crate::status)
//!   run/           the training run: checkpoints, loss.csv (resumed from after a kill)
//!   model.onnx     the model, written under a temporary name and renamed when whole
//!   eval.json      the model's evaluation (`sinmdm eval --json`)
//!   card.md        the model's card: clip, settings, training, evaluation table
//!   sample.bvh     one sample, for the library's contact sheet
//! ```

use std::path::{Path, PathBuf};

use crate::error::LibraryError;

/// The folder of one clip's task.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskFolder {
    /// The folder.
    pub dir: PathBuf,
}

/// What a task must do, given its folder and the fingerprint it works for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plan {
    /// The model is there and current: nothing to do.
    UpToDate,
    /// A run of this fingerprint has checkpoints: continue it.
    Resume,
    /// Train from the start (nothing there, or what is there is stale and was cleared).
    Fresh,
}

impl TaskFolder {
    /// The folder `dir` (not created yet).
    pub fn new(dir: impl Into<PathBuf>) -> TaskFolder {
        TaskFolder { dir: dir.into() }
    }

    /// The training run's folder.
    pub fn run(&self) -> PathBuf {
        self.dir.join("run")
    }
    /// The model file.
    pub fn model(&self) -> PathBuf {
        self.dir.join("model.onnx")
    }
    /// The evaluation JSON.
    pub fn eval(&self) -> PathBuf {
        self.dir.join("eval.json")
    }
    /// The model's card.
    pub fn card(&self) -> PathBuf {
        self.dir.join("card.md")
    }
    /// One sample of the model, for the contact sheet.
    pub fn sample(&self) -> PathBuf {
        self.dir.join("sample.bvh")
    }
    /// The status file.
    pub fn status(&self) -> PathBuf {
        self.dir.join("status.json")
    }
    /// The fingerprint file.
    pub fn fingerprint_file(&self) -> PathBuf {
        self.dir.join("fingerprint")
    }

    /// The fingerprint recorded in the folder, if any.
    pub fn recorded_fingerprint(&self) -> Option<String> {
        std::fs::read_to_string(self.fingerprint_file())
            .ok()
            .map(|s| s.trim().to_string())
    }

    /// Whether the folder holds a finished model of `fingerprint`: the model, and a status
    /// that says done for that fingerprint (written last, after the evaluation and the card, so
    /// a task killed between the model and its card is not taken for finished).
    pub fn is_current(&self, fingerprint: &str) -> bool {
        let done = matches!(
            crate::status::TaskStatus::read(&self.status()),
            Ok(Some(s)) if s.state == crate::status::State::Done && s.fingerprint == fingerprint
        );
        done && self.model().is_file()
            && self.recorded_fingerprint().as_deref() == Some(fingerprint)
    }

    /// Decides what the task does, and makes the folder ready for it: a stale folder (another
    /// fingerprint) loses its run and model first; the fingerprint is then recorded.
    pub fn prepare(
        &self,
        fingerprint: &str,
        has_checkpoint: impl Fn(&Path) -> bool,
    ) -> Result<Plan, LibraryError> {
        if self.is_current(fingerprint) {
            return Ok(Plan::UpToDate);
        }
        std::fs::create_dir_all(&self.dir).map_err(|e| LibraryError::io(&self.dir, e))?;
        let same = self.recorded_fingerprint().as_deref() == Some(fingerprint);
        if same && has_checkpoint(&self.run()) {
            return Ok(Plan::Resume);
        }
        // Stale, or never started, or killed before its first checkpoint: start clean.
        let run = self.run();
        if run.exists() {
            std::fs::remove_dir_all(&run).map_err(|e| LibraryError::io(&run, e))?;
        }
        for file in [self.model(), self.eval(), self.card(), self.sample()] {
            match std::fs::remove_file(&file) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(LibraryError::io(&file, e)),
            }
        }
        sinmdm::files::write_atomically(&self.fingerprint_file(), fingerprint.as_bytes())
            .map_err(|e| LibraryError::io(self.fingerprint_file(), e))?;
        Ok(Plan::Fresh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_current_model_is_kept_a_stale_one_cleared_a_checkpointed_run_resumed() {
        let dir = std::env::temp_dir().join(format!("sinmdm-task-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let folder = TaskFolder::new(&dir);
        let never = |_: &Path| false;
        let always = |_: &Path| true;
        assert_eq!(folder.prepare("a", never).unwrap(), Plan::Fresh);
        std::fs::create_dir_all(folder.run()).unwrap();
        assert_eq!(folder.prepare("a", always).unwrap(), Plan::Resume);
        std::fs::write(folder.model(), b"model").unwrap();
        // A model without a done status (killed before its card) is not finished: resume.
        assert_eq!(folder.prepare("a", always).unwrap(), Plan::Resume);
        let status = crate::status::TaskStatus {
            state: crate::status::State::Done,
            name: "x".into(),
            clip: "x.bvh".into(),
            fingerprint: "a".into(),
            started: 0,
            finished: Some(1),
            training_seconds: None,
            steps: None,
            error: None,
            host: None,
            pid: None,
        };
        status.write(&folder.status()).unwrap();
        assert_eq!(folder.prepare("a", always).unwrap(), Plan::UpToDate);
        assert_eq!(folder.prepare("b", always).unwrap(), Plan::Fresh);
        assert!(!folder.model().exists() && !folder.run().exists());
        assert_eq!(folder.recorded_fingerprint().as_deref(), Some("b"));
        std::fs::remove_dir_all(dir).unwrap();
    }
}
