//! The step ladder on a real calm clip: each rung is trained, exported and scored as `sinmdm
//! eval` scores it, a rung already scored is not trained again, the main run trains the rung the
//! ladder chose (or the varied setting when no rung covers the clip), and a stopped climb keeps
//! the rungs it finished.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

use burn::tensor::Device;
use sinmdm_train::TrainConfig;
use sinmdm_train::choose::step_ladder::{
    FASTER_LEARNING_RATE, Ladder, RungCheck, choose, folder, rung_folder,
};
use sinmdm_train::choose::{StepsFrom, start_run};

mod common;
use common::root;

/// burn's CPU RNG is process-wide: runs in this file take turns.
static RNG: Mutex<()> = Mutex::new(());

fn fox() -> PathBuf {
    root().join("tests/data/bvh/fox_survey_khronos.bvh")
}

/// The tiny model, with the rule asked for the steps only (so the shape stays the tiny one).
fn tiny_asking_for_steps() -> TrainConfig {
    let mut config = TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap();
    config.from_clip.steps = true;
    config
}

fn device() -> Device {
    Device::flex().autodiff()
}

/// The `sinmdm` command line built beside this test (the workspace's test run builds it).
fn sinmdm_command() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile = exe.parent().and_then(Path::parent).unwrap();
    let cli = profile.join(format!("sinmdm{}", std::env::consts::EXE_SUFFIX));
    assert!(
        cli.is_file(),
        "{} is not built; run the workspace's tests (cargo test --workspace)",
        cli.display()
    );
    cli
}

fn json_number(value: &serde_json::Value, path: &[&str]) -> f64 {
    path.iter()
        .fold(value, |v, key| &v[key])
        .as_f64()
        .unwrap_or_else(|| panic!("{path:?} in {value}"))
}

/// Starts a run on the fox with `config` and `ladder`, telling `on_rung` each rung's scores.
fn start_fox(
    run: &Path,
    config: TrainConfig,
    ladder: &Ladder,
    stop: bool,
    on_rung: &mut dyn FnMut(&RungCheck),
) -> Option<sinmdm_train::Trainer> {
    start_run(
        &fox(),
        config,
        run,
        device(),
        StepsFrom::Rule(ladder),
        &AtomicBool::new(stop),
        on_rung,
    )
    .unwrap()
}

/// A ladder of three short rungs and a faster one, scored on two samples.
fn three_rungs() -> Ladder {
    Ladder {
        steps: vec![4, 8, 12],
        faster: vec![5],
        samples: 2,
        seed: 1,
    }
}

#[test]
fn each_rung_is_scored_as_sinmdm_eval_scores_it_and_the_chosen_one_trains() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "climb");
    let ladder = Ladder {
        steps: vec![3, 6],
        faster: Vec::new(),
        samples: 2,
        seed: 1,
    };
    let mut heard: Vec<RungCheck> = Vec::new();
    let trainer = start_fox(&run, tiny_asking_for_steps(), &ladder, false, &mut |r| {
        heard.push(r.clone())
    })
    .expect("not stopped");
    // The most-trained rung first, and the other only when it covers the clip.
    assert_eq!(heard[0].steps, 6);
    let climbed: Vec<u64> = heard.iter().map(|r| r.steps).collect();
    assert_eq!(
        climbed,
        if heard[0].covers() {
            vec![6, 3]
        } else {
            vec![6]
        }
    );

    // Each rung's scores are those `sinmdm eval` gives its model for the same samples.
    for rung in &heard {
        let dir = folder(&run).join(format!("steps-{}", rung.steps));
        let json = dir.join("eval.json");
        let status = Command::new(sinmdm_command())
            .args(["eval", "-m"])
            .arg(dir.join("model.onnx"))
            .arg("--clip")
            .arg(fox())
            .args(["--samples", "2", "--seed", "1", "--quiet", "--json"])
            .arg(&json)
            .status()
            .unwrap();
        assert!(status.success());
        let eval: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let close = |ours: f64, theirs: f64, what: &str| {
            assert!(
                (ours - theirs).abs() <= 1e-6 * theirs.abs().max(1.0),
                "rung {}: {what} {ours} against sinmdm eval's {theirs}",
                rung.steps
            );
        };
        close(
            rung.coverage,
            json_number(&eval, &["report", "coverage", "mean"]),
            "coverage",
        );
        close(
            rung.global_diversity,
            json_number(&eval, &["report", "global_diversity", "mean"]),
            "global diversity",
        );
        close(
            rung.replay_seconds,
            json_number(&eval, &["replay", "mean_seconds"]),
            "replay",
        );
        close(
            rung.jitter_ratio,
            json_number(&eval, &["feet", "raw", "jitter_ratio"]),
            "jitter",
        );
    }

    // The main run trains what the ladder chose, and its lines list the rungs.
    let config = &trainer.state().config;
    match choose(&heard) {
        Some(best) => assert_eq!(config.training.steps, best.steps),
        None => assert_eq!(
            config.training.steps, 300,
            "the configuration's, as a varied clip"
        ),
    }
    let lines = trainer.chosen().unwrap().lines().join("\n");
    assert!(lines.contains("   6 steps: coverage"), "{lines}");
    let _ = std::fs::remove_dir_all(&run);
}

