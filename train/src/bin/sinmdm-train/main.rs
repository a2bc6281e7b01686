//! `sinmdm-train`: fit the denoiser on one clip (BVH, glTF or FBX).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use sinmdm_train::choose::StepsFrom;
use sinmdm_train::{RunEnd, TrainConfig, Trainer};

mod dry_run;

/// Fit the single-motion QnA-UNet denoiser on one clip (BVH, glTF .glb/.gltf, or FBX).
///
/// Examples:
///   sinmdm-train tests/data/bvh/human_walk_cmu_131_01.bvh --out runs/walk   (the default, ~9 min)
///   sinmdm-train CLIP.bvh --minutes 5 --out runs/quick   (as many steps as fit in 5 minutes)
///   sinmdm-train --resume --out runs/walk            (continue after Ctrl-C or a crash)
///   sinmdm-train CLIP.bvh --dry-run   (sizes, and what the default chose from the clip)
///   sinmdm-train character.glb --clip-anim Walk --out runs/walk   (one animation of a glTF file)
///   sinmdm-train mixamo_walk.fbx --out runs/walk                  (an FBX clip, e.g. from Mixamo)
///   sinmdm-train --manifest library.yaml --index 3     (clip 3 of a library: one array task;
///                                   the index may also come from SLURM_ARRAY_TASK_ID or
///                                   JOB_COMPLETION_INDEX)
#[derive(Parser, Debug)]
#[command(name = "sinmdm-train", version, verbatim_doc_comment)]
struct Args {
    /// The clip to learn: .bvh, .glb, .gltf or .fbx (optional with --resume: the run keeps a copy).
    clip: Option<PathBuf>,
    /// The animation of a glTF or FBX clip a new run learns, by name or index (default: the first),
    /// replacing the config's data.animation.
    #[arg(long, value_name = "NAME|INDEX")]
    clip_anim: Option<String>,
    /// Read a .gltf clip's buffer files even where its URIs lead outside the clip's folder
    /// (`../other/data.bin`); off so that a downloaded file cannot read others on the machine.
    #[arg(long)]
    allow_outside_folder: bool,
    /// Training configuration (YAML). Without it a new run uses the default (configs/default.yaml,
    /// built in) and a resumed run its own.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Time budget of a new run in minutes: a short timing probe sets training.steps so that
    /// the run (probe and export included) ends within it. The steps chosen are recorded in the
    /// run's config.yaml, so the run can be repeated exactly with that file.
    #[arg(long, value_name = "M")]
    minutes: Option<f64>,
    /// Frame rate a new run learns the clip at, replacing the config's data.fps: a number of
    /// frames per second, or `clip` for the clip's own. The receptive field is a number of frames,
    /// so this sets how much time the model sees at once (23 frames: 0.77 s at 30 fps).
    #[arg(long, value_name = "FPS|clip")]
    fps: Option<String>,
    /// QnA window of a new run (odd), replacing the config's model.window at any frame rate: the
    /// network then sees 14 + 3 K frames at once (23 for 3, 47 for 11). The trainer names a wider
    /// one when the clip's motion stays correlated far longer than the network sees.
    #[arg(long, value_name = "K")]
    window: Option<usize>,
    /// How a new run describes the root, replacing the config's data.root_layout: `world`
    /// (ground displacement in world axes and a world rotation), `heading` (speeds and turn
    /// in the character's facing frame, which steering needs) or `auto` (the default: heading
    /// where the clip has a facing pair and a travelling root, world otherwise).
    #[arg(long, value_name = "world|heading|auto")]
    root_layout: Option<sinmdm::motion::RootLayout>,
    /// The floor on each feature's standard deviation in a new run, as a share of the mean one,
    /// replacing the config's data.std_floor (0.05; 0.001 trains as models before it did).
    #[arg(long, value_name = "SHARE")]
    std_floor: Option<f64>,
    /// Run folder: checkpoints, loss.csv, loss.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Continue the run in --out from its newest checkpoint (same optimiser state, learning rate
    /// and random stream). A --config may raise training.steps.
    #[arg(long)]
    resume: bool,
    /// Print the clip's size, the parameter count, the receptive field and what the rule that
    /// reads the clip chose (and why), then stop.
    #[arg(long)]
    dry_run: bool,
    /// CPU threads (default: all cores). Each step's batch is split into this many shards that
    /// run in parallel; a run is bit-for-bit repeatable for the same seed and thread count.
    #[arg(long)]
    threads: Option<usize>,
    /// Write the trained model as ONNX here when training finishes (same as running
    /// `sinmdm-export RUN -o FILE` afterwards).
    #[arg(long, value_name = "MODEL.onnx")]
    export: Option<PathBuf>,
    /// Compute device: cpu, or cuda / wgpu when built with that feature.
    #[arg(long, default_value = "cpu")]
    device: String,
    /// A library manifest (YAML): run one task of it, training, exporting and evaluating one
    /// clip into its own folder; a current model is not trained again, a killed task resumes.
    #[arg(long, value_name = "LIBRARY.yaml", conflicts_with_all = ["clip", "out", "resume", "export", "minutes", "config"])]
    manifest: Option<PathBuf>,
    /// The task (clip) index in --manifest, from 0; default: SLURM_ARRAY_TASK_ID, then
    /// JOB_COMPLETION_INDEX (a Kubernetes Indexed Job's).
    #[arg(long, requires = "manifest")]
    index: Option<usize>,
}

