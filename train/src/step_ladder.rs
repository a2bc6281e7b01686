//! A calm clip's steps, chosen by its own samples: the step ladder.
//!
//! A calm clip (see [`crate::clip_rule`]) is covered within a few hundred steps, and the longer
//! it trains the longer its samples replay it verbatim. How few steps a calm clip can train and
//! still be covered, and how many it can train before it replays, differ from clip to clip in
//! ways one number read before training did not predict on clips it was not chosen on
//! (docs/TRAINING_EXPERIMENTS.md, "The step ladder"). So the trainer measures instead: it trains
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
use serde::{Deserialize, Serialize};

use sinmdm::motion::encode_for_model;
use sinmdm_formats::{AnimationChoice, ReadOptions, read_clip};

pub use crate::ladder_settings::{CHECK_SAMPLES, CHECK_SEED, LADDER_STEPS, goals};

use crate::clip_data::ClipData;
use crate::clip_rule::RuleChoice;
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::trainer::{RunEnd, Trainer};

/// The folder, inside the run folder, that holds the rungs.
pub const LADDER_FOLDER: &str = "step_ladder";
/// The scores file of a finished rung.
const CHECK_FILE: &str = "check.json";

/// How a rung's samples scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RungCheck {
    /// The rung's optimiser steps.
    pub steps: u64,
    /// Coverage of the clip's windows, percent.
    pub coverage: f64,
    /// Global diversity.
    pub global_diversity: f64,
    /// Mean over the samples of their longest verbatim copy of the clip, seconds.
    pub replay_seconds: f64,
    /// The samples' jitter as a multiple of the clip's (raw feet).
    pub jitter_ratio: f64,
    /// Seconds the rung trained.
    pub train_seconds: f64,
    /// Seconds its samples took to make and score.
    pub check_seconds: f64,
    /// What the rung was made from ([`Ladder::rung_fingerprint`]): a rung scored for another
    /// clip, configuration, check or trainer version is trained again, not reused.
    #[serde(default)]
    pub made_from: String,
}

impl RungCheck {
    /// Each goal's margin (coverage, replay, most jitter, least jitter), in units of about one
    /// goal's worth ([`goals`]): positive where met, negative where missed.
    pub fn margins(&self) -> [f64; 4] {
        [
            (self.coverage - goals::COVERAGE) / goals::COVERAGE_UNIT,
            (goals::REPLAY_SECONDS - self.replay_seconds) / goals::REPLAY_UNIT,
            (goals::JITTER_RATIO - self.jitter_ratio) / goals::JITTER_UNIT,
            (self.jitter_ratio - goals::LEAST_JITTER_RATIO) / goals::LEAST_JITTER_UNIT,
        ]
    }

    /// The smallest margin: how far the rung is from missing a goal (negative: how far it misses
    /// the goal it misses most).
    pub fn worst_margin(&self) -> f64 {
        self.margins().into_iter().fold(f64::INFINITY, f64::min)
    }

    /// The goals' shortfalls summed (0 where every goal is met), in the margins' units: how far
    /// the rung misses the goals it misses, all of them.
    pub fn shortfall(&self) -> f64 {
        self.margins().into_iter().map(|m| (-m).max(0.0)).sum()
    }

    /// Whether the samples cover the clip.
    pub fn covers(&self) -> bool {
        self.coverage >= goals::COVERAGE
    }

    /// Whether the samples meet every goal.
    pub fn meets_goals(&self) -> bool {
        self.worst_margin() >= 0.0
    }

    /// One line of the ladder's table.
    pub fn line(&self) -> String {
        format!(
            "{:>4} steps: coverage {:.1}, replay {:.2} s, jitter {:.2}x the clip's, global diversity {:.3}{} ({:.0} s + {:.0} s check)",
            self.steps,
            self.coverage,
            self.replay_seconds,
            self.jitter_ratio,
            self.global_diversity,
            if self.meets_goals() {
                ", every goal met"
            } else {
                ""
            },
            self.train_seconds,
            self.check_seconds
        )
    }
}

/// Which rung the main run trains: of those that meet every goal, the one whose worst margin
/// is widest; where none does, the one whose shortfalls sum least ([`RungCheck::shortfall`]), so
/// that a rung a hair under one goal beats one that misses another by far, and a clip with a
/// goal no rung meets does not give up a second goal for it (the fox's idle replays whatever
/// the steps, 1.66-2.06 s; its 75-step rung replayed 0.15 s less than the 50-step one at 2.28x
/// the clip's jitter against 1.42x). Fewer steps on a tie. `None` when no rung covers the clip
/// (it is not calm after all); where one does, the rung chosen may still be one a hair under
/// coverage, when the covering rungs miss the other goals by more.
pub fn choose(rungs: &[RungCheck]) -> Option<&RungCheck> {
    if !rungs.iter().any(RungCheck::covers) {
        return None;
    }
    rungs.iter().min_by(|a, b| {
        a.shortfall()
            .total_cmp(&b.shortfall())
            .then(b.worst_margin().total_cmp(&a.worst_margin()))
            .then(a.steps.cmp(&b.steps))
    })
}