/// Scores as a finished rung leaves them.
fn scored(steps: u64, coverage: f64, replay_seconds: f64, jitter_ratio: f64) -> RungCheck {
    RungCheck {
        steps,
        learning_rate: None,
        coverage,
        global_diversity: 0.5,
        replay_seconds,
        jitter_ratio,
        replay_floor_seconds: 0.0,
        kinematics: sinmdm_eval::KinematicScores {
            speed_ratios: [1.0; 3],
            ..Default::default()
        },
        clip_still_share: 0.0,
        train_seconds: 1.0,
        check_seconds: 1.0,
        made_from: String::new(),
    }
}

/// What a rung of `steps` on the fox is made from, when `ladder` climbs it for `config`.
fn fox_rung_fingerprint(ladder: &Ladder, config: &TrainConfig, steps: u64) -> String {
    fox_rung_fingerprint_at(ladder, config, steps, None)
}

/// [`fox_rung_fingerprint`] of a rung at `learning_rate` (the configuration's where `None`).
fn fox_rung_fingerprint_at(
    ladder: &Ladder,
    config: &TrainConfig,
    steps: u64,
    learning_rate: Option<f64>,
) -> String {
    let clip = sinmdm_train::clip::sha256_hex(&std::fs::read(fox()).unwrap());
    ladder.rung_fingerprint(&clip, &Ladder::rung_config(config, steps, learning_rate))
}

/// Writes `rungs` into the ladder folder of `run`, as a climb of `ladder` with `config` on the
/// fox, stopped after them, leaves them; returns them as written.
fn leave_scored(
    run: &Path,
    ladder: &Ladder,
    config: &TrainConfig,
    rungs: &[RungCheck],
) -> Vec<RungCheck> {
    let mut written = Vec::new();
    for rung in rungs {
        let rung = RungCheck {
            made_from: fox_rung_fingerprint_at(ladder, config, rung.steps, rung.learning_rate),
            ..rung.clone()
        };
        let dir = folder(run).join(rung_folder(rung.steps, rung.learning_rate));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("check.json"),
            serde_json::to_string(&rung).unwrap(),
        )
        .unwrap();
        written.push(rung);
    }
    written
}

