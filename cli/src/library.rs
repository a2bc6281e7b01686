//! `sinmdm library`: a motion library trained as an array job (`sinmdm-train --manifest`), read
//! back: which clips are done, running, failed or stale; a report of every model (a Markdown and
//! JSON table, a contact sheet); and a batch generation mode, one clip per array task.

use std::path::PathBuf;
use std::process::Command;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use sinmdm_library::report::{Standing, rows, status_text, write_report};
use sinmdm_library::{Manifest, TaskFolder, task_index};

/// Examples of `sinmdm library`.
pub const EXAMPLES: &str = "Examples:
  sinmdm-train --manifest library.yaml --index 0     # one task (a Slurm array task reads SLURM_ARRAY_TASK_ID)
  sinmdm library status --manifest library.yaml      # done, running, failed (with the error), stale, pending
  sinmdm library report --manifest library.yaml -o report/   # report.md, report.json, contact_sheet.png
  sinmdm library generate --manifest library.yaml --index 0 --count 20 --format glb

Recipes for Slurm and Kubernetes: scripts/cluster/ (see docs/GUIDE.md, A library on a cluster).";

/// Arguments of `sinmdm library`.
#[derive(Debug, Args)]
pub struct LibraryArgs {
    #[command(subcommand)]
    command: LibraryCommand,
}

#[derive(Debug, Subcommand)]
enum LibraryCommand {
    /// Every clip's state: done, running, failed (with its error), stale or pending.
    Status(ManifestArg),
    /// One table of every model's evaluation and training time (Markdown and JSON) and a
    /// contact sheet of their samples.
    Report(ReportArgs),
    /// Samples of one clip's model (an array task of a generation job): `--count` samples into
    /// the clip's folder, `samples/` (BVH files, or one glTF file).
    Generate(GenerateArgs),
}

#[derive(Debug, Args)]
struct ManifestArg {
    /// The library manifest (YAML).
    #[arg(long, value_name = "LIBRARY.yaml")]
    manifest: PathBuf,
}

#[derive(Debug, Args)]
struct ReportArgs {
    #[command(flatten)]
    manifest: ManifestArg,
    /// Folder for report.md, report.json and contact_sheet.png (default: the library's folder).
    #[arg(short, long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct GenerateArgs {
    #[command(flatten)]
    manifest: ManifestArg,
    /// The clip, from 0 (default: SLURM_ARRAY_TASK_ID, then JOB_COMPLETION_INDEX).
    #[arg(long)]
    index: Option<usize>,
    /// Samples to make.
    #[arg(long, default_value_t = 10)]
    count: usize,
    /// Seed of the samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output format: bvh (a file per sample) or glb / gltf (one file, an animation per sample).
    #[arg(long, default_value = "bvh")]
    format: String,
    /// Seconds per sample (default: twice the clip).
    #[arg(long)]
    seconds: Option<f64>,
}

/// Runs `sinmdm library ...`.
pub fn run(args: &LibraryArgs) -> Result<()> {
    match &args.command {
        LibraryCommand::Status(a) => {
            let manifest = Manifest::load(&a.manifest)?;
            let rows = rows(&manifest)?;
            print!("{}", status_text(&rows));
            Ok(())
        }
        LibraryCommand::Report(a) => {
            let manifest = Manifest::load(&a.manifest.manifest)?;
            let out = a.out.clone().unwrap_or_else(|| manifest.out.clone());
            for file in write_report(&manifest, &out)? {
                println!("wrote {}", file.display());
            }
            Ok(())
        }
        LibraryCommand::Generate(a) => generate(a),
    }
}

fn generate(args: &GenerateArgs) -> Result<()> {
    let manifest = Manifest::load(&args.manifest.manifest)?;
    let index = task_index(args.index, |v| std::env::var(v).ok())?;
    let entry = manifest.entry(index)?;
    let folder = TaskFolder::new(manifest.folder(entry));
    let standing = rows(&manifest)?[index].standing;
    if standing != Standing::Done {
        bail!(
            "clip {index} ({}) has no current model ({standing:?}); train it first with sinmdm-train --manifest",
            Manifest::name(entry)
        );
    }
    let extension = match args.format.as_str() {
        "bvh" | "glb" | "gltf" => args.format.as_str(),
        other => bail!("--format must be bvh, glb or gltf, got '{other}'"),
    };
    let dir = folder.dir.join("samples");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let out = dir.join(format!("{}.{extension}", Manifest::name(entry)));
    let mut command = Command::new(std::env::current_exe().context("finding the sinmdm binary")?);
    command
        .arg("generate")
        .arg("-m")
        .arg(folder.model())
        .args([
            "--count",
            &args.count.to_string(),
            "--seed",
            &args.seed.to_string(),
        ])
        .arg("-o")
        .arg(&out)
        .arg("--quiet");
    if let Some(seconds) = args.seconds {
        command.args(["--seconds", &seconds.to_string()]);
    }
    let status = command.status().context("running sinmdm generate")?;
    if !status.success() {
        bail!(
            "sinmdm generate failed for clip {index} ({})",
            Manifest::name(entry)
        );
    }
    println!("{}", dir.display());
    Ok(())
}
