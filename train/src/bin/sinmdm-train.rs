//! `sinmdm-train`: fit the denoiser on one BVH clip.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};
use burn::module::Module;
use burn::tensor::Device;
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use sinmdm_train::clip_data::ClipData;
use sinmdm_train::{QnaUnet, RunEnd, TrainConfig, Trainer};

/// Fit the single-motion QnA-UNet denoiser on one BVH clip.
///
/// Examples:
///   sinmdm-train tests/data/bvh/human_walk_cmu_131_01.bvh --config configs/cpu.yaml --out runs/walk
///   sinmdm-train --resume --out runs/walk            (continue after Ctrl-C or a crash)
///   sinmdm-train CLIP.bvh --config configs/paper.yaml --dry-run   (sizes only)
#[derive(Parser, Debug)]
#[command(name = "sinmdm-train", version, verbatim_doc_comment)]
struct Args {
    /// The BVH clip to learn (optional with --resume: the run keeps a copy).
    clip: Option<PathBuf>,
    /// Training configuration (YAML); optional with --resume.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Run folder: checkpoints, loss.csv, loss.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Continue the run in --out from its newest checkpoint (same optimiser state, learning rate
    /// and random stream). A --config may raise training.steps.
    #[arg(long)]
    resume: bool,
    /// Print the clip's size, the parameter count and the receptive field, then stop.
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

fn dry_run(args: &Args) -> Result<()> {
    let (Some(clip), Some(config)) = (&args.clip, &args.config) else {
        bail!("--dry-run needs a CLIP and a --config");
    };
    let config = TrainConfig::load(config)?;
    let data = ClipData::load(clip, &config.data, &config.model)?;
    let features = data.features.nrows();
    let model = QnaUnet::new(features, &config.model, &Device::flex());
    println!(
        "clip            {} ({} frames at {} fps)",
        clip.display(),
        data.facts.frames,
        data.facts.layout.fps
    );
    println!("up axis         {}", data.facts.up);
    if data.facts.in_place {
        println!("cycle           in place: contacts measured against the treadmill");
    }
    println!("features F      {features}");
    println!("channels C      {}", config.model.channels);
    println!("parameters      {}", model.num_params());
    println!("receptive field {} frames", config.model.receptive_field());
    println!(
        "steps           {} (batch {})",
        config.training.steps, config.training.batch_size
    );
    Ok(())
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
        return dry_run(&args);
    }
    let Some(out) = &args.out else {
        bail!("--out is required: the run folder for checkpoints and logs");
    };
    if let Some(file) = &args.export {
        let dir = file.parent().filter(|p| !p.as_os_str().is_empty());
        if let Some(dir) = dir {
            std::fs::create_dir_all(dir).with_context(|| {
                format!("--export: cannot create the folder '{}'", dir.display())
            })?;
        }
        if file.is_dir() {
            bail!(
                "--export '{}' is a folder; give a file name such as model.onnx",
                file.display()
            );
        }
    }
    let device = device(&args.device)?.autodiff();
    let config = args.config.as_deref().map(TrainConfig::load).transpose()?;
    let mut trainer = if args.resume {
        Trainer::resume(out, args.clip.as_deref(), config, device)?
    } else {
        let Some(clip) = &args.clip else {
            bail!("a CLIP to train on is required (or --resume an existing run)");
        };
        let Some(config) = config else {
            bail!("--config is required for a new run (for example configs/cpu.yaml)");
        };
        Trainer::start(clip, config, out, device)?
    };

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C handler")?;
    }

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
    eprintln!("up axis {}", state.clip.up);
    if state.clip.in_place {
        eprintln!("in-place cycle: contacts measured against the treadmill");
    }
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
    let end = trainer.run(&stop, |report| {
        bar.set_position(report.step);
        bar.set_message(format!(
            "{:.4} (mean {:.4})",
            report.loss, report.recent_loss
        ));
        if !terminal && report.step % quiet_every == 0 {
            eprintln!(
                "step {}/{}  loss {:.4}  mean {:.4}  lr {:.3e}",
                report.step, report.total, report.loss, report.recent_loss, report.learning_rate
            );
        }
    });
    bar.finish_and_clear();
    let end = end?;
    let state = trainer.state();
    match end {
        RunEnd::Finished(dir) => {
            let png = trainer.run_dir().join("loss.png");
            sinmdm_train::loss_plot::write(trainer.loss_log(), &png)?;
            eprintln!(
                "done: {} steps in {:.0} s, final loss {:.4} (mean of the last 100: {:.4})\ncheckpoint {}\nloss curve {}",
                state.step,
                state.elapsed_seconds,
                state.loss,
                state.recent_loss,
                dir.display(),
                png.display()
            );
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