#[test]
fn scored_rungs_are_kept_and_the_widest_margin_trains() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "chosen");
    // Rungs 4 and 12 scored already: only 8 is trained. Rung 4 has the widest margin any rung
    // can have (1: full coverage, no replay, the clip's jitter), so 8 can at best tie with it,
    // and a tie goes to fewer steps.
    let config = tiny_asking_for_steps();
    let kept = leave_scored(
        &run,
        &three_rungs(),
        &config,
        &[scored(4, 100.0, 0.0, 1.0), scored(12, 99.0, 0.5, 1.0)],
    );
    // Rung 8 was scored too, but for another configuration: it is trained again.
    let mut other = config.clone();
    other.model.dropout = 0.3;
    let stale = leave_scored(&run, &three_rungs(), &other, &[scored(8, 100.0, 0.0, 1.0)]);
    assert_ne!(
        stale[0].made_from,
        fox_rung_fingerprint(&three_rungs(), &config, 8)
    );
    let mut heard: Vec<RungCheck> = Vec::new();
    let trainer = start_fox(&run, config.clone(), &three_rungs(), false, &mut |r| {
        heard.push(r.clone())
    })
    .unwrap();
    // The most-trained first (it covers the clip), then the others, fewest steps first; rung 4
    // meets every goal, so the faster rung is not climbed.
    assert_eq!(
        heard.iter().map(|r| r.steps).collect::<Vec<_>>(),
        [12, 4, 8]
    );
    assert!(!folder(&run).join("steps-5-lr0.001").exists());
    assert_eq!((&heard[0], &heard[1]), (&kept[1], &kept[0]));
    assert!(folder(&run).join("steps-8/model.onnx").is_file());
    assert_eq!(
        heard[2].made_from,
        fox_rung_fingerprint(&three_rungs(), &config, 8)
    );
    assert_ne!(heard[2], stale[0]);
    assert!(!folder(&run).join("steps-4/model.onnx").exists());
    let config = &trainer.state().config;
    assert_eq!(config.training.steps, 4);
    assert_eq!(config.training.warmup_steps, 1);
    let lines = trainer.chosen().unwrap().lines().join("\n");
    assert!(
        lines.contains(
            "steps           4 (warm-up 1): the rung of the step ladder that meets every goal"
        ),
        "{lines}"
    );
    let _ = std::fs::remove_dir_all(&run);
}

#[test]
fn a_clip_the_most_steps_do_not_cover_trains_as_a_varied_one() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "varied");
    let mut config = tiny_asking_for_steps();
    config.from_clip.window = true;
    leave_scored(&run, &three_rungs(), &config, &[scored(12, 90.0, 0.5, 1.0)]);
    let trainer = start_fox(&run, config, &three_rungs(), false, &mut |_| {}).unwrap();
    // Nothing under the most-trained rung is climbed, nor the faster rung.
    assert!(!folder(&run).join("steps-4").exists() && !folder(&run).join("steps-8").exists());
    assert!(!folder(&run).join("steps-5-lr0.001").exists());
    let trained = &trainer.state().config;
    assert_eq!(trained.training.steps, 300, "the configuration's");
    // The fox stands on four feet: a varied clip on as many trains the wide window.
    assert_eq!(
        trained.model.window,
        sinmdm_train::choose::clip_rule::MANY_FEET_WINDOW
    );
    let lines = trainer.chosen().unwrap().lines().join("\n");
    assert!(
        lines.contains("varied: its own intra diversity")
            && lines
                .contains("no short run of the step ladder covered it (at most 90.0 at 12 steps)"),
        "{lines}"
    );
    let _ = std::fs::remove_dir_all(&run);
}

#[test]
fn a_climb_stopped_before_its_first_rung_starts_no_run() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "stopped");
    let stopped = start_fox(
        &run,
        tiny_asking_for_steps(),
        &Ladder::default(),
        true,
        &mut |_| {},
    );
    assert!(stopped.is_none());
    assert!(!run.join("config.yaml").exists());
    let _ = std::fs::remove_dir_all(&run);
}

#[test]
fn a_run_started_without_the_policy_refuses_a_configuration_that_asks_for_the_rule() {
    // The trainer trains final numbers; the rule that reads the clip is the policy's to apply
    // (`choose::start_run`), so a configuration that still asks for it is refused, before any
    // folder is made.
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "refused");
    let err = sinmdm_train::Trainer::start(&fox(), tiny_asking_for_steps(), &run, device())
        .err()
        .expect("refused");
    assert!(
        matches!(err, sinmdm_train::TrainError::RuleNotApplied),
        "{err}"
    );
    assert!(err.to_string().contains("from_clip"), "{err}");
    assert!(!run.exists());
    // Without the section the same configuration trains as written, and keeps no record of a
    // choice.
    let mut written = tiny_asking_for_steps();
    written.from_clip.steps = false;
    let trainer = sinmdm_train::Trainer::start(&fox(), written, &run, device()).unwrap();
    assert!(trainer.chosen().is_none());
    let _ = std::fs::remove_dir_all(&run);
}

