//! `sinmdm-export`: turn a training checkpoint into the self-contained `.onnx` the runtime loads.

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;

/// Write a training checkpoint as one self-contained ONNX model file.
///
/// Examples:
///   sinmdm-export runs/walk -o walk.onnx                              (newest checkpoint)
///   sinmdm-export runs/walk/checkpoints/step-00010000 -o walk-10k.onnx
#[derive(Parser, Debug)]
#[command(name = "sinmdm-export", version, verbatim_doc_comment)]
struct Args {
    /// A run folder (its newest checkpoint) or a checkpoint folder.
    checkpoint: PathBuf,
    /// The ONNX file to write.
    #[arg(short, long)]
    output: PathBuf,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let state = sinmdm_train::export::export_checkpoint(&args.checkpoint, &args.output)?;
    let size = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    eprintln!(
        "wrote {} ({:.1} MB): {} at step {}, F {}, C {}, loss {:.4}",
        args.output.display(),
        size as f64 / 1e6,
        state.clip.name,
        state.step,
        state.features,
        state.config.model.channels,
        state.recent_loss
    );
    Ok(())
}