/// The ladder's settings (the trainer climbs [`Ladder::default`]; tests climb a shorter one).
#[derive(Debug, Clone, PartialEq)]
pub struct Ladder {
    /// The steps of each rung.
    pub steps: Vec<u64>,
    /// Samples a rung is scored on.
    pub samples: usize,
    /// Their seed.
    pub seed: u64,
}

impl Default for Ladder {
    fn default() -> Self {
        Ladder {
            steps: LADDER_STEPS.to_vec(),
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

/// The clip a ladder climbs on: its file, and the SHA-256 (hex) of its bytes as [`ClipData`]
/// holds it, which goes into each rung's fingerprint.
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
    /// when the most steps do not cover it, fewer will not). A rung whose scores are already
    /// there is not trained again. `on_rung` hears each rung's scores as they come; the rungs
    /// come back sorted by their steps.
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
        let mut rungs: Vec<RungCheck> = Vec::with_capacity(order.len());
        for steps in order {
            if rungs.first().is_some_and(|most| !most.covers()) {
                break;
            }
            let dir = folder.join(format!("steps-{steps}"));
            let made_from = self.rung_fingerprint(clip.sha256, config, steps);
            let check = match read_check(&dir, steps, &made_from) {
                Some(check) => check,
                None => match self.train_rung(clip.path, config, steps, &dir, device, stop)? {
                    Some(check) => {
                        let check = RungCheck { made_from, ..check };
                        write_check(&dir, &check)?;
                        check
                    }
                    None => return Ok(Climb::Interrupted),
                },
            };
            on_rung(&check);
            rungs.push(check);
        }
        rungs.sort_by_key(|r| r.steps);
        Ok(Climb::Done(rungs))
    }

    /// The configuration a rung of `steps` trains: `config` with the rung's steps and warm-up,
    /// one checkpoint at its end, and no rule (its numbers are the rule's already).
    pub fn rung_config(config: &TrainConfig, steps: u64) -> TrainConfig {
        let mut rung = config.clone();
        rung.from_clip = Default::default();
        rung.training.steps = steps;
        rung.training.warmup_steps = crate::clip_rule::calm_warmup_steps(steps);
        rung.training.checkpoint_every = steps;
        rung
    }

    /// What a rung of `steps` on the clip whose bytes hash to `clip_sha256` (SHA-256, hex) is
    /// made from, hashed: the trainer's version, the clip, the rung's configuration
    /// ([`Ladder::rung_config`] of `config`) and this ladder's check (samples and seed). A
    /// finished rung is reused only when its scores record the same.
    pub fn rung_fingerprint(&self, clip_sha256: &str, config: &TrainConfig, steps: u64) -> String {
        let rung = serde_json::to_string(&Self::rung_config(config, steps))
            .expect("a configuration serialises");
        let check = format!("{} samples, seed {}", self.samples, self.seed);
        sinmdm_library::fingerprint::sha256_of_parts(&[
            env!("CARGO_PKG_VERSION").as_bytes(),
            clip_sha256.as_bytes(),
            rung.as_bytes(),
            check.as_bytes(),
        ])
    }

    /// Trains one rung into `dir` (anything a killed rung left there is replaced), exports it
    /// and scores its samples; `None` when stopped.
    fn train_rung(
        &self,
        clip: &Path,
        config: &TrainConfig,
        steps: u64,
        dir: &Path,
        device: &Device,
        stop: &AtomicBool,
    ) -> Result<Option<RungCheck>, TrainError> {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|source| TrainError::Io {
                what: "clear an unfinished rung of the step ladder",
                path: dir.to_path_buf(),
                source,
            })?;
        }
        let rung = Self::rung_config(config, steps);
        let started = Instant::now();
        let mut trainer = Trainer::start(clip, rung, dir, device.clone())?;
        let checkpoint = match trainer.run(stop, |_| {})? {
            RunEnd::Finished(checkpoint) => checkpoint,
            RunEnd::Interrupted(_) => return Ok(None),
        };
        let train_seconds = started.elapsed().as_secs_f64();
        let model = dir.join("model.onnx");
        crate::export::export_checkpoint(&checkpoint, &model)?;
        let animation = trainer.state().config.data.animation.clone();
        let mut check = self.score(&model, clip, animation.as_deref())?;
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
        let (channels, _) = read_clip(clip, &options)?;
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
            coverage: scores.report.coverage.mean,
            global_diversity: scores.report.global_diversity.mean,
            replay_seconds: scores.replay.mean_seconds,
            jitter_ratio: scores.raw_jitter_ratio,
            train_seconds: 0.0,
            check_seconds: started.elapsed().as_secs_f64(),
            made_from: String::new(),
        })
    }
}

