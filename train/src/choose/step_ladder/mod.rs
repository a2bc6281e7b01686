//! A calm clip's steps, chosen by its own samples: the step ladder.
//!
//! A calm clip (see [`crate::choose::clip_rule`]) is covered within a few hundred steps, and the longer
//! it trains the longer its samples replay it verbatim. How few steps a calm clip can train and
//! still be covered, and how many it can train before it replays, differ from clip to clip in
//! ways one number read before training did not predict on clips it was not chosen on
//! (lab/EXPERIMENTS.md, "The step ladder"). So the trainer measures instead: it trains
//! short runs of [`LADDER_STEPS`] steps (each its own run, warm-up a third; the most-trained
//! first, and the rest only when it covers the clip), samples each as the benchmark does
//! ([`CHECK_SAMPLES`] samples of twice the clip, seed [`CHECK_SEED`], through onnxruntime as a
//! user would), scores the samples against the [`goals`] and trains the main run with the rung
//! that meets them with the widest margin, or, where none meets them all, the one that misses
//! them by least in all ([`choose`]). When no rung covers the clip, the clip
//! is not calm after all and trains as a varied one.
//!
//! The rungs live in the run folder's [`LADDER_FOLDER`], one folder each with its model and its
//! scores (`check.json`); a start that was interrupted keeps the rungs it finished, and a start
//! again reuses a finished rung only when it was made from the same clip bytes, configuration,
//! check and trainer version ([`Ladder::rung_fingerprint`]).

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use burn::tensor::Device;

use sinmdm::motion::encode_for_model;
use sinmdm_formats::{AnimationChoice, FileAccess, ReadOptions, read_clip_with_access};

pub use crate::choose::ladder_settings::{
    CHECK_SAMPLES, CHECK_SEED, FASTER_LEARNING_RATE, FASTER_STEPS, LADDER_STEPS, goals,
};

use crate::choose::clip_rule::{self, RuleChoice};
use crate::chosen::{Chosen, Reason};
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::run::{RunEnd, Trainer};

mod rung_check;

pub use rung_check::{RungCheck, choose};
use rung_check::{read_check, write_check};

/// The folder, inside the run folder, that holds the rungs.
pub const LADDER_FOLDER: &str = "step_ladder";

/// The ladder's settings (the trainer climbs [`Ladder::default`]; tests climb a shorter one).
#[derive(Debug, Clone, PartialEq)]
pub struct Ladder {
    /// The steps of each rung.
    pub steps: Vec<u64>,
    /// The steps of the rungs at [`FASTER_LEARNING_RATE`], climbed only where no rung of
    /// `steps` meets every goal and that rate is above the configuration's.
    pub faster: Vec<u64>,
    /// Samples a rung is scored on.
    pub samples: usize,
    /// Their seed.
    pub seed: u64,
}

impl Default for Ladder {
    fn default() -> Self {
        Ladder {
            steps: LADDER_STEPS.to_vec(),
            faster: FASTER_STEPS.to_vec(),
            samples: CHECK_SAMPLES,
            seed: CHECK_SEED,
        }
    }
}

/// How a climb ended.
#[derive(Debug)]
pub enum Climb {
    /// Every rung was trained and scored, in the ladder's order.
    Done(Vec<RungCheck>),
    /// The stop flag was raised; the rungs finished so far are kept.
    Interrupted,
}

/// The clip a ladder climbs on: its file, and the SHA-256 (hex) of its bytes as
/// [`crate::clip::ClipData`] holds it, which goes into each rung's fingerprint.
#[derive(Debug, Clone, Copy)]
pub struct LadderClip<'a> {
    /// The clip's file.
    pub path: &'a Path,
    /// SHA-256 of the file's bytes, in hex.
    pub sha256: &'a str,
}