/// One task of a library array job.
fn library_task(args: &Args, manifest: &std::path::Path) -> Result<()> {
    use sinmdm_train::library_task::{TaskEnd, run_task};
    let index = sinmdm_library::task_index(args.index, |v| std::env::var(v).ok())?;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C handler")?;
    }
    let device = device(&args.device)?.autodiff();
    let mut last = std::time::Instant::now();
    let end = run_task(manifest, index, device, &stop, |report| {
        if last.elapsed().as_secs_f64() >= 10.0 || report.step == report.total {
            last = std::time::Instant::now();
            eprintln!(
                "task {index}: step {}/{}  loss {:.4}  {:.1} min",
                report.step,
                report.total,
                report.loss,
                report.seconds / 60.0
            );
        }
    })
    .with_context(|| format!("task {index} of {}", manifest.display()))?;
    match end {
        TaskEnd::UpToDate(model) => eprintln!("task {index}: up to date ({})", model.display()),
        TaskEnd::Trained { model, resumed } => eprintln!(
            "task {index}: {} {}",
            if resumed {
                "resumed and finished"
            } else {
                "trained"
            },
            model.display()
        ),
        TaskEnd::Interrupted => {
            eprintln!("task {index}: interrupted; run it again to resume from its checkpoint");
            std::process::exit(130);
        }
    }
    Ok(())
}

fn device(name: &str) -> Result<Device> {
    match name {
        "cpu" => Ok(Device::flex()),
        #[cfg(feature = "cuda")]
        "cuda" => Ok(Device::cuda(0)),
        #[cfg(feature = "wgpu")]
        "wgpu" => Ok(Device::wgpu(Default::default())),
        other => bail!(
            "--device {other} is not available in this build (cpu{}{})",
            if cfg!(feature = "cuda") { ", cuda" } else { "" },
            if cfg!(feature = "wgpu") { ", wgpu" } else { "" }
        ),
    }
}

/// The built-in default configuration (`configs/default.yaml`).
fn default_config() -> TrainConfig {
    TrainConfig::parse(include_str!("../../../../configs/default.yaml"))
        .expect("the shipped default configuration is valid")
}

/// The configuration of a new run: --config, else the default, with --fps and --window applied.
fn new_run_config(args: &Args) -> Result<TrainConfig> {
    let mut config = match &args.config {
        Some(path) => TrainConfig::load(path)?,
        None => default_config(),
    };
    if let Some(fps) = &args.fps {
        config.data.fps = match fps.as_str() {
            "clip" => None,
            number => match number.parse::<f64>() {
                Ok(f) if f.is_finite() && f > 0.0 => Some(f),
                _ => bail!(
                    "--fps must be a positive number of frames per second or `clip`, got '{fps}'"
                ),
            },
        };
    }
    if let Some(animation) = &args.clip_anim {
        config.data.animation = Some(animation.clone());
    }
    config.data.allow_outside_folder = args.allow_outside_folder;
    if let Some(layout) = args.root_layout {
        config.data.root_layout = layout;
    }
    if let Some(floor) = args.std_floor {
        config.data.std_floor = floor;
        config
            .validate()
            .map_err(|e| anyhow::anyhow!("--std-floor {floor}: {e}"))?;
    }
    if let Some(window) = args.window {
        config.model.window = window;
        config.model.window_follows_fps = false;
        config.from_clip.window = false;
        config
            .validate()
            .map_err(|e| anyhow::anyhow!("--window {window}: {e}"))?;
    }
    Ok(config)
}

