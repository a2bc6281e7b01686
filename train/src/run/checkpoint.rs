//! Checkpoints: one folder per saved step (weights, optimiser state, `state.json`), made under a
//! temporary name and renamed into place, plus a `latest` file naming the newest one.

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use serde::{Deserialize, Serialize};

use crate::clip::ClipFacts;
use crate::config::{BatchShape, TrainConfig};
use crate::error::{TrainError, io};
use crate::model::QnaUnet;
use crate::run::recovery::RecoveryRecord;

/// Checkpoints kept on disk (older ones are removed after a new one is complete).
pub const KEPT_CHECKPOINTS: usize = 2;
/// Folder of the checkpoints inside a run folder.
pub const CHECKPOINT_DIR: &str = "checkpoints";
/// File in the run folder naming the newest complete checkpoint.
pub const LATEST_FILE: &str = "latest";
/// Model weights inside a checkpoint (burnpack).
pub const MODEL_FILE: &str = "model.bpk";
/// The weight average inside a checkpoint (burnpack), when the run keeps one; it is what the
/// export writes.
pub const AVERAGE_FILE: &str = "average.bpk";
/// Optimiser state inside a checkpoint (burnpack).
pub const OPTIMIZER_FILE: &str = "optimizer.bpk";
/// Everything else inside a checkpoint.
pub const STATE_FILE: &str = "state.json";

/// The non-tensor part of a checkpoint: enough to resume, and to export a model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckpointState {
    /// Optimiser steps completed.
    pub step: u64,
    /// Learning rate of the next step.
    pub learning_rate: f64,
    /// Loss of the last step.
    pub loss: f64,
    /// Mean loss over the last (up to) 100 steps.
    pub recent_loss: f64,
    /// Seconds spent training so far, over all sessions of the run.
    pub elapsed_seconds: f64,
    /// Number of parameters.
    pub parameters: usize,
    /// Feature rows F the model reads and writes.
    pub features: usize,
    /// The run's configuration.
    pub config: TrainConfig,
    /// The clip the model learns.
    pub clip: ClipFacts,
    /// The batch every step has: the configuration's rule
    /// ([`crate::config::TrainingConfig::batch_shape`]) resolved for this clip, recorded so that
    /// a reader of the run need not repeat the rule. Absent in runs saved before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub batch: Option<BatchShape>,
    /// When the run started (UTC, RFC 3339).
    pub started: String,
    /// What the trainer did about non-finite steps (clean in runs saved before it was kept).
    #[serde(default)]
    pub recovery: RecoveryRecord,
}

fn record(path: &Path) -> impl FnOnce(burn::store::RecordError) -> TrainError + '_ {
    move |e| TrainError::Checkpoint {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Saves a complete checkpoint of `state.step` (with the averaged weights when the run keeps
/// them) and points `latest` at it; returns its folder.
pub fn save(
    run: &Path,
    model: &QnaUnet,
    average: Option<&QnaUnet>,
    optimizer: &ModuleOptimizer,
    state: &CheckpointState,
) -> Result<PathBuf, TrainError> {
    let dir = run.join(CHECKPOINT_DIR);
    std::fs::create_dir_all(&dir).map_err(io("create the checkpoint folder", &dir))?;
    let name = format!("step-{:08}", state.step);
    let partial = dir.join(format!(".{name}.partial"));
    let done = dir.join(&name);
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(io("clear", &partial))?;
    }
    std::fs::create_dir(&partial).map_err(io("create", &partial))?;
    model
        .clone()
        .save_file(partial.join(MODEL_FILE))
        .map_err(record(&partial))?;
    if let Some(average) = average {
        average
            .clone()
            .save_file(partial.join(AVERAGE_FILE))
            .map_err(record(&partial))?;
    }
    optimizer
        .save(partial.join(OPTIMIZER_FILE))
        .map_err(record(&partial))?;
    let json = serde_json::to_vec_pretty(state).expect("checkpoint state serialises");
    sinmdm::files::write_atomically(&partial.join(STATE_FILE), &json)
        .map_err(io("write", &partial))?;
    if done.exists() {
        std::fs::remove_dir_all(&done).map_err(io("replace", &done))?;
    }
    std::fs::rename(&partial, &done).map_err(io("complete", &done))?;
    let latest = run.join(LATEST_FILE);
    sinmdm::files::write_atomically(&latest, format!("{CHECKPOINT_DIR}/{name}\n").as_bytes())
        .map_err(io("write", &latest))?;
    prune(&dir, &name);
    Ok(done)
}

/// Removes all but the newest [`KEPT_CHECKPOINTS`] complete checkpoints (never `keep`).
fn prune(dir: &Path, keep: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut steps: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("step-"))
        .collect();
    steps.sort();
    let excess = steps.len().saturating_sub(KEPT_CHECKPOINTS);
    for name in steps.into_iter().take(excess) {
        if name != keep {
            let _ = std::fs::remove_dir_all(dir.join(name));
        }
    }
}