/// Starts a new run of `config` on `clip` in the folder `run`, as [`Trainer::start`] does, but
/// for a calm clip whose steps the rule that reads the clip was asked for, climbs `ladder`
/// ([`Ladder::default`] for the trainer) first (in [`folder`]`(run)`) and trains the rung it chooses, or trains the clip as a
/// varied one when no rung covers it. `on_rung` hears each rung's scores; `None` when the stop
/// flag was raised during the climb (the same command starts again and keeps the finished
/// rungs).
pub fn start_run(
    clip: &Path,
    config: TrainConfig,
    run: &Path,
    device: Device,
    ladder: &Ladder,
    stop: &AtomicBool,
    on_rung: &mut dyn FnMut(&RungCheck),
) -> Result<Option<Trainer>, TrainError> {
    Trainer::check_new_run(run)?;
    let data = ClipData::load(clip, &config.data, &config.model)?;
    let choice = match crate::clip_rule::apply(&config, &data) {
        Some(choice) if choice.climb_ladder => choice,
        Some(choice) => return Trainer::start_chosen(clip, data, choice, run, device).map(Some),
        None => return Trainer::start_loaded(clip, data, config, run, device).map(Some),
    };
    let on_clip = LadderClip {
        path: clip,
        sha256: &data.facts.sha256,
    };
    let rungs = match ladder.climb(
        on_clip,
        &choice.config,
        &folder(run),
        &device,
        stop,
        on_rung,
    )? {
        Climb::Done(rungs) => rungs,
        Climb::Interrupted => return Ok(None),
    };
    let mut chosen = match choose(&rungs) {
        Some(best) => {
            let mut chosen = choice.config;
            chosen.training.steps = best.steps;
            chosen.training.warmup_steps = crate::clip_rule::calm_warmup_steps(best.steps);
            let why = if best.meets_goals() {
                "the rung of the step ladder that meets every goal with the widest margin"
            } else {
                "no rung of the step ladder meets every goal; this one misses them by least in all"
            };
            let mut lines = choice.lines;
            for line in lines.iter_mut().filter(|l| l.starts_with("steps ")) {
                *line = format!(
                    "steps           {} (warm-up {}): {why}",
                    chosen.training.steps, chosen.training.warmup_steps
                );
            }
            RuleChoice {
                config: chosen,
                lines,
                ..choice
            }
        }
        None => {
            let most = rungs
                .iter()
                .max_by(|a, b| a.coverage.total_cmp(&b.coverage))
                .expect("the ladder has rungs");
            let why = format!(
                "no short run of the step ladder covered it (at most {:.1} at {} steps)",
                most.coverage, most.steps
            );
            crate::clip_rule::not_calm_after_all(&config, choice.reading, &why)
        }
    };
    chosen
        .lines
        .push("step ladder (each rung's samples, scored):".into());
    chosen
        .lines
        .extend(rungs.iter().map(|r| format!("  {}", r.line())));
    Trainer::start_chosen(clip, data, chosen, run, device).map(Some)
}

/// Writes a finished rung's scores into its folder `dir` (whole, or not at all).
fn write_check(dir: &Path, check: &RungCheck) -> Result<(), TrainError> {
    let json = serde_json::to_string_pretty(check).expect("scores serialise");
    sinmdm::files::write_atomically(&dir.join(CHECK_FILE), json.as_bytes()).map_err(|source| {
        TrainError::Io {
            what: "write a rung's scores",
            path: dir.join(CHECK_FILE),
            source,
        }
    })
}

/// The scores a finished rung left in `dir`, if it finished, trained `steps` and was made from
/// `made_from` ([`Ladder::rung_fingerprint`]).
fn read_check(dir: &Path, steps: u64, made_from: &str) -> Option<RungCheck> {
    let text = std::fs::read_to_string(dir.join(CHECK_FILE)).ok()?;
    serde_json::from_str::<RungCheck>(&text)
        .ok()
        .filter(|c| c.steps == steps && c.made_from == made_from)
}