fn main() -> Result<()> {
    sinmdm_train::memory::keep_freed_memory();
    let args = Args::parse();
    if let Some(threads) = args.threads {
        if threads == 0 {
            bail!("--threads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .context("setting the thread count")?;
    }
    if args.dry_run {
        return dry_run::dry_run(&args);
    }
    if let Some(manifest) = &args.manifest {
        if args.allow_outside_folder {
            bail!("--allow-outside-folder is for a clip named on the command line, not --manifest");
        }
        return library_task(&args, manifest);
    }
    let Some(out) = &args.out else {
        bail!("--out is required: the run folder for checkpoints and logs");
    };
    if let Some(file) = &args.export {
        check_export(file)?;
    }
    let device = device(&args.device)?.autodiff();
    if args.resume && args.minutes.is_some() {
        bail!(
            "--minutes sets the steps of a new run; a resumed run keeps its own (raise them with a --config)"
        );
    }
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C handler")?;
    }
    let mut trainer = if args.resume {
        resumed(&args, out, device)?
    } else {
        started(&args, out, device, &stop)?
    };
    print_start(&trainer, out);
    let end = train(&mut trainer, &stop)?;
    finish(&args, &trainer, end, out)
}

/// Makes `--export`'s folder, and refuses a folder given as the file.
fn check_export(file: &Path) -> Result<()> {
    let dir = file.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--export: cannot create the folder '{}'", dir.display()))?;
    }
    if file.is_dir() {
        bail!(
            "--export '{}' is a folder; give a file name such as model.onnx",
            file.display()
        );
    }
    Ok(())
}

/// The run in `out` resumed, refusing the flags only a new run takes.
fn resumed(args: &Args, out: &Path, device: Device) -> Result<Trainer> {
    if args.fps.is_some() {
        bail!("--fps sets the frame rate of a new run; a resumed run keeps its own");
    }
    if args.window.is_some() {
        bail!("--window sets the QnA window of a new run; a resumed run keeps its own");
    }
    if args.root_layout.is_some() {
        bail!("--root-layout sets the root layout of a new run; a resumed run keeps its own");
    }
    if args.std_floor.is_some() {
        bail!("--std-floor sets how a new run normalises its clip; a resumed run keeps its own");
    }
    if args.clip_anim.is_some() {
        bail!("--clip-anim picks the animation of a new run; a resumed run keeps its own");
    }
    if args.allow_outside_folder {
        bail!("--allow-outside-folder reads a new run's clip; a resumed run reads its own copy");
    }
    let config = args.config.as_deref().map(TrainConfig::load).transpose()?;
    Ok(Trainer::resume(out, args.clip.as_deref(), config, device)?)
}

/// A new run on the clip, its steps from `--minutes` or the rule (and its step ladder); exits
/// with 130 when Ctrl-C stops the ladder.
fn started(args: &Args, out: &Path, device: Device, stop: &Arc<AtomicBool>) -> Result<Trainer> {
    let Some(clip) = &args.clip else {
        bail!("a CLIP to train on is required (or --resume an existing run)");
    };
    let config = new_run_config(args)?;
    let ladder = sinmdm_train::choose::step_ladder::Ladder::default();
    let steps = match args.minutes {
        Some(minutes) if !(minutes.is_finite() && minutes > 0.0) => {
            bail!("--minutes must be a positive number, got {minutes}")
        }
        Some(minutes) => StepsFrom::Minutes(minutes),
        None => StepsFrom::Rule(&ladder),
    };
    let mut on_rung = |rung: &sinmdm_train::choose::step_ladder::RungCheck| {
        eprintln!("step ladder: {}", rung.line());
    };
    match sinmdm_train::choose::start_run(clip, config, out, device, steps, stop, &mut on_rung)? {
        Some(trainer) => {
            if let Some(minutes) = args.minutes {
                let steps = trainer.state().config.training.steps;
                eprintln!("--minutes {minutes}: {steps} steps fit, from a timing probe");
            }
            Ok(trainer)
        }
        None => {
            eprintln!(
                "interrupted while the step ladder chose the steps; the same command starts again and keeps the rungs finished (in {})",
                sinmdm_train::choose::step_ladder::folder(out).display()
            );
            std::process::exit(130);
        }
    }
}

