//! Training runs on a real clip: the loss falls, interrupted runs resume exactly, and bad input
//! stops with an error that names the problem.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use burn::tensor::Device;
use sinmdm_train::model::weights::named_tensors;
use sinmdm_train::{RunEnd, TrainConfig, TrainError, Trainer};

/// burn's CPU RNG is process-wide: runs in this file take turns.
mod common;
use common::root;

static RNG: Mutex<()> = Mutex::new(());

fn walk() -> PathBuf {
    root().join("tests/data/bvh/human_walk_cmu_131_01.bvh")
}

fn tiny() -> TrainConfig {
    TrainConfig::load(&root().join("configs/tiny.yaml")).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("train", name)
}

fn losses(run: &Path) -> Vec<(u64, String)> {
    std::fs::read_to_string(run.join("loss.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let mut parts = l.split(',');
            (
                parts.next().unwrap().parse().unwrap(),
                parts.next().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn loss_falls_to_under_half_of_its_start() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = scratch("falls");
    let mut trainer = Trainer::start(&walk(), tiny(), &run, Device::flex().autodiff()).unwrap();
    let end = trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    assert!(matches!(end, RunEnd::Finished(_)));
    let values: Vec<f64> = losses(&run)
        .iter()
        .map(|(_, l)| l.parse().unwrap())
        .collect();
    assert_eq!(values.len(), 300);
    let start = values[..10].iter().sum::<f64>() / 10.0;
    let end = values[values.len() - 50..].iter().sum::<f64>() / 50.0;
    assert!(end < 0.5 * start, "loss went from {start} to {end}");
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn stopped_and_resumed_run_reproduces_the_uninterrupted_one() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let mut config = tiny();
    config.training.steps = 60;
    config.training.checkpoint_every = 25;
    config.model.dropout = 0.3; // exercise the reseeded dropout stream too
    // ... and the cosine schedule and the weight average, which a resume must rebuild.
    config.training.lr_schedule = sinmdm_train::config::LrSchedule::Cosine;
    config.training.warmup_steps = 10;
    config.training.ema_decay = Some(0.9);
    let whole = scratch("whole");
    let mut trainer =
        Trainer::start(&walk(), config.clone(), &whole, Device::flex().autodiff()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    let whole_weights = named_tensors(trainer.model());
    let whole_average = named_tensors(&trainer.averaged_model().unwrap());
    assert_ne!(whole_weights, whole_average);

    let parts = scratch("parts");
    let stop = AtomicBool::new(false);
    let mut first = Trainer::start(&walk(), config, &parts, Device::flex().autodiff()).unwrap();
    let end = first
        .run(&stop, |r| {
            if r.step == 37 {
                stop.store(true, Ordering::SeqCst);
            }
        })
        .unwrap();
    assert!(matches!(end, RunEnd::Interrupted(_)), "{end:?}");
    assert_eq!(first.state().step, 37);
    drop(first);
    let mut second = Trainer::resume(&parts, None, None, Device::flex().autodiff()).unwrap();
    assert_eq!(second.state().step, 37);
    second.run(&AtomicBool::new(false), |_| {}).unwrap();

    assert_eq!(losses(&whole), losses(&parts));
    assert_eq!(whole_weights, named_tensors(second.model()));
    assert_eq!(
        whole_average,
        named_tensors(&second.averaged_model().unwrap())
    );
    // The export writes the average.
    let checkpoint = sinmdm_train::run::checkpoint::latest(&parts)
        .unwrap()
        .unwrap();
    let shape = sinmdm_train::QnaUnet::new(
        second.state().features,
        &second.state().config.model,
        &Device::flex(),
    );
    let exported = sinmdm_train::run::checkpoint::load_exported(&checkpoint, shape).unwrap();
    assert_eq!(whole_average, named_tensors(&exported));
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&parts).unwrap();
}

#[test]
fn a_window_that_follows_the_frame_rate_is_saved_resolved_and_resumes() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = scratch("window-fps");
    let _ = std::fs::remove_dir_all(&run);
    let mut config = tiny();
    config.model.window_follows_fps = true;
    config.data.fps = Some(60.0);
    config.training.steps = 2;
    config.training.checkpoint_every = 1;
    let mut trainer =
        Trainer::start(&walk(), config.clone(), &run, Device::flex().autodiff()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    // Window 3 at 30 fps is window 11 at 60 (the same 0.77 s receptive field: 47 frames), and
    // the run records it as trained.
    let saved = TrainConfig::load(&run.join("config.yaml")).unwrap();
    assert_eq!(saved.model.window, 11);
    assert!(!saved.model.window_follows_fps);
    assert_eq!(trainer.state().config.model.receptive_field(), 47);
    drop(trainer);
    // Asking for the same (unresolved) config again continues the run.
    config.training.steps = 3;
    let mut resumed =
        Trainer::resume(&run, None, Some(config.clone()), Device::flex().autodiff()).unwrap();
    resumed.run(&AtomicBool::new(false), |_| {}).unwrap();
    assert_eq!(resumed.state().step, 3);
    drop(resumed);
    // Another window is refused, by its key.
    config.model.window_follows_fps = false;
    config.training.steps = 4;
    let err = Trainer::resume(&run, None, Some(config), Device::flex().autodiff())
        .err()
        .expect("a different window");
    assert!(err.to_string().contains("model.window"), "{err}");
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn an_automatic_root_layout_is_chosen_from_the_clip_saved_and_resumes() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let mut config = tiny();
    config.data.root_layout = sinmdm::motion::RootLayout::Auto;
    config.training.steps = 1;
    config.training.checkpoint_every = 1;
    let fox = root().join("tests/data/bvh/fox_survey_khronos.bvh");
    for (clip, chosen) in [
        (walk(), sinmdm::motion::RootLayout::Heading),
        (fox, sinmdm::motion::RootLayout::World),
    ] {
        let run = scratch(&format!("auto-root-{chosen}"));
        let _ = std::fs::remove_dir_all(&run);
        let mut trainer =
            Trainer::start(&clip, config.clone(), &run, Device::flex().autodiff()).unwrap();
        trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
        let saved = TrainConfig::load(&run.join("config.yaml")).unwrap();
        assert_eq!(saved.data.root_layout, chosen);
        assert_eq!(trainer.state().clip.root_layout(), chosen);
        let words = &trainer.state().clip.root;
        match chosen {
            sinmdm::motion::RootLayout::Heading => {
                assert!(words.contains("chosen from the clip"), "{words}")
            }
            _ => assert!(words.contains("nothing to steer"), "{words}"),
        }
        drop(trainer);
        // The unresolved config resumes the run: the choice stands.
        let mut longer = config.clone();
        longer.training.steps = 2;
        let mut resumed =
            Trainer::resume(&run, None, Some(longer), Device::flex().autodiff()).unwrap();
        resumed.run(&AtomicBool::new(false), |_| {}).unwrap();
        assert_eq!(resumed.state().step, 2);
        drop(resumed);
        std::fs::remove_dir_all(&run).unwrap();
    }
}

#[test]
fn each_checkpoint_records_the_batch_its_steps_had() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let run = scratch("batch-shape");
    let _ = std::fs::remove_dir_all(&run);
    let mut config = tiny();
    config.training.batch_size = 8;
    config.training.frames_per_step = Some(1024);
    config.data.fps = Some(60.0);
    config.training.steps = 1;
    config.training.checkpoint_every = 1;
    let mut trainer = Trainer::start(&walk(), config, &run, Device::flex().autodiff()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    drop(trainer);
    // The walk's 249 frames at 30 fps (8.27 s) are 497 at 60: 1 024 frames a step make 2
    // whole clips (1 024 / 497 = 2.06), each within the 1 024-frame window.
    let latest = std::fs::read_to_string(run.join("latest")).unwrap();
    let state: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(run.join(latest.trim()).join("state.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(state["clip"]["frames"], 497);
    assert_eq!(
        state["batch"],
        serde_json::json!({"items": 2, "window": 1024})
    );
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn ctrl_c_saves_and_resume_finishes_like_an_uninterrupted_run() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    let config = scratch("ctrlc-config.yaml");
    let text = std::fs::read_to_string(root().join("configs/tiny.yaml"))
        .unwrap()
        .replace("steps: 300", "steps: 400");
    assert!(
        text.contains("steps: 400"),
        "configs/tiny.yaml no longer says steps: 300"
    );
    std::fs::write(&config, text).unwrap();
    let train = |out: &Path, resume: bool| {
        let mut cmd = Command::new(bin);
        if resume {
            cmd.arg("--resume");
        } else {
            cmd.arg(walk());
        }
        cmd.arg("--config").arg(&config).arg("--out").arg(out);
        cmd
    };
    let whole = scratch("ctrlc-whole");
    assert!(train(&whole, false).output().unwrap().status.success());

    let parts = scratch("ctrlc-parts");
    let mut child = train(&parts, false)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while !parts.join("latest").exists() {
        assert!(std::time::Instant::now() < deadline, "no first checkpoint");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // SAFETY: sends SIGINT to the child process we spawned.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGINT);
    }
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "the run should stop on Ctrl-C");
    let saved = losses(&parts).len();
    assert!((100..400).contains(&saved), "saved after {saved} steps");
    let resumed = train(&parts, true).output().unwrap();
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    assert_eq!(losses(&whole), losses(&parts));
    assert!(parts.join("loss.png").is_file());
    for dir in [whole, parts] {
        std::fs::remove_dir_all(dir).unwrap();
    }
    std::fs::remove_file(config).unwrap();
}

#[test]
fn bad_input_gets_an_error_that_names_it() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let device = || Device::flex().autodiff();
    // A clip shorter than the receptive field: the fox, cut to 10 frames.
    let fox =
        std::fs::read_to_string(root().join("tests/data/bvh/fox_survey_khronos.bvh")).unwrap();
    let motion = fox.find("MOTION").unwrap();
    let frames: Vec<&str> = fox[motion..].lines().skip(3).take(10).collect();
    let short = scratch("short.bvh");
    std::fs::write(
        &short,
        format!(
            "{}MOTION\nFrames: 10\nFrame Time: 0.0416667\n{}\n",
            &fox[..motion],
            frames.join("\n")
        ),
    )
    .unwrap();
    let err = Trainer::start(&short, tiny(), &scratch("short-run"), device())
        .err()
        .unwrap();
    assert!(
        matches!(err, TrainError::ClipTooShort { frames: 12, .. }),
        "{err}"
    );
    assert!(
        err.to_string().contains("receptive field of 23 frames"),
        "{err}"
    );

    // An output folder that cannot be made: below a regular file.
    let err = Trainer::start(&walk(), tiny(), &short.join("run"), device())
        .err()
        .unwrap();
    assert!(
        err.to_string()
            .contains("could not create the output folder"),
        "{err}"
    );
    std::fs::remove_file(&short).unwrap();

    // A checkpoint of another model shape.
    let run = scratch("shape");
    let mut config = tiny();
    config.training.steps = 2;
    let mut trainer = Trainer::start(&walk(), config.clone(), &run, device()).unwrap();
    trainer.run(&AtomicBool::new(false), |_| {}).unwrap();
    let mut wider = config.clone();
    wider.model.channels = 64;
    let err = Trainer::resume(&run, None, Some(wider), device())
        .err()
        .unwrap();
    assert!(
        err.to_string()
            .contains("model.channels = 32, the config asks for 64"),
        "{err}"
    );
    // Starting over in a folder that already holds a run.
    let err = Trainer::start(&walk(), config, &run, device())
        .err()
        .unwrap();
    assert!(err.to_string().contains("pass --resume"), "{err}");
    // Resuming with another clip.
    let hop = root().join("tests/data/bvh/human_hop_cmu_131_03.bvh");
    let err = Trainer::resume(&run, Some(&hop), None, device())
        .err()
        .unwrap();
    assert!(
        err.to_string().contains("is not the clip this run learns"),
        "{err}"
    );
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn a_time_budget_sets_the_steps_and_records_them() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    let run = scratch("budget");
    let child = Command::new(bin)
        .arg(walk())
        .arg("--config")
        .arg(root().join("configs/tiny.yaml"))
        .args(["--minutes", "0.15", "--threads", "1", "--out"])
        .arg(&run)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let probe = std::env::temp_dir().join(format!("sinmdm-timing-probe-{}", child.id()));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let recorded = TrainConfig::load(&run.join("config.yaml")).unwrap();
    let steps = recorded.training.steps;
    assert_ne!(steps, tiny().training.steps, "{err}");
    assert!(
        err.contains(&format!("--minutes 0.15: {steps} steps fit"))
            && err.contains(&format!("done: {steps} steps")),
        "{err}"
    );
    // Progress lines in a log (no terminal) say how long the run has taken and has left.
    assert!(err.contains(" min left"), "{err}");
    assert_eq!(losses(&run).len() as u64, steps);
    // No timing probe is left behind.
    assert!(!probe.exists());
    // A resumed run keeps its own steps.
    let again = Command::new(bin)
        .args(["--resume", "--minutes", "1", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(!again.status.success());
    assert!(
        String::from_utf8_lossy(&again.stderr).contains("--minutes sets the steps of a new run")
    );
    std::fs::remove_dir_all(&run).unwrap();
}

#[test]
fn dry_run_prints_the_sizes_of_a_configuration() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    let out = Command::new(bin)
        .arg(walk())
        .args(["--config"])
        .arg(root().join("configs/paper.yaml"))
        .arg("--dry-run")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    // F = 191 for this skeleton: 5,262,546 + 17 * (2 * 3 * 256 + 1).
    assert!(text.contains("parameters      5288675"), "{text}");
    assert!(text.contains("receptive field 23 frames"), "{text}");
    // A configuration of one's own trains its numbers as written.
    assert!(
        text.contains("from_clip       off: the configuration's numbers train as written"),
        "{text}"
    );
}

#[test]
fn dry_run_of_the_default_reads_the_clip() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    // Without --config, the built-in default; --fps replaces its frame rate.
    let default = TrainConfig::load(&root().join("configs/default.yaml")).unwrap();
    let out = Command::new(bin)
        .arg(walk())
        .arg("--dry-run")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains(&format!("channels C      {}", default.model.channels))
            && text.contains(&format!(
                "steps           {} (batch",
                default.training.steps
            ))
            && text.contains("(249 frames at 30 fps)")
            // The rule that reads the clip finds the walk varied (its own intra diversity
            // 0.837) and widens its window to 5 (29 frames), keeping the dropout 0.2.
            && text.contains("clip            varied: its own intra diversity 0.837")
            && text.contains("receptive field 29 frames (QnA window 5)")
            && text.contains("dropout         0.2 (the configuration's): more damps")
            // The default gives a walk the heading-relative root, and says so.
            && text.contains("root            heading-relative: facing across LeftHip and RightHip")
            && text.contains("chosen from the clip (data.root_layout auto)"),
        "{text}"
    );
}

#[test]
fn dry_run_at_the_clips_frame_rate_widens_the_window_and_names_a_bad_fps() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    let out = Command::new(bin)
        .arg(walk())
        .args(["--fps", "clip", "--dry-run"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("(994 frames at 120"), "{text}");
    // The default's QnA window follows the frame rate: the rule's 5 at 30 fps (29 frames,
    // 0.97 s) is 33 at 120 (113 frames, 0.94 s).
    assert!(
        text.contains("receptive field 113 frames (QnA window 33)"),
        "{text}"
    );
    let out = Command::new(bin)
        .arg(walk())
        .args(["--fps", "fast", "--dry-run"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("--fps must be"));
}

#[test]
fn the_window_flag_replaces_the_window_and_names_what_it_refuses() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    // --window replaces the window at any frame rate: 5 at 120 fps stays 5 (14 + 3 * 5 frames).
    let out = Command::new(bin)
        .arg(walk())
        .args(["--fps", "clip", "--window", "5", "--dry-run"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("receptive field 29 frames (QnA window 5)"),
        "{text}"
    );
    let out = Command::new(bin)
        .arg(walk())
        .args(["--window", "4", "--dry-run"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && err.contains("--window 4: model (channels")
            && err.contains("window (4) must be odd"),
        "{err}"
    );
    let out = Command::new(bin)
        .args(["--resume", "--window", "5", "--out"])
        .arg(scratch("no-run-to-resume"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--window sets the QnA window of a new run"),
        "{err}"
    );
}

#[test]
fn the_cli_names_an_unknown_field_of_a_config_and_writes_nothing() {
    let bin = env!("CARGO_BIN_EXE_sinmdm-train");
    let bad = scratch("bad.yaml");
    let text = std::fs::read_to_string(root().join("configs/tiny.yaml"))
        .unwrap()
        .replace("heads: 4", "heads: 4\n  hedas: 2");
    std::fs::write(&bad, text).unwrap();
    let never = scratch("never");
    let out = Command::new(bin)
        .arg(walk())
        .arg("--config")
        .arg(&bad)
        .arg("--out")
        .arg(&never)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("unknown field `hedas`") && err.contains("bad.yaml"),
        "{err}"
    );
    assert!(!never.exists());
    std::fs::remove_file(bad).unwrap();
}
