//! How a trainer comes to be: a new run of a final configuration in a folder that holds none,
//! or a run resumed from its newest checkpoint.

use std::collections::{BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::time::Instant;

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::tensor::Device;

use sinmdm::diffusion::Schedule;

use super::{CLIP_COPY, CONFIG_COPY, LOSS_LOG, Trainer, fresh_parts, load_parts, saved_clip};
use crate::chosen::Choices;
use crate::clip::ClipData;
use crate::config::TrainConfig;
use crate::error::{TrainError, io};
use crate::model::QnaUnet;
use crate::run::checkpoint::{self, CheckpointState};
use crate::run::folder::clip_copy;
use crate::run::loss_log::LossLog;
use crate::run::recovery::RecoveryRecord;
use crate::run::weight_average::WeightAverage;

/// The schedule of a configuration.
fn schedule(config: &TrainConfig) -> Schedule {
    Schedule::cosine(config.diffusion.steps).expect("validated configuration has T >= 2")
}

impl Trainer {
    /// A trainer of the run in `run` from its parts, its state and its open loss log;
    /// `last_checkpoint` is the one it resumed from.
    fn assemble(
        run: &Path,
        device: Device,
        (model, average, optimizer): (QnaUnet, Option<WeightAverage>, ModuleOptimizer),
        clip: ClipData,
        state: CheckpointState,
        log: LossLog,
        last_checkpoint: Option<PathBuf>,
    ) -> Trainer {
        Trainer {
            run: run.to_path_buf(),
            device,
            model: Some(model),
            average,
            optimizer,
            schedule: schedule(&state.config),
            clip,
            elapsed_before: state.elapsed_seconds,
            state,
            recent: VecDeque::new(),
            log,
            session_start: Instant::now(),
            last_checkpoint,
            injected_faults: BTreeSet::new(),
            chosen: None,
        }
    }

    /// An error when the folder `run` already holds a training run.
    pub fn check_new_run(run: &Path) -> Result<(), TrainError> {
        if checkpoint::latest(run)?.is_some() || run.join(LOSS_LOG).exists() {
            return Err(TrainError::Checkpoint {
                path: run.to_path_buf(),
                message: "already holds a training run; pass --resume to continue it, or choose another --out".into(),
            });
        }
        Ok(())
    }

    /// Starts a new run of `config` on `clip` in the folder `run` (created if needed; it must
    /// not already hold a run). `config` trains as written: one whose `from_clip` section leaves
    /// settings to the rule that reads the clip is refused ([`TrainError::RuleNotApplied`]).
    pub fn start(
        clip: &Path,
        config: TrainConfig,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        Trainer::check_new_run(run)?;
        Trainer::check_final(&config)?;
        let data = ClipData::load(clip, &config.data)?;
        Trainer::start_chosen(clip, data, config, None, run, device)
    }

    /// An error when `config` still leaves settings to the rule that reads the clip.
    fn check_final(config: &TrainConfig) -> Result<(), TrainError> {
        if config.from_clip.is_off() {
            Ok(())
        } else {
            Err(TrainError::RuleNotApplied)
        }
    }

    /// Starts a new run of the final configuration `config` (the rule that reads the clip, if
    /// any, applied) on the clip `data` was read from (`clip`, read with `config`'s data
    /// section); `chosen` is what the rule chose and why, which the run keeps and prints.
    pub fn start_chosen(
        clip: &Path,
        data: ClipData,
        config: TrainConfig,
        chosen: Option<Choices>,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        Trainer::check_new_run(run)?;
        Trainer::check_final(&config)?;
        // The run saves the numbers it trains: a window that follows the frame rate and a root
        // layout chosen from the clip, resolved.
        let mut config = config.at_fps(data.facts.layout.fps);
        config.data.root_layout = data.facts.root_layout();
        data.check_length(clip, config.model.receptive_field())?;
        std::fs::create_dir_all(run).map_err(io("create the output folder", run))?;
        let yaml = serde_yaml::to_string(&config).expect("config serialises");
        sinmdm::files::write_atomically(&run.join(CONFIG_COPY), yaml.as_bytes())
            .map_err(io("write into the output folder", run))?;
        let clip_bytes = std::fs::read(clip).map_err(io("read the clip", clip))?;
        sinmdm::files::write_atomically(&clip_copy(run, clip), &clip_bytes)
            .map_err(io("write into the output folder", run))?;
        let log = LossLog::create(&run.join(LOSS_LOG))?;
        let features = data.features.nrows();
        let (model, average, optimizer) = fresh_parts(&config, features, &device);
        let state = CheckpointState {
            step: 0,
            learning_rate: config.training.first_rate(),
            loss: f64::NAN,
            recent_loss: f64::NAN,
            elapsed_seconds: 0.0,
            parameters: model.num_params(),
            features,
            clip: data.facts.clone(),
            batch: Some(config.training.batch_shape(data.features.ncols())),
            started: crate::clock::now(),
            recovery: RecoveryRecord::default(),
            config: config.clone(),
        };
        let parts = (model, average, optimizer);
        let mut trainer = Trainer::assemble(run, device, parts, data, state, log, None);
        trainer.chosen = chosen;
        Ok(trainer)
    }

    /// Continues the run in `run` from its newest checkpoint. A `config`, when given, must
    /// describe the same model and training (only `training.steps` and
    /// `training.checkpoint_every` may change); a `clip`, when given, must be the same file.
    pub fn resume(
        run: &Path,
        clip: Option<&Path>,
        config: Option<TrainConfig>,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        let dir = checkpoint::latest(run)?.ok_or_else(|| TrainError::Checkpoint {
            path: run.to_path_buf(),
            message: "holds no checkpoint to resume from".into(),
        })?;
        let mut state = checkpoint::load_state(&dir)?;
        if let Some(asked) = &config {
            let asked = asked.for_resume(&state.config, state.clip.layout.fps);
            if let Some(message) = state.config.resume_difference(&asked) {
                return Err(TrainError::Checkpoint { path: dir, message });
            }
            state.config.training.steps = asked.training.steps;
            state.config.training.checkpoint_every = asked.training.checkpoint_every;
        }
        let clip_path = match clip {
            Some(p) => p.to_path_buf(),
            None => saved_clip(run).ok_or_else(|| TrainError::Checkpoint {
                path: run.to_path_buf(),
                message: format!(
                    "holds no copy of its clip ({CLIP_COPY}.bvh, .glb, .gltf or .fbx); pass the clip"
                ),
            })?,
        };
        let data = ClipData::load(&clip_path, &state.config.data)?;
        data.check_length(&clip_path, state.config.model.receptive_field())?;
        if data.facts.sha256 != state.clip.sha256 {
            return Err(TrainError::Checkpoint {
                path: clip_path,
                message: format!(
                    "is not the clip this run learns ({}, SHA-256 {})",
                    state.clip.name, state.clip.sha256
                ),
            });
        }
        if data.features.nrows() != state.features {
            return Err(TrainError::Checkpoint {
                path: dir,
                message: format!(
                    "the model reads {} feature rows, the clip gives {}",
                    state.features,
                    data.features.nrows()
                ),
            });
        }
        let (model, average, optimizer) = load_parts(&dir, &state, &device)?;
        let log = LossLog::resume(&run.join(LOSS_LOG), state.step)?;
        state.batch = Some(state.config.training.batch_shape(data.features.ncols()));
        let parts = (model, average, optimizer);
        Ok(Trainer::assemble(
            run,
            device,
            parts,
            data,
            state,
            log,
            Some(dir),
        ))
    }
}