/// What is trained, from which step, and what the rule chose.
fn print_start(trainer: &Trainer, out: &Path) {
    let state = trainer.state().clone();
    eprintln!(
        "training {} ({} frames, F {}, {} parameters) into {}, from step {} of {}",
        state.clip.name,
        state.clip.frames,
        state.features,
        state.parameters,
        out.display(),
        state.step,
        state.config.training.steps
    );
    if let Some(dropped) = &state.clip.dropped {
        eprintln!("left out {dropped}");
    }
    eprintln!("up axis {}", state.clip.up);
    if !state.clip.root.is_empty() {
        eprintln!("root {}", state.clip.root);
    }
    if state.clip.in_place {
        eprintln!("in-place cycle: contacts measured against the treadmill");
    }
    if let Some(chosen) = trainer.chosen() {
        eprintln!("the rule that reads the clip chose (--dry-run says more):");
        for line in chosen.lines() {
            eprintln!("  {line}");
        }
    }
    if state.step == 0
        && let Some(hint) = trainer.wider_window_hint()
    {
        eprintln!("hint: {hint}");
    }
}

/// Trains to the end or to Ctrl-C, with a progress bar on a terminal and a line every 5 % of
/// the steps elsewhere.
fn train(trainer: &mut Trainer, stop: &Arc<AtomicBool>) -> Result<RunEnd> {
    let state = trainer.state().clone();
    let bar = ProgressBar::new(state.config.training.steps);
    if !std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template("{bar:30} step {pos}/{len}  loss {msg}  {per_sec}  ETA {eta}")
            .expect("valid template"),
    );
    bar.set_position(state.step);
    bar.reset_eta();
    let quiet_every = (state.config.training.steps / 20).max(1);
    let terminal = std::io::stderr().is_terminal();
    let end = trainer.run(stop, |report| {
        if let Some(event) = &report.event {
            bar.suspend(|| eprintln!("recovery: {event}"));
        }
        bar.set_position(report.step);
        bar.set_message(format!(
            "{:.4} (mean {:.4})",
            report.loss, report.recent_loss
        ));
        if !terminal && report.step % quiet_every == 0 {
            eprintln!(
                "step {}/{}  loss {:.4}  mean {:.4}  lr {:.3e}  {:.1} min, about {:.1} min left",
                report.step,
                report.total,
                report.loss,
                report.recent_loss,
                report.learning_rate,
                report.seconds / 60.0,
                report.seconds_left() / 60.0
            );
        }
    });
    bar.finish_and_clear();
    Ok(end?)
}

/// The run's ending: the loss curve, recovery and export when finished; how to continue when
/// interrupted (exit code 130).
fn finish(args: &Args, trainer: &Trainer, end: RunEnd, out: &Path) -> Result<()> {
    let state = trainer.state();
    match end {
        RunEnd::Finished(dir) => {
            let png = trainer.run_dir().join("loss.png");
            sinmdm_train::run::loss_plot::write(trainer.loss_log(), &png)?;
            eprintln!(
                "done: {} steps in {:.0} s, final loss {:.4} (mean of the last 100: {:.4})\ncheckpoint {}\nloss curve {}",
                state.step,
                state.elapsed_seconds,
                state.loss,
                state.recent_loss,
                dir.display(),
                png.display()
            );
            if !state.recovery.is_clean() {
                eprintln!(
                    "non-finite steps recovered from: {} (listed under 'recovery' in {})",
                    state.recovery.summary(),
                    dir.join(sinmdm_train::run::checkpoint::STATE_FILE)
                        .display()
                );
            }
            if let Some(file) = &args.export {
                sinmdm_train::export::export_checkpoint(&dir, file)?;
                eprintln!("model {}", file.display());
            }
            Ok(())
        }
        RunEnd::Interrupted(dir) => {
            eprintln!(
                "interrupted at step {}; saved {}. Continue with: sinmdm-train --resume --out {}",
                state.step,
                dir.display(),
                out.display()
            );
            std::process::exit(130);
        }
    }
}