/// The newest complete checkpoint of a run folder, if any.
pub fn latest(run: &Path) -> Result<Option<PathBuf>, TrainError> {
    let file = run.join(LATEST_FILE);
    match std::fs::read_to_string(&file) {
        Ok(text) => {
            let dir = run.join(text.trim());
            if dir.join(STATE_FILE).is_file() {
                Ok(Some(dir))
            } else {
                Err(TrainError::Checkpoint {
                    path: file,
                    message: format!(
                        "names '{}', which is not a complete checkpoint",
                        text.trim()
                    ),
                })
            }
        }
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
            ) =>
        {
            Ok(None)
        }
        Err(source) => Err(TrainError::Io {
            what: "read",
            path: file,
            reason: source,
        }),
    }
}

/// Resolves a checkpoint given as a run folder (its latest) or as a checkpoint folder.
pub fn resolve(path: &Path) -> Result<PathBuf, TrainError> {
    if path.join(STATE_FILE).is_file() {
        return Ok(path.to_path_buf());
    }
    match latest(path)? {
        Some(dir) => Ok(dir),
        None => Err(TrainError::Checkpoint {
            path: path.to_path_buf(),
            message: "is neither a checkpoint folder (with state.json) nor a run folder with a checkpoint".into(),
        }),
    }
}

/// Reads a checkpoint's `state.json`.
pub fn load_state(dir: &Path) -> Result<CheckpointState, TrainError> {
    let file = dir.join(STATE_FILE);
    let text = std::fs::read(&file).map_err(io("read", &file))?;
    serde_json::from_slice(&text).map_err(|e| TrainError::Checkpoint {
        path: file,
        message: format!("not a readable checkpoint state: {e}"),
    })
}

/// Loads a checkpoint's weights into `model` (which must have the checkpoint's shape).
pub fn load_model(dir: &Path, model: QnaUnet) -> Result<QnaUnet, TrainError> {
    load_weights(&dir.join(MODEL_FILE), model)
}

/// Loads a checkpoint's averaged weights into `model`, or `None` when it keeps no average.
pub fn load_average(dir: &Path, model: QnaUnet) -> Result<Option<QnaUnet>, TrainError> {
    let file = dir.join(AVERAGE_FILE);
    if !file.is_file() {
        return Ok(None);
    }
    load_weights(&file, model).map(Some)
}

/// The weights the export writes: the average when the checkpoint keeps one, else the trained
/// weights.
pub fn load_exported(dir: &Path, model: QnaUnet) -> Result<QnaUnet, TrainError> {
    match load_average(dir, model.clone())? {
        Some(average) => Ok(average),
        None => load_model(dir, model),
    }
}

fn load_weights(file: &Path, model: QnaUnet) -> Result<QnaUnet, TrainError> {
    let file = file.to_path_buf();
    model.try_load_file(&file).map_err(|e| {
        let text = e.to_string();
        let mismatches: Vec<&str> = text
            .split('"')
            .filter(|part| part.contains("shape mismatch"))
            .collect();
        let message = match mismatches.as_slice() {
            [] => text,
            [first, rest @ ..] => format!(
                "the weights do not fit this model: {first}{}",
                if rest.is_empty() {
                    String::new()
                } else {
                    format!(" (and {} more)", rest.len())
                }
            ),
        };
        TrainError::Checkpoint {
            path: file.clone(),
            message,
        }
    })
}

/// Loads a checkpoint's optimiser state.
pub fn load_optimizer(
    dir: &Path,
    optimizer: ModuleOptimizer,
) -> Result<ModuleOptimizer, TrainError> {
    let file = dir.join(OPTIMIZER_FILE);
    optimizer.load(&file).map_err(record(&file))
}
