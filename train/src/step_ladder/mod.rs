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
use sinmdm_eval::KinematicScores;
use sinmdm_formats::{AnimationChoice, FileAccess, ReadOptions, read_clip_with_access};

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
    /// What the clip played backwards scores on the replay measure, seconds: motion that is no
    /// copy, so a replay no longer than it meets the replay goal however long it is.
    #[serde(default)]
    pub replay_floor_seconds: f64,
    /// How the samples (raw feet) move against the clip: stillness, speeds, accelerations.
    #[serde(default)]
    pub kinematics: KinematicScores,
    /// The clip's own share of nearly still frames.
    #[serde(default)]
    pub clip_still_share: f64,
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
            (self.replay_goal() - self.replay_seconds) / goals::REPLAY_UNIT,
            (goals::JITTER_RATIO - self.jitter_ratio) / goals::JITTER_UNIT,
            (self.jitter_ratio - goals::LEAST_JITTER_RATIO) / goals::LEAST_JITTER_UNIT,
        ]
    }

    /// The longest mean verbatim run that meets the replay goal: [`goals::REPLAY_SECONDS`], or
    /// the clip's backwards score where that is longer (a replay no longer than motion that is
    /// no copy is no evidence of copying).
    pub fn replay_goal(&self) -> f64 {
        goals::REPLAY_SECONDS.max(self.replay_floor_seconds)
    }

    /// Each kinematic goal's margin (nearly still share, speed p25, p50 and p90, speed and
    /// acceleration distance; `sinmdm_eval::kinematics::goals`), in units of about one goal's
    /// worth: positive where met, negative where missed.
    pub fn kinematic_margins(&self) -> [f64; 6] {
        use sinmdm_eval::kinematics::goals as moves;
        let k = &self.kinematics;
        let ratio = |r: f64| {
            let r = r.max(f64::MIN_POSITIVE);
            (r / moves::LEAST_SPEED_RATIO)
                .ln()
                .min((moves::MOST_SPEED_RATIO / r).ln())
                / goals::SPEED_RATIO_UNIT.ln()
        };
        [
            (self.clip_still_share + moves::STILL_SHARE_MARGIN - k.still_share)
                / goals::STILL_SHARE_UNIT,
            ratio(k.speed_ratios[0]),
            ratio(k.speed_ratios[1]),
            ratio(k.speed_ratios[2]),
            (moves::SPEED_DISTANCE - k.speed_distance) / goals::SPEED_DISTANCE_UNIT,
            (moves::ACCELERATION_DISTANCE - k.acceleration_distance)
                / goals::ACCELERATION_DISTANCE_UNIT,
        ]
    }

    /// The smallest margin of every goal, the kinematic ones included: how far the rung is from
    /// missing a goal (negative: how far it misses the goal it misses most).
    pub fn worst_margin(&self) -> f64 {
        self.margins()
            .into_iter()
            .chain(self.kinematic_margins())
            .fold(f64::INFINITY, f64::min)
    }

    /// The kinematic goals' shortfalls summed (0 where the samples move like the clip), in the
    /// margins' units.
    pub fn kinematic_shortfall(&self) -> f64 {
        self.kinematic_margins()
            .into_iter()
            .map(|m| (-m).max(0.0))
            .sum()
    }

    /// The other goals' shortfalls summed (0 where every one is met), in the margins' units: how
    /// far the rung misses the goals it misses, all of them.
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
            "{:>4} steps: coverage {:.1}, replay {:.2} s, jitter {:.2}x the clip's, global diversity {:.3}, still {:.0}% (clip {:.0}%), speed p25/p50/p90 {:.2}/{:.2}/{:.2}x, distances {:.2}/{:.2}{} ({:.0} s + {:.0} s check)",
            self.steps,
            self.coverage,
            self.replay_seconds,
            self.jitter_ratio,
            self.global_diversity,
            100.0 * self.kinematics.still_share,
            100.0 * self.clip_still_share,
            self.kinematics.speed_ratios[0],
            self.kinematics.speed_ratios[1],
            self.kinematics.speed_ratios[2],
            self.kinematics.speed_distance,
            self.kinematics.acceleration_distance,
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
/// is widest. Where none does, moving like the clip comes first: the rung whose kinematic
/// shortfalls sum least ([`RungCheck::kinematic_shortfall`]), so that a frozen or shaking rung
/// is never taken for a moving one; then the one whose other shortfalls sum least
/// ([`RungCheck::shortfall`]), so that a rung a hair under one goal beats one that misses another
/// by far. Fewer steps on a tie. `None` when no rung covers the clip (it is not calm after
/// all); where one does, the rung chosen may still be one under coverage, when the covering
/// rungs move less like the clip or miss the other goals by more.
pub fn choose(rungs: &[RungCheck]) -> Option<&RungCheck> {
    if !rungs.iter().any(RungCheck::covers) {
        return None;
    }
    rungs.iter().min_by(|a, b| {
        a.kinematic_shortfall()
            .total_cmp(&b.kinematic_shortfall())
            .then(a.shortfall().total_cmp(&b.shortfall()))
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
        // The check's version names what a rung's scores hold: version 2 added the backwards
        // floor and the kinematic figures, which a rung scored before does not have; version 3
        // measures the body from the joint that carries it.
        let check = format!("{} samples, seed {}, check 3", self.samples, self.seed);
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
                reason: source,
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
                "no rung of the step ladder meets every goal; this one moves most like the clip, then misses the rest by least in all"
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
            reason: source,
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

    /// Kinematic scores of samples that move exactly like their clip.
    fn moving_like_the_clip() -> KinematicScores {
        KinematicScores {
            speed_ratios: [1.0; 3],
            ..KinematicScores::default()
        }
    }

    fn rung(steps: u64, coverage: f64, replay_seconds: f64, jitter_ratio: f64) -> RungCheck {
        RungCheck {
            steps,
            coverage,
            global_diversity: 1.0,
            replay_seconds,
            jitter_ratio,
            replay_floor_seconds: 0.0,
            kinematics: moving_like_the_clip(),
            clip_still_share: 0.0,
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
    fn kinematic_margins_are_in_units_of_one_goal() {
        let mut r = rung(100, 100.0, 0.5, 1.0);
        assert_eq!(r.kinematic_margins()[4..], [2.0, 2.0]);
        assert!(r.meets_goals());
        // A quarter of the clip's still share over its bound (clip 10 %, samples 20 %): one
        // unit short. p50 at 1.25 x 1.25 the clip's: one unit over; p25 at 0.8: just met.
        r.clip_still_share = 0.1;
        r.kinematics.still_share = 0.2;
        r.kinematics.speed_ratios = [0.8, 1.25 * 1.25, 1.0];
        let m = r.kinematic_margins();
        assert!((m[0] + 1.0).abs() < 1e-12 && m[1].abs() < 1e-12, "{m:?}");
        assert!((m[2] + 1.0).abs() < 1e-12, "{m:?}");
        assert!((r.kinematic_shortfall() - 2.0).abs() < 1e-12);
        assert!(!r.meets_goals());
    }

    #[test]
    fn moving_like_the_clip_comes_before_every_other_goal() {
        // The fox's ladder: 50 steps stand still in 69 % of the frames (its clip: none) and meet
        // the other goals; 1 000 steps move at the clip's median speed but shake (acceleration
        // distance 4.1) and jitter 4.4x. Moving more like the clip wins.
        let mut frozen = rung(50, 100.0, 1.89, 1.42);
        frozen.replay_floor_seconds = 2.0;
        frozen.kinematics = KinematicScores {
            still_share: 0.69,
            speed_ratios: [0.02, 0.06, 1.39],
            speed_distance: 0.78,
            acceleration_distance: 0.78,
            ..KinematicScores::default()
        };
        let mut shaking = rung(1000, 100.0, 2.06, 4.44);
        shaking.replay_floor_seconds = 2.0;
        shaking.kinematics = KinematicScores {
            still_share: 0.03,
            speed_ratios: [0.71, 1.01, 1.49],
            speed_distance: 0.32,
            acceleration_distance: 4.12,
            ..KinematicScores::default()
        };
        assert!(frozen.shortfall() < shaking.shortfall());
        assert!(shaking.kinematic_shortfall() < frozen.kinematic_shortfall());
        let rungs = [frozen, shaking];
        assert_eq!(choose(&rungs).map(|r| r.steps), Some(1000));
    }

    #[test]
    fn a_replay_no_longer_than_the_clip_played_backwards_meets_the_replay_goal() {
        // The fox's idle: its samples replay 1.97 s, the clip backwards scores 2.00 s.
        let mut fox = rung(50, 100.0, 1.97, 1.4);
        assert!(!fox.meets_goals());
        fox.replay_floor_seconds = 2.0;
        assert_eq!(fox.replay_goal(), 2.0);
        assert!(fox.meets_goals(), "{:?}", fox.margins());
        // Over the floor misses it by as much as over the one second would.
        fox.replay_seconds = 2.5;
        assert!(
            (fox.margins()[1] + 1.0).abs() < 1e-12,
            "{:?}",
            fox.margins()
        );
        // A floor under a second leaves the goal at one second.
        fox.replay_floor_seconds = 0.4;
        assert_eq!(fox.replay_goal(), goals::REPLAY_SECONDS);
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