#[test]
fn where_no_rung_meets_every_goal_the_faster_rungs_climb_at_their_rate() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "faster");
    // The tiny configuration's rate (2e-3) is faster than the arm's: the default's is not.
    let mut config = tiny_asking_for_steps();
    config.training.learning_rate = 3e-4;
    let ladder = three_rungs();
    // Every rung at the configuration's rate covers the clip and replays it for 3 s.
    leave_scored(
        &run,
        &ladder,
        &config,
        &[
            scored(4, 100.0, 3.0, 1.0),
            scored(8, 100.0, 3.0, 1.0),
            scored(12, 100.0, 3.0, 1.0),
        ],
    );
    let mut heard: Vec<RungCheck> = Vec::new();
    let trainer = start_fox(&run, config.clone(), &ladder, false, &mut |r| {
        heard.push(r.clone())
    })
    .unwrap();
    let climbed: Vec<(u64, Option<f64>)> =
        heard.iter().map(|r| (r.steps, r.learning_rate)).collect();
    assert_eq!(
        climbed,
        [
            (12, None),
            (4, None),
            (8, None),
            (5, Some(FASTER_LEARNING_RATE))
        ]
    );
    let dir = folder(&run).join(rung_folder(5, Some(FASTER_LEARNING_RATE)));
    assert!(dir.join("model.onnx").is_file(), "{}", dir.display());
    // The rung was trained at its rate: its fingerprint is that of the faster configuration.
    let clip = sinmdm_train::clip::sha256_hex(&std::fs::read(fox()).unwrap());
    let faster = Ladder::rung_config(&config, 5, Some(FASTER_LEARNING_RATE));
    assert_eq!(faster.training.learning_rate, FASTER_LEARNING_RATE);
    assert_eq!(heard[3].made_from, ladder.rung_fingerprint(&clip, &faster));
    // The main run trains the chosen rung with its rate.
    let best = choose(&heard).expect("the rungs cover the clip");
    let trained = &trainer.state().config.training;
    assert_eq!(trained.steps, best.steps);
    assert_eq!(
        trained.learning_rate,
        best.learning_rate.unwrap_or(config.training.learning_rate)
    );
    let _ = std::fs::remove_dir_all(&run);
}

#[test]
fn the_main_run_trains_a_faster_rung_at_its_rate_and_a_fast_configuration_climbs_none() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = common::scratch("ladder", "faster-chosen");
    let mut config = tiny_asking_for_steps();
    config.training.learning_rate = 3e-4;
    // Every rung at the configuration's rate replays the clip for 3 s; the faster rung meets
    // every goal, so the main run trains it, at its rate.
    let replaying = [4, 8, 12].map(|steps| scored(steps, 100.0, 3.0, 1.0));
    leave_scored(&run, &three_rungs(), &config, &replaying);
    let faster = RungCheck {
        learning_rate: Some(FASTER_LEARNING_RATE),
        ..scored(5, 100.0, 0.0, 1.0)
    };
    leave_scored(&run, &three_rungs(), &config, &[faster]);
    let trainer = start_fox(&run, config, &three_rungs(), false, &mut |_| {}).unwrap();
    let trained = &trainer.state().config.training;
    assert_eq!(
        (trained.steps, trained.learning_rate),
        (5, FASTER_LEARNING_RATE)
    );
    let lines = trainer.chosen().unwrap().lines().join("\n");
    assert!(
        lines.contains("(warm-up 2, learning rate 0.001)"),
        "{lines}"
    );
    let _ = std::fs::remove_dir_all(&run);

    // A configuration already at a faster rate (the tiny one's 2e-3) climbs no faster rung.
    let run = common::scratch("ladder", "faster-none");
    let config = tiny_asking_for_steps();
    leave_scored(&run, &three_rungs(), &config, &replaying);
    let mut heard = Vec::new();
    start_fox(&run, config, &three_rungs(), false, &mut |r| {
        heard.push(r.steps)
    })
    .unwrap();
    assert_eq!(heard, [12, 4, 8]);
    let _ = std::fs::remove_dir_all(&run);
}
