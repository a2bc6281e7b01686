//! A clip's task folder and what is in it:
//!
//! ```text
//! <out>/<name>/
//!   fingerprint    what the model in this folder was made from (see crate::fingerprint)
//!   status.json    the task's state (see crate::status)
//!   run/           the training run: checkpoints, loss.csv (resumed from after a kill), and
//!                  a calm clip's step_ladder/ (kept when a task killed before its first
//!                  checkpoint starts again)
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
    /// fingerprint) loses its run and model first; the fingerprint is then recorded. A run of
    /// the same fingerprint killed before its first checkpoint starts again, but keeps the
    /// entries of its folder named in `kept_by_a_restart` (work a start does before its first
    /// checkpoint and can reuse, such as the trainer's step ladder).
    pub fn prepare(
        &self,
        fingerprint: &str,
        has_checkpoint: impl Fn(&Path) -> bool,
        kept_by_a_restart: &[&str],
    ) -> Result<Plan, LibraryError> {
        if self.is_current(fingerprint) {
            return Ok(Plan::UpToDate);
        }
        std::fs::create_dir_all(&self.dir).map_err(|e| LibraryError::io(&self.dir, e))?;
        let same = self.recorded_fingerprint().as_deref() == Some(fingerprint);
        if same && has_checkpoint(&self.run()) {
            return Ok(Plan::Resume);
        }
        // Stale, or never started, or killed before its first checkpoint: start clean (but for
        // what a restart of the same fingerprint keeps).
        let run = self.run();
        if same && run.is_dir() {
            let entries = std::fs::read_dir(&run).map_err(|e| LibraryError::io(&run, e))?;
            for entry in entries {
                let entry = entry.map_err(|e| LibraryError::io(&run, e))?;
                if kept_by_a_restart.iter().any(|k| entry.file_name() == *k) {
                    continue;
                }
                let path = entry.path();
                let removed = if path.is_dir() {
                    std::fs::remove_dir_all(&path)
                } else {
                    std::fs::remove_file(&path)
                };
                removed.map_err(|e| LibraryError::io(&path, e))?;
            }
        } else if run.exists() {
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
        let kept = ["ladder"];
        assert_eq!(folder.prepare("a", never, &kept).unwrap(), Plan::Fresh);
        std::fs::create_dir_all(folder.run()).unwrap();
        assert_eq!(folder.prepare("a", always, &kept).unwrap(), Plan::Resume);
        // Killed before its first checkpoint: a start again keeps what a restart keeps.
        std::fs::create_dir_all(folder.run().join("ladder/rung")).unwrap();
        std::fs::create_dir_all(folder.run().join("checkpoints")).unwrap();
        std::fs::write(folder.run().join("loss.csv"), b"step,loss").unwrap();
        assert_eq!(folder.prepare("a", never, &kept).unwrap(), Plan::Fresh);
        let left: Vec<_> = std::fs::read_dir(folder.run())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["ladder"]);
        assert!(folder.run().join("ladder/rung").is_dir());
        std::fs::write(folder.model(), b"model").unwrap();
        // A model without a done status (killed before its card) is not finished: resume.
        assert_eq!(folder.prepare("a", always, &kept).unwrap(), Plan::Resume);
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
        assert_eq!(folder.prepare("a", always, &kept).unwrap(), Plan::UpToDate);
        // Another fingerprint: nothing of the run is kept.
        assert_eq!(folder.prepare("b", always, &kept).unwrap(), Plan::Fresh);
        assert!(!folder.model().exists() && !folder.run().exists());
        assert_eq!(folder.recorded_fingerprint().as_deref(), Some("b"));
        std::fs::remove_dir_all(dir).unwrap();
    }
}
