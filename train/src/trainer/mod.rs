//! The training loop: batches, loss, AdamW with a decaying learning rate, checkpoints, resume.

use std::collections::{BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::tensor::{Device, Tensor, TensorData};

use sinmdm::diffusion::Schedule;

use crate::checkpoint::{self, CheckpointState};
use crate::clip_data::ClipData;
use crate::clip_rule::RuleChoice;
use crate::config::TrainConfig;
use crate::data::make_batch;
use crate::error::{TrainError, io};
use crate::loss_log::LossLog;
use crate::model::QnaUnet;
pub use crate::pace::StepReport;
use crate::recovery::{NonFinite, RecoveryEvent, RecoveryRecord};
use crate::run_folder::clip_copy;
pub use crate::run_folder::{CLIP_COPY, CONFIG_COPY, LOSS_LOG, saved_clip};
use crate::step::step_with_fault;
pub use crate::step::{StepOutcome, new_optimizer, optimisation_step};
use crate::weight_average::WeightAverage;

/// Steps averaged into `recent_loss`.
const RECENT_STEPS: usize = 100;

/// How a call to [`Trainer::run`] ended.
#[derive(Debug, Clone, PartialEq)]
pub enum RunEnd {
    /// All configured steps are done; the final checkpoint is at the path.
    Finished(PathBuf),
    /// The stop flag was raised; a checkpoint of the last completed step is at the path.
    Interrupted(PathBuf),
}

/// A training run in a run folder.
pub struct Trainer {
    run: PathBuf,
    device: Device,
    model: Option<QnaUnet>,
    average: Option<WeightAverage>,
    optimizer: ModuleOptimizer,
    schedule: Schedule,
    clip: ClipData,
    state: CheckpointState,
    recent: VecDeque<f64>,
    log: LossLog,
    session_start: Instant,
    elapsed_before: f64,
    last_checkpoint: Option<PathBuf>,
    /// Steps (1-based) whose gradients tests turn into NaN, once each.
    injected_faults: BTreeSet<u64>,
    /// What the rule that reads the clip chose for a new run started here.
    rule: Option<RuleChoice>,
}

/// A new network, its weight average and optimiser for `config`, drawn from the run's seed.
fn fresh_parts(
    config: &TrainConfig,
    features: usize,
    device: &Device,
) -> (QnaUnet, Option<WeightAverage>, ModuleOptimizer) {
    device.seed(config.training.seed);
    let model = QnaUnet::new(features, &config.model, device);
    let average = config
        .training
        .ema_decay
        .map(|decay| WeightAverage::new(&model, decay, 0));
    (model, average, new_optimizer(config))
}

/// The network, weight average and optimiser saved in the checkpoint `dir` of a run whose
/// state is `state`.
fn load_parts(
    dir: &Path,
    state: &CheckpointState,
    device: &Device,
) -> Result<(QnaUnet, Option<WeightAverage>, ModuleOptimizer), TrainError> {
    let model = QnaUnet::new(state.features, &state.config.model, device);
    let model = checkpoint::load_model(dir, model)?;
    let average = match state.config.training.ema_decay {
        None => None,
        Some(decay) => {
            let shape = QnaUnet::new(state.features, &state.config.model, &Device::flex());
            let saved =
                checkpoint::load_average(dir, shape)?.ok_or_else(|| TrainError::Checkpoint {
                    path: dir.to_path_buf(),
                    message: format!(
                        "keeps no {} although the run averages its weights",
                        checkpoint::AVERAGE_FILE
                    ),
                })?;
            Some(WeightAverage::new(&saved, decay, state.step))
        }
    };
    let optimizer = checkpoint::load_optimizer(dir, new_optimizer(&state.config))?;
    Ok((model, average, optimizer))
}

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
            rule: None,
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
    /// not already hold a run).
    pub fn start(
        clip: &Path,
        config: TrainConfig,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        Trainer::check_new_run(run)?;
        let data = ClipData::load(clip, &config.data, &config.model)?;
        Trainer::start_loaded(clip, data, config, run, device)
    }

    /// [`Trainer::start`] for a clip already read: `data` is `clip` as [`ClipData::load`] read
    /// it with `config`'s data section.
    pub fn start_loaded(
        clip: &Path,
        data: ClipData,
        config: TrainConfig,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        // (The steps of a calm clip are left to the step ladder, which `step_ladder::start_run`
        // climbs before it starts the run; called directly, a calm clip trains the ladder's most.)
        match crate::clip_rule::apply(&config, &data) {
            Some(choice) => Trainer::start_chosen(clip, data, choice, run, device),
            None => Trainer::begin(clip, data, config, None, run, device),
        }
    }

    /// [`Trainer::start_loaded`] once the rule that reads the clip has chosen: `choice.config`
    /// trains, and `choice` is what the run says the rule chose.
    pub fn start_chosen(
        clip: &Path,
        data: ClipData,
        choice: RuleChoice,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        let config = choice.config.clone();
        Trainer::begin(clip, data, config, Some(choice), run, device)
    }

    /// Starts a new run of `config` (the rule, if any, applied) on the clip `data` was read from.
    fn begin(
        clip: &Path,
        data: ClipData,
        config: TrainConfig,
        rule: Option<RuleChoice>,
        run: &Path,
        device: Device,
    ) -> Result<Trainer, TrainError> {
        Trainer::check_new_run(run)?;
        // The run saves the numbers it trains: what the rule that reads the clip chose, a
        // window that follows the frame rate and a root layout chosen from the clip, resolved.
        let mut config = config.at_fps(data.facts.layout.fps);
        config.data.root_layout = data.facts.root_layout();
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
        trainer.rule = rule;
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
        let data = ClipData::load(&clip_path, &state.config.data, &state.config.model)?;
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

    /// The checkpoint state as of now.
    pub fn state(&self) -> &CheckpointState {
        &self.state
    }

    /// The network being trained.
    pub fn model(&self) -> &QnaUnet {
        self.model.as_ref().expect("model present between steps")
    }

    /// The run folder.
    pub fn run_dir(&self) -> &Path {
        &self.run
    }

    /// A line for the user when the clip's motion stays correlated for much longer than the
    /// network sees at once ([`crate::motion_span::wider_window_hint`]); none when the rule that
    /// reads the clip chose the window.
    pub fn wider_window_hint(&self) -> Option<String> {
        if self.rule.as_ref().is_some_and(|r| r.window_from_clip) {
            return None;
        }
        let fps = self.clip.facts.layout.fps;
        let frames = crate::motion_span::decorrelation_frames(self.clip.features.view(), fps)?;
        crate::motion_span::wider_window_hint(frames, fps, &self.state.config.model)
    }

    /// What the rule that reads the clip chose for this run, a line per setting, when it was
    /// started here with a configuration that asks for the rule ([`crate::clip_rule`]).
    pub fn rule_lines(&self) -> Option<&[String]> {
        self.rule.as_ref().map(|r| r.lines.as_slice())
    }

    /// Whether all configured steps are done.
    pub fn finished(&self) -> bool {
        self.state.step >= self.state.config.training.steps
    }

    fn elapsed(&self) -> f64 {
        self.elapsed_before + self.session_start.elapsed().as_secs_f64()
    }

    /// Runs one optimiser step and returns its report. A step whose loss or gradients are not
    /// finite changes nothing and is skipped, and repeated ones roll the run back
    /// ([`crate::recovery`]); the report's `event` says so. The error is for a run that could
    /// not be recovered, or a checkpoint that could not be read or written.
    pub fn step(&mut self) -> Result<StepReport, TrainError> {
        let config = &self.state.config;
        let step = self.state.step;
        // The flex RNG (dropout) is reseeded every step so a resumed run draws what an
        // uninterrupted one would.
        self.device.seed(sinmdm::diffusion::noise::mix(
            config.training.seed ^ step.wrapping_mul(0x9E37_79B9),
        ));
        let shape = config.training.batch_shape(self.clip.features.ncols());
        let batch = make_batch(
            self.clip.features.view(),
            &self.schedule,
            shape.items,
            (config.training.resample_min, config.training.resample_max),
            shape.window,
            config.training.seed,
            step,
        );
        let shape = [batch.batch, batch.features, batch.frames];
        let noised = Tensor::<3>::from_data(TensorData::new(batch.noised, shape), &self.device);
        let clean = Tensor::<3>::from_data(TensorData::new(batch.clean, shape), &self.device);
        let t: Vec<f32> = batch.timesteps.iter().map(|&t| t as f32).collect();
        let t = Tensor::<1>::from_data(TensorData::new(t, [batch.batch]), &self.device);
        let model = self.model.take().expect("model present between steps");
        let learning_rate = self.state.learning_rate;
        let inject_fault = self.injected_faults.remove(&(step + 1));
        let (model, outcome) = step_with_fault(
            model,
            &mut self.optimizer,
            (noised, t, clean),
            learning_rate,
            inject_fault,
        );
        let value = match outcome {
            StepOutcome::Updated(value) => value,
            StepOutcome::Skipped { loss, cause } => {
                self.model = Some(model);
                return self.skip(loss, cause);
            }
        };
        if let Some(average) = &mut self.average {
            average.update(&model);
        }
        self.model = Some(model);
        self.advance();
        self.state.loss = value;
        self.recent.push_back(value);
        if self.recent.len() > RECENT_STEPS {
            self.recent.pop_front();
        }
        self.state.recent_loss = self.recent.iter().sum::<f64>() / self.recent.len() as f64;
        let seconds = self.elapsed();
        self.log
            .push(self.state.step, value, learning_rate, seconds);
        Ok(self.report(value, learning_rate, None))
    }

    /// Counts the step done and moves the learning rate on (scaled by the roll-backs so far).
    fn advance(&mut self) {
        let training = &self.state.config.training;
        let scale = self.state.recovery.rate_scale;
        self.state.step += 1;
        self.state.learning_rate =
            training.next_rate(self.state.step, self.state.learning_rate / scale) * scale;
    }

    fn report(&self, loss: f64, learning_rate: f64, event: Option<RecoveryEvent>) -> StepReport {
        StepReport {
            step: self.state.step,
            total: self.state.config.training.steps,
            loss,
            recent_loss: self.state.recent_loss,
            learning_rate,
            seconds: self.elapsed(),
            event,
        }
    }

    /// A step whose update was skipped: recorded, then either passed over (its batch dropped,
    /// no row in the loss log) or, when skips repeat, the run rolled back.
    fn skip(&mut self, loss: f64, cause: NonFinite) -> Result<StepReport, TrainError> {
        let learning_rate = self.state.learning_rate;
        let at = self.state.step + 1;
        if self.state.recovery.skip(at, cause) {
            let event = self.roll_back(at)?;
            return Ok(self.report(loss, learning_rate, Some(event)));
        }
        self.advance();
        let event = RecoveryEvent::Skipped { step: at, cause };
        Ok(self.report(loss, learning_rate, Some(event)))
    }

    /// Goes back to the last good checkpoint (or the start, before the first), lowers the
    /// learning rate, and saves that point with the record at once, so a resume starts from it.
    fn roll_back(&mut self, at: u64) -> Result<RecoveryEvent, TrainError> {
        let checkpoint = match &self.last_checkpoint {
            Some(dir) => Some(dir.clone()),
            None => checkpoint::latest(&self.run)?,
        };
        let target = match &checkpoint {
            Some(dir) => checkpoint::load_state(dir)?,
            None => CheckpointState {
                step: 0,
                learning_rate: self.state.config.training.first_rate(),
                loss: f64::NAN,
                recent_loss: f64::NAN,
                recovery: RecoveryRecord::default(),
                ..self.state.clone()
            },
        };
        let mut record = self.state.recovery.clone();
        if !record.may_roll_back_to(target.step) {
            return Err(TrainError::Unrecoverable {
                step: at,
                to: target.step,
                tried: record.summary(),
                last_checkpoint: checkpoint,
            });
        }
        let (model, average, optimizer) = match &checkpoint {
            Some(dir) => load_parts(dir, &target, &self.device)?,
            None => fresh_parts(&target.config, target.features, &self.device),
        };
        let event = record.roll_back(at, target.step);
        let elapsed = self.elapsed();
        self.state = CheckpointState {
            learning_rate: target.learning_rate / target.recovery.rate_scale * record.rate_scale,
            recovery: record,
            elapsed_seconds: elapsed,
            // The run's configuration as it is now: a resume may have raised its step count
            // since the checkpoint was written.
            config: self.state.config.clone(),
            ..target
        };
        self.model = Some(model);
        self.average = average;
        self.optimizer = optimizer;
        self.log = LossLog::resume(&self.run.join(LOSS_LOG), self.state.step)?;
        self.recent.clear();
        self.elapsed_before = elapsed;
        self.session_start = Instant::now();
        self.save()?;
        Ok(event)
    }

    /// Makes the gradients of the given steps (1-based, as in the loss log) NaN, once each: a
    /// test's stand-in for a numerical failure, met by the same checks.
    #[doc(hidden)]
    pub fn inject_non_finite_gradients(&mut self, steps: impl IntoIterator<Item = u64>) {
        self.injected_faults.extend(steps);
    }

    /// Writes a checkpoint of the current step and flushes the loss log.
    pub fn save(&mut self) -> Result<PathBuf, TrainError> {
        self.log.flush()?;
        self.state.elapsed_seconds = self.elapsed();
        let average = self.averaged_model();
        let dir = checkpoint::save(
            &self.run,
            self.model(),
            average.as_ref(),
            &self.optimizer,
            &self.state,
        )?;
        self.last_checkpoint = Some(dir.clone());
        Ok(dir)
    }

    /// Steps until the configured count, saving every `checkpoint_every` steps (except on a
    /// step that went non-finite) and at the end.
    /// When `stop` becomes true, saves the last completed step and returns.
    pub fn run(
        &mut self,
        stop: &AtomicBool,
        mut on_step: impl FnMut(&StepReport),
    ) -> Result<RunEnd, TrainError> {
        let every = self.state.config.training.checkpoint_every;
        while !self.finished() {
            if stop.load(Ordering::SeqCst) {
                return Ok(RunEnd::Interrupted(self.save()?));
            }
            let report = self.step()?;
            on_step(&report);
            // No checkpoint on a step that went non-finite: a roll-back has saved its own, and
            // one saved amid skips would become the target a repeat of them rolls back to.
            if report.step % every == 0 && !self.finished() && report.event.is_none() {
                self.save()?;
            }
        }
        Ok(RunEnd::Finished(self.save()?))
    }

    /// The network without autodiff or dropout, for evaluation.
    pub fn inference_model(&self) -> QnaUnet {
        self.model().valid()
    }

    /// The network with the averaged weights (without autodiff or dropout), when the run keeps
    /// an average.
    pub fn averaged_model(&self) -> Option<QnaUnet> {
        self.average
            .as_ref()
            .map(|average| average.apply(self.inference_model()))
    }

    /// The loss log's path.
    pub fn loss_log(&self) -> &Path {
        self.log.path()
    }
}

/// Seconds one optimiser step of `config` on `clip` takes on `device`: the mean of `steps`
/// timed steps (after two untimed ones) of a throw-away run in a temporary folder. The mean,
/// not the median: each step stretches the clip by its own random factor, and a budget is
/// spent on the sum of the steps, slow ones included. This is what a time budget
/// (`sinmdm-train --minutes`) turns into a step count.
pub fn seconds_per_step(
    clip: &Path,
    config: &TrainConfig,
    device: Device,
    steps: u64,
) -> Result<f64, TrainError> {
    let folder = std::env::temp_dir().join(format!("sinmdm-timing-probe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    let mut probe_config = config.clone();
    probe_config.training.steps = steps + 2;
    probe_config.training.warmup_steps = 0;
    probe_config.from_clip.steps = false;
    let measured = (|| {
        let mut trainer = Trainer::start(clip, probe_config, &folder, device)?;
        let mut times = Vec::new();
        for i in 0..steps + 2 {
            let begun = Instant::now();
            trainer.step()?;
            if i >= 2 {
                times.push(begun.elapsed().as_secs_f64());
            }
        }
        Ok(times.iter().sum::<f64>() / times.len().max(1) as f64)
    })();
    let _ = std::fs::remove_dir_all(&folder);
    measured
}