/// The ladder folder of the run folder `run`.
pub fn folder(run: &Path) -> PathBuf {
    run.join(LADDER_FOLDER)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rung(steps: u64, coverage: f64, replay_seconds: f64, jitter_ratio: f64) -> RungCheck {
        RungCheck {
            steps,
            coverage,
            global_diversity: 1.0,
            replay_seconds,
            jitter_ratio,
            train_seconds: 1.0,
            check_seconds: 1.0,
            made_from: String::new(),
        }
    }

    #[test]
    fn margins_are_in_units_of_one_goal() {
        let r = rung(100, 97.5, 0.75, 1.0);
        let m = r.margins();
        assert_eq!(m[..3], [0.5, 0.5, 1.0]);
        // 1.0 is 1/3 over the least jitter 2/3, whose unit is 2/3 - 1/2 = 1/6: two units.
        assert!((m[3] - 2.0).abs() < 1e-12, "{m:?}");
        assert_eq!(r.worst_margin(), 0.5);
        assert!(r.meets_goals() && r.covers());
        // Exactly on every goal meets it.
        assert!(rung(100, 95.0, 1.0, 1.5).meets_goals());
        assert!(rung(100, 95.0, 1.0, 1.0 / 1.5).meets_goals());
        let missed = rung(100, 99.0, 1.25, 1.0);
        assert_eq!(missed.worst_margin(), -0.5);
        assert!(!missed.meets_goals() && missed.covers());
        // Smoother than the clip by more than 1.5x misses the least jitter: half the clip's is
        // one unit under it.
        let smooth = rung(50, 100.0, 0.2, 0.5);
        assert!(
            (smooth.worst_margin() + 1.0).abs() < 1e-12,
            "{:?}",
            smooth.margins()
        );
    }

    #[test]
    fn the_widest_margin_wins_and_the_least_shortfall_where_no_rung_meets_every_goal() {
        // A kick: covered only from 200 steps, and replaying more the longer it trains.
        let kick = [
            rung(50, 80.0, 0.4, 1.0),
            rung(100, 90.0, 0.5, 1.2),
            rung(200, 96.0, 0.8, 1.4),
            rung(300, 97.5, 0.9, 1.45),
        ];
        // 200: min(0.2, 0.4, 0.2) = 0.2; 300: min(0.5, 0.2, 0.1) = 0.1.
        assert_eq!(choose(&kick).map(|r| r.steps), Some(200));
        // A hair under coverage beats a replay well over its goal.
        let edge = [rung(300, 94.97, 0.97, 1.48), rung(400, 97.3, 1.23, 1.45)];
        assert_eq!(choose(&edge).map(|r| r.steps), Some(300));
        // Every rung meets the adaptive default's goals: the least-trained is too smooth.
        let happy = [
            rung(50, 100.0, 0.20, 0.26),
            rung(150, 100.0, 0.76, 0.82),
            rung(300, 100.0, 0.91, 0.83),
        ];
        assert_eq!(choose(&happy).map(|r| r.steps), Some(150));
        // A clip that replays: the rung that replays least, when every rung covers it.
        let still = [
            rung(50, 100.0, 1.7, 1.4),
            rung(100, 100.0, 1.9, 1.3),
            rung(200, 100.0, 2.1, 1.2),
        ];
        assert_eq!(choose(&still).map(|r| r.steps), Some(50));
        // A goal no rung meets (the fox's idle, which replays whatever the steps): the rung
        // that misses only it beats one that misses it a little less and the jitter too. The
        // widest worst margin alone would take 75: min(-1.48, -1.56) against min(-1.78, 0.16).
        let fox = [
            rung(50, 100.0, 1.89, 1.42),
            rung(75, 100.0, 1.74, 2.28),
            rung(300, 100.0, 1.66, 3.61),
        ];
        assert!(fox[1].worst_margin() > fox[0].worst_margin());
        assert!(
            (fox[0].shortfall() - 1.78).abs() < 1e-9,
            "{}",
            fox[0].shortfall()
        );
        assert!(
            (fox[1].shortfall() - 3.04).abs() < 1e-9,
            "{}",
            fox[1].shortfall()
        );
        assert_eq!(choose(&fox).map(|r| r.steps), Some(50));
        // Ties go to fewer steps, in any order.
        let tie = [rung(100, 100.0, 0.5, 1.0), rung(50, 100.0, 0.5, 1.0)];
        assert_eq!(choose(&tie).map(|r| r.steps), Some(50));
        // No rung that covers the clip: none is chosen, however wide the other margins.
        let uncovered = [rung(50, 94.9, 0.1, 0.5), rung(300, 90.0, 0.1, 0.5)];
        assert_eq!(choose(&uncovered), None);
        assert_eq!(choose(&[]), None);
    }
}