impl Ladder {
    /// Trains and scores the rungs of the ladder on `clip` with `config` (its steps and warm-up
    /// replaced by each rung's), in `folder`: the most-trained rung first, and the others, fewest
    /// steps first, only when it covers the clip (a calm clip covers more the longer it trains:
    /// when the most steps do not cover it, fewer will not); then, where none of those meets
    /// every goal and [`FASTER_LEARNING_RATE`] is above the configuration's rate, the
    /// [`faster`](Ladder::faster) rungs, fewest steps first. A rung whose scores
    /// are already there is not trained again. `on_rung` hears each rung's scores as they come;
    /// the rungs come back sorted by their steps, those at the configuration's rate first.
    pub fn climb(
        &self,
        clip: LadderClip<'_>,
        config: &TrainConfig,
        folder: &Path,
        device: &Device,
        stop: &AtomicBool,
        on_rung: &mut dyn FnMut(&RungCheck),
    ) -> Result<Climb, TrainError> {
        let mut order = self.steps.clone();
        order.sort_unstable();
        order.dedup();
        if let Some(most) = order.pop() {
            order.insert(0, most);
        }
        let mut rungs: Vec<RungCheck> = Vec::with_capacity(order.len() + self.faster.len());
        for steps in order {
            if rungs.first().is_some_and(|most| !most.covers()) {
                break;
            }
            let Some(check) = self.rung(clip, config, (steps, None), folder, device, stop)? else {
                return Ok(Climb::Interrupted);
            };
            on_rung(&check);
            rungs.push(check);
        }
        let covered = rungs.first().is_some_and(RungCheck::covers);
        let faster_than_configured = FASTER_LEARNING_RATE > config.training.learning_rate;
        if covered && faster_than_configured && !rungs.iter().any(RungCheck::meets_goals) {
            let mut faster = self.faster.clone();
            faster.sort_unstable();
            faster.dedup();
            for steps in faster {
                let rung = (steps, Some(FASTER_LEARNING_RATE));
                let Some(check) = self.rung(clip, config, rung, folder, device, stop)? else {
                    return Ok(Climb::Interrupted);
                };
                on_rung(&check);
                rungs.push(check);
            }
        }
        rungs.sort_by(|a, b| {
            (a.learning_rate.is_some(), a.steps).cmp(&(b.learning_rate.is_some(), b.steps))
        });
        Ok(Climb::Done(rungs))
    }

    /// The scores of the rung of `steps` at `learning_rate` (the configuration's where `None`):
    /// read from its folder where it finished before, else trained, scored and written there;
    /// `None` when the stop flag was raised.
    fn rung(
        &self,
        clip: LadderClip<'_>,
        config: &TrainConfig,
        (steps, learning_rate): (u64, Option<f64>),
        folder: &Path,
        device: &Device,
        stop: &AtomicBool,
    ) -> Result<Option<RungCheck>, TrainError> {
        let dir = folder.join(rung_folder(steps, learning_rate));
        let rung_config = Self::rung_config(config, steps, learning_rate);
        let made_from = self.rung_fingerprint(clip.sha256, &rung_config);
        if let Some(check) = read_check(&dir, steps, &made_from) {
            return Ok(Some(check));
        }
        let Some(check) = self.train_rung(clip.path, rung_config, &dir, device, stop)? else {
            return Ok(None);
        };
        let check = RungCheck {
            made_from,
            learning_rate,
            ..check
        };
        write_check(&dir, &check)?;
        Ok(Some(check))
    }

    /// The configuration a rung of `steps` trains: `config` with the rung's steps and warm-up,
    /// its `learning_rate` where given, one checkpoint at its end, and no rule (its numbers are
    /// the rule's already).
    pub fn rung_config(
        config: &TrainConfig,
        steps: u64,
        learning_rate: Option<f64>,
    ) -> TrainConfig {
        let mut rung = config.clone();
        rung.from_clip = Default::default();
        if let Some(rate) = learning_rate {
            rung.training.learning_rate = rate;
        }
        rung.training.steps = steps;
        rung.training.warmup_steps = clip_rule::calm_warmup_steps(steps);
        rung.training.checkpoint_every = steps;
        rung
    }

