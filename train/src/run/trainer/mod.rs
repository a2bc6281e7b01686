//! The training loop: batches, loss, AdamW with a decaying learning rate, checkpoints, resume.

use std::collections::{BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::tensor::{Device, Tensor, TensorData};

use sinmdm::diffusion::Schedule;

use crate::chosen::Choices;
use crate::clip::ClipData;
use crate::clip::batch::make_batch;
use crate::clip::motion_span;
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::model::QnaUnet;
use crate::run::checkpoint::{self, CheckpointState};
pub use crate::run::folder::{CLIP_COPY, CONFIG_COPY, LOSS_LOG, saved_clip};
use crate::run::loss_log::LossLog;
pub use crate::run::pace::StepReport;
use crate::run::recovery::RecoveryEvent;
use crate::run::step::step_with_fault;
pub use crate::run::step::{StepOutcome, new_optimizer, optimisation_step};
use crate::run::weight_average::WeightAverage;

mod roll_back;
mod start;

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
    /// What the rule that reads the clip chose for a new run started here, and why.
    chosen: Option<Choices>,
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

impl Trainer {
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
    /// network sees at once ([`motion_span::wider_window_hint`]); none when the rule that reads
    /// the clip chose the window.
    pub fn wider_window_hint(&self) -> Option<String> {
        if self.chosen.as_ref().is_some_and(Choices::window_from_clip) {
            return None;
        }
        let fps = self.clip.facts.layout.fps;
        let frames = motion_span::decorrelation_frames(self.clip.features.view(), fps)?;
        motion_span::wider_window_hint(frames, fps, &self.state.config.model)
    }

    /// What the rule that reads the clip chose for this run, and why, when it was started here
    /// with a configuration that asked for the rule.
    pub fn chosen(&self) -> Option<&Choices> {
        self.chosen.as_ref()
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
    /// ([`crate::run::recovery`]); the report's `event` says so. The error is for a run that could
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
