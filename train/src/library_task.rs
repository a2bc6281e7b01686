//! One task of a library array job (`sinmdm-train --manifest LIB.yaml --index N`): train,
//! export and evaluate clip N of the manifest into its own folder (see `sinmdm_library::task`).
//! Idempotent (a current model is left alone), resumable (a run of the same fingerprint
//! continues from its newest checkpoint), atomic (every file is written under a temporary name
//! and renamed, and the folder is the task's alone).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::AtomicBool;

use burn::tensor::Device;
use sinmdm_library::report::{config_text, current_fingerprint};
use sinmdm_library::status::{host, now};
use sinmdm_library::task::Plan;
use sinmdm_library::{ClipEntry, LibraryError, Manifest, State, TaskFolder, TaskStatus};

use crate::run::checkpoint;
use crate::{RunEnd, StepReport, TrainConfig, TrainError, Trainer, export};

/// Why a library task stopped.
#[derive(Debug, thiserror::Error)]
pub enum LibraryTaskError {
    /// The manifest, the index or the folder.
    #[error(transparent)]
    Library(#[from] LibraryError),
    /// Training or export.
    #[error(transparent)]
    Train(#[from] TrainError),
    /// A setting of the manifest that the training configuration refuses.
    #[error("clip '{name}': {message}")]
    Setting {
        /// The clip's task name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// The evaluation by the `sinmdm` command failed.
    #[error("evaluating '{name}': {message}")]
    Evaluation {
        /// The clip's task name.
        name: String,
        /// What went wrong.
        message: String,
    },
}

/// How a task ended.
#[derive(Debug, Clone, PartialEq)]
pub enum TaskEnd {
    /// The folder already held a current model: nothing was trained.
    UpToDate(PathBuf),
    /// The model was trained (from the start or resumed), exported and evaluated.
    Trained {
        /// The model file.
        model: PathBuf,
        /// Whether training continued a run instead of starting one.
        resumed: bool,
    },
    /// The stop flag was raised; the run's checkpoint is kept for the next try.
    Interrupted,
}

/// The training configuration of `entry`: its own file, the manifest's, or the built-in one,
/// with the entry's frame rate, up axis, contacts, animation and window applied.
fn entry_config(manifest: &Manifest, entry: &ClipEntry) -> Result<TrainConfig, LibraryTaskError> {
    let name = Manifest::name(entry).to_string();
    let setting = |message: String| LibraryTaskError::Setting {
        name: name.clone(),
        message,
    };
    let mut config = TrainConfig::parse(&config_text(manifest, entry)?).map_err(setting)?;
    if let Some(fps) = entry.fps {
        config.data.fps = Some(fps);
    }
    if let Some(up) = &entry.up {
        config.data.up = Some(up.parse().map_err(|e| setting(format!("up '{up}': {e}")))?);
    }
    if let Some(contacts) = &entry.contacts {
        config.data.contact_joints = Some(contacts.clone());
    }
    if let Some(animation) = &entry.animation {
        config.data.animation = Some(animation.clone());
    }
    if let Some(window) = entry.window {
        config.model.window = window;
        config.model.window_follows_fps = false;
        config.from_clip.window = false;
    }
    config.validate().map_err(setting)?;
    Ok(config)
}

/// The `sinmdm` command beside the running `sinmdm-train` (they are installed together).
fn sibling_command() -> PathBuf {
    let name = format!("sinmdm{}", std::env::consts::EXE_SUFFIX);
    std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(|dir| dir.join(&name)))
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from(name))
}

/// Runs `sinmdm ARGS` and gives its standard output.
fn sinmdm(name: &str, args: &[&std::ffi::OsStr]) -> Result<String, LibraryTaskError> {
    let failed = |message: String| LibraryTaskError::Evaluation {
        name: name.to_string(),
        message,
    };
    let command = sibling_command();
    let output = Command::new(&command)
        .args(args)
        .output()
        .map_err(|e| failed(format!("cannot run {}: {e}", command.display())))?;
    if !output.status.success() {
        return Err(failed(
            String::from_utf8_lossy(&output.stderr).trim().to_string(),
        ));
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// Moves a file written under a temporary name to its place.
fn put_in_place(from: &Path, to: &Path) -> Result<(), LibraryTaskError> {
    std::fs::rename(from, to).map_err(|e| LibraryError::io(to, e).into())
}

/// Evaluates the model (`sinmdm eval`), writes one sample for the contact sheet and the card.
fn evaluate(
    manifest: &Manifest,
    entry: &ClipEntry,
    folder: &TaskFolder,
    state: &crate::run::checkpoint::CheckpointState,
) -> Result<(), LibraryTaskError> {
    let name = Manifest::name(entry);
    let partial = folder.dir.join("eval.json.partial");
    let samples = manifest.samples.to_string();
    let model = folder.model();
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "eval".as_ref(),
        "-m".as_ref(),
        model.as_os_str(),
        "--clip".as_ref(),
        entry.clip.as_os_str(),
        "--samples".as_ref(),
        samples.as_ref(),
        "--json".as_ref(),
        partial.as_os_str(),
        "--quiet".as_ref(),
    ];
    if let Some(up) = &entry.up {
        args.extend::<[&std::ffi::OsStr; 2]>(["--up".as_ref(), up.as_ref()]);
    }
    if let Some(animation) = &entry.animation {
        args.extend::<[&std::ffi::OsStr; 2]>(["--clip-anim".as_ref(), animation.as_ref()]);
    }
    let table = sinmdm(name, &args)?;
    put_in_place(&partial, &folder.eval())?;
    let sample = folder.sample();
    sinmdm(
        name,
        &[
            "generate".as_ref(),
            "-m".as_ref(),
            model.as_os_str(),
            "--seed".as_ref(),
            "0".as_ref(),
            "-o".as_ref(),
            sample.as_os_str(),
            "--quiet".as_ref(),
        ],
    )?;
    let settings = serde_yaml::to_string(&ClipEntry {
        clip: entry
            .clip
            .file_name()
            .map(PathBuf::from)
            .unwrap_or_default(),
        ..entry.clone()
    })
    .unwrap_or_default();
    let card = format!(
        "# {name}\n\nTrained by `sinmdm-train --manifest` from `{}` (SHA-256 {}), {} frames at {} fps.\n\n\
         ## Settings\n\n```yaml\n{settings}```\n\n## Training\n\n{} steps in {:.1} min; final loss {:.4} \
         (mean of the last 100: {:.4}).\n\n## Evaluation ({} samples)\n\n```text\n{}```\n",
        entry.clip.display(),
        state.clip.sha256,
        state.clip.frames,
        state.clip.layout.fps,
        state.step,
        state.elapsed_seconds / 60.0,
        state.loss,
        state.recent_loss,
        manifest.samples,
        table
    );
    sinmdm::files::write_atomically(&folder.card(), card.as_bytes())
        .map_err(|e| LibraryError::io(folder.card(), e))?;
    Ok(())
}

/// Runs task `index` of the manifest at `manifest_path` (see the module documentation);
/// `on_step` sees every training step. A failure is also recorded in the folder's status.
pub fn run_task(
    manifest_path: &Path,
    index: usize,
    device: Device,
    stop: &AtomicBool,
    on_step: impl FnMut(&StepReport),
) -> Result<TaskEnd, LibraryTaskError> {
    let manifest = Manifest::load(manifest_path)?;
    let entry = manifest.entry(index)?.clone();
    let folder = TaskFolder::new(manifest.folder(&entry));
    let mut status = TaskStatus {
        state: State::Running,
        name: Manifest::name(&entry).to_string(),
        clip: entry.clip.display().to_string(),
        fingerprint: String::new(),
        started: now(),
        finished: None,
        training_seconds: None,
        steps: None,
        error: None,
        host: host(),
        pid: Some(std::process::id()),
    };
    let fingerprint = match current_fingerprint(&manifest, &entry) {
        Ok(f) => f,
        Err(e) => {
            // The clip cannot be read: say so in the folder, where `library status` looks.
            std::fs::create_dir_all(&folder.dir).map_err(|io| LibraryError::io(&folder.dir, io))?;
            status.state = State::Failed;
            status.error = Some(e.to_string());
            status.finished = Some(now());
            status.write(&folder.status())?;
            return Err(e.into());
        }
    };
    status.fingerprint = fingerprint.clone();
    // A task killed during its step ladder keeps the rungs it finished (they are reused only
    // when made from the same clip and configuration).
    let plan = folder.prepare(
        &fingerprint,
        |run| checkpoint::latest(run).ok().flatten().is_some(),
        &[crate::choose::step_ladder::LADDER_FOLDER],
    )?;
    if plan == Plan::UpToDate {
        return Ok(TaskEnd::UpToDate(folder.model()));
    }
    status.write(&folder.status())?;
    let outcome = train_export_evaluate(&manifest, &entry, &folder, plan, device, stop, on_step);
    match &outcome {
        Ok(TaskEnd::Trained { .. }) | Ok(TaskEnd::UpToDate(_)) => {}
        Ok(TaskEnd::Interrupted) => {
            // Stopped by a signal (a scheduler's time limit or preemption): the checkpoint
            // stays for the next try, and the status says so.
            status.state = State::Failed;
            status.error =
                Some("interrupted; submit the task again to resume from its checkpoint".into());
            status.finished = Some(now());
            status.write(&folder.status())?;
            return outcome;
        }
        Err(e) => {
            status.state = State::Failed;
            status.error = Some(e.to_string());
            status.finished = Some(now());
            status.write(&folder.status())?;
            return outcome;
        }
    }
    let state = crate::run::checkpoint::load_state(
        &checkpoint::latest(&folder.run())?.ok_or_else(|| TrainError::Checkpoint {
            path: folder.run(),
            message: "holds no checkpoint after training".into(),
        })?,
    )?;
    status.state = State::Done;
    status.finished = Some(now());
    status.training_seconds = Some(state.elapsed_seconds);
    status.steps = Some(state.step);
    status.write(&folder.status())?;
    outcome
}

fn train_export_evaluate(
    manifest: &Manifest,
    entry: &ClipEntry,
    folder: &TaskFolder,
    plan: Plan,
    device: Device,
    stop: &AtomicBool,
    on_step: impl FnMut(&StepReport),
) -> Result<TaskEnd, LibraryTaskError> {
    let config = entry_config(manifest, entry)?;
    let run = folder.run();
    let resumed = plan == Plan::Resume;
    let mut trainer = if resumed {
        Trainer::resume(&run, Some(&entry.clip), None, device)?
    } else {
        let ladder = crate::choose::step_ladder::Ladder::default();
        let steps = crate::choose::StepsFrom::Rule(&ladder);
        let started =
            crate::choose::start_run(&entry.clip, config, &run, device, steps, stop, &mut |_| {})?;
        match started {
            Some(trainer) => trainer,
            None => return Ok(TaskEnd::Interrupted),
        }
    };
    let dir = match trainer.run(stop, on_step)? {
        RunEnd::Finished(dir) => dir,
        RunEnd::Interrupted(_) => return Ok(TaskEnd::Interrupted),
    };
    crate::run::loss_plot::write(trainer.loss_log(), &run.join("loss.png"))?;
    let partial = folder.dir.join("model.onnx.partial");
    export::export_checkpoint(&dir, &partial)?;
    put_in_place(&partial, &folder.model())?;
    evaluate(manifest, entry, folder, trainer.state())?;
    Ok(TaskEnd::Trained {
        model: folder.model(),
        resumed,
    })
}