    /// What a rung on the clip whose bytes hash to `clip_sha256` (SHA-256, hex) is made from,
    /// hashed: the trainer's version, the clip, the rung's configuration `rung_config`
    /// ([`Ladder::rung_config`]) and this ladder's check (samples and seed). A finished rung is
    /// reused only when its scores record the same.
    pub fn rung_fingerprint(&self, clip_sha256: &str, rung_config: &TrainConfig) -> String {
        let rung = serde_json::to_string(rung_config).expect("a configuration serialises");
        // The check's version names what a rung's scores hold: version 2 added the backwards
        // floor and the kinematic figures, which a rung scored before does not have; version 3
        // measures the body from the joint that carries it; version 4 leaves a static container
        // out of the body (the clip's height and contacts, the planted samples' scores).
        let check = format!("{} samples, seed {}, check 4", self.samples, self.seed);
        sinmdm_library::fingerprint::sha256_of_parts(&[
            env!("CARGO_PKG_VERSION").as_bytes(),
            clip_sha256.as_bytes(),
            rung.as_bytes(),
            check.as_bytes(),
        ])
    }

    /// Trains one rung, its configuration `rung` ([`Ladder::rung_config`]), into `dir` (anything
    /// a killed rung left there is replaced), exports it and scores its samples; `None` when
    /// stopped.
    fn train_rung(
        &self,
        clip: &Path,
        rung: TrainConfig,
        dir: &Path,
        device: &Device,
        stop: &AtomicBool,
    ) -> Result<Option<RungCheck>, TrainError> {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|source| TrainError::Io {
                what: "clear an unfinished rung of the step ladder",
                path: dir.to_path_buf(),
                reason: source,
            })?;
        }
        let steps = rung.training.steps;
        let started = Instant::now();
        let mut trainer = Trainer::start(clip, rung, dir, device.clone())?;
        let checkpoint = match trainer.run(stop, |_| {})? {
            RunEnd::Finished(checkpoint) => checkpoint,
            RunEnd::Interrupted(_) => return Ok(None),
        };
        let train_seconds = started.elapsed().as_secs_f64();
        let model = dir.join("model.onnx");
        crate::export::export_checkpoint(&checkpoint, &model)?;
        let data = &trainer.state().config.data;
        let access = FileAccess {
            allow_outside_folder: data.allow_outside_folder,
        };
        let animation = data.animation.clone();
        let mut check = self.score(&model, clip, animation.as_deref(), access)?;
        check.steps = steps;
        check.train_seconds = train_seconds;
        Ok(Some(check))
    }

    /// Samples the model at `model` as the benchmark does and scores the samples against the
    /// clip it learned (the file at `clip`, its `animation`), read and encoded for the model as
    /// `sinmdm eval` reads it, so that the scores are the ones it prints.
    fn score(
        &self,
        model: &Path,
        clip: &Path,
        animation: Option<&str>,
        access: FileAccess,
    ) -> Result<RungCheck, TrainError> {
        let failed = |message: String| TrainError::Check {
            model: model.to_path_buf(),
            message,
        };
        let started = Instant::now();
        let mut network = sinmdm::Model::open(model, &sinmdm::ModelOptions::default())
            .map_err(|e| failed(e.to_string()))?;
        let metadata = network.metadata().clone();
        let options = ReadOptions {
            animation: animation.map(AnimationChoice::parse),
            fps: None,
        };
        let (channels, _) = read_clip_with_access(clip, &options, access)?;
        let clip = encode_for_model(&channels, &metadata.layout, None)
            .map_err(|e| failed(e.to_string()))?
            .features;
        let request = sinmdm::Request {
            task: sinmdm::Task::Generate {
                frames: 2 * clip.ncols(),
            },
            count: self.samples,
            seed: self.seed,
            // The sampling a user gets by default (`sinmdm eval`'s too): respaced steps.
            steps: Some(sinmdm::DEFAULT_STEPS),
            feet: sinmdm::Feet::Planted,
            method: Default::default(),
        };
        let threads = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
        let plan = sinmdm::plan(&metadata, &request).map_err(|e| failed(e.to_string()))?;
        let generated = plan
            .run(&mut network, &mut |_, _| ControlFlow::Continue(()))
            .map_err(|e| failed(e.to_string()))?;
        let scores = sinmdm_eval::goal_scores(&generated, clip.view(), threads)
            .map_err(|e| failed(e.to_string()))?;
        Ok(RungCheck {
            steps: 0,
            learning_rate: None,
            coverage: scores.report.coverage.mean,
            global_diversity: scores.report.global_diversity.mean,
            replay_seconds: scores.replay.mean_seconds,
            jitter_ratio: scores.raw_jitter_ratio,
            replay_floor_seconds: scores.replay.clip_backwards_seconds,
            kinematics: scores.kinematics,
            clip_still_share: scores.clip_still_share,
            train_seconds: 0.0,
            check_seconds: started.elapsed().as_secs_f64(),
            made_from: String::new(),
        })
    }
}

/// The rule's choice once the ladder has climbed: `choice` with the steps of the rung it
/// chooses, or, where no rung covers the clip, the clip trained as a varied one (the rule's
/// [`RuleChoice::if_not_calm`]).
fn climbed(choice: RuleChoice, rungs: &[RungCheck]) -> RuleChoice {
    match choose(rungs) {
        Some(best) => {
            let mut chosen = choice;
            let warmup = clip_rule::calm_warmup_steps(best.steps);
            chosen.config.training.steps = best.steps;
            chosen.config.training.warmup_steps = warmup;
            if let Some(rate) = best.learning_rate {
                chosen.config.training.learning_rate = rate;
            }
            let reason = Reason::LadderRung {
                warmup,
                meets_goals: best.meets_goals(),
                learning_rate: best.learning_rate,
            };
            chosen.choices.steps = Chosen::new(best.steps, reason);
            chosen
        }
        None => {
            let most = rungs
                .iter()
                .max_by(|a, b| a.coverage.total_cmp(&b.coverage))
                .expect("the ladder has rungs");
            clip_rule::not_calm_after_all(&choice, most.coverage, most.steps).unwrap_or(choice)
        }
    }
}

impl Ladder {
    /// The rule's `choice` with its steps settled: as the rule left them, or, where it leaves
    /// them to the ladder (a calm clip), the ladder climbed in `folder` on `clip` and the rung
    /// it chooses (or the rule's choice for a clip no rung covers). `on_rung` hears each rung's
    /// scores; `None` when the stop flag was raised during the climb (the rungs finished so far
    /// are kept for the next start).
    pub fn settle(
        &self,
        clip: LadderClip<'_>,
        choice: RuleChoice,
        folder: &Path,
        device: &Device,
        stop: &AtomicBool,
        on_rung: &mut dyn FnMut(&RungCheck),
    ) -> Result<Option<RuleChoice>, TrainError> {
        if !choice.climb_ladder {
            return Ok(Some(choice));
        }
        let rungs = match self.climb(clip, &choice.config, folder, device, stop, on_rung)? {
            Climb::Done(rungs) => rungs,
            Climb::Interrupted => return Ok(None),
        };
        let mut chosen = climbed(choice, &rungs);
        chosen.choices.rungs = rungs.iter().map(RungCheck::line).collect();
        Ok(Some(chosen))
    }
}

/// The folder, inside the ladder's, of the rung of `steps` at `learning_rate` (the
/// configuration's where `None`).
pub fn rung_folder(steps: u64, learning_rate: Option<f64>) -> String {
    match learning_rate {
        None => format!("steps-{steps}"),
        Some(rate) => format!("steps-{steps}-lr{rate}"),
    }
}

/// The ladder folder of the run folder `run`.
pub fn folder(run: &Path) -> PathBuf {
    run.join(LADDER_FOLDER)
}
