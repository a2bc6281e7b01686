//! `sinmdm info` and `sinmdm encode`: what a model file holds, and a clip in a model's layout.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use ndarray::Axis;

use crate::sampling::reference_features;
use sinmdm::features_file::write_features;
use sinmdm::model_file::{MetadataError, ModelMetadata};
use sinmdm::{Model, ModelError, ModelOptions};

pub(crate) const INFO_EXAMPLES: &str = "Examples:
  sinmdm info onnx-models/walk.onnx
  sinmdm info onnx-models/walk.onnx --json > walk_metadata.json";

pub(crate) const ENCODE_EXAMPLES: &str = "Examples:
  sinmdm encode walk.bvh -m onnx-models/walk.onnx -o walk_features.json";

/// Arguments of `sinmdm info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The model file.
    pub model: PathBuf,
    /// Print the metadata as JSON instead of a summary.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `sinmdm encode`.
#[derive(Debug, Args)]
pub struct EncodeArgs {
    /// The clip: .bvh, .glb, .gltf or .fbx (same skeleton as the model).
    pub clip: PathBuf,
    /// The model whose feature layout to use.
    #[arg(short, long, value_name = "MODEL.onnx")]
    pub model: PathBuf,
    /// The features JSON to write.
    #[arg(short, long, value_name = "OUT.json")]
    pub output: PathBuf,
    #[command(flatten)]
    pub up: crate::clip_files::ClipUpArg,
}

/// A readable summary of a model's metadata.
pub fn describe(path: &std::path::Path, m: &ModelMetadata) -> String {
    let mut s = String::new();
    let n = &m.network;
    let l = &m.layout;
    let t = &m.training;
    // A file that failed validation is still described: a bad index shows as such.
    let joint_name = |j: usize| {
        l.skeleton
            .joints
            .get(j)
            .map_or("(no such joint)", |joint| joint.name.as_str())
    };
    let _ = writeln!(s, "model        {}", path.display());
    let _ = writeln!(
        s,
        "network      QnA-UNet, {} features, {} channels, {} heads, window {}, receptive field {} frames, {} parameters",
        n.features, n.channels, n.heads, n.window, n.receptive_field, n.parameters
    );
    let _ = writeln!(
        s,
        "diffusion    {} steps, {} schedule, predicts {}",
        m.diffusion.steps, m.diffusion.schedule, m.diffusion.prediction
    );
    let _ = writeln!(
        s,
        "skeleton     {} joints (root '{}'), height {:.3} file units",
        l.skeleton.len(),
        l.skeleton.joints.first().map_or("", |j| j.name.as_str()),
        l.skeleton_height
    );
    let _ = writeln!(s, "frame rate   {} fps", l.fps);
    let _ = writeln!(
        s,
        "up axis      {} (its clips are read and written {}-up; a file without the field is Y-up)",
        l.up, l.up
    );
    if let Some(root) = &l.root {
        let _ = writeln!(
            s,
            "root motion  joint '{}', axes {:?}, starts at {:?}, {} root layout",
            joint_name(root.joint),
            root.axes,
            root.start_position,
            root.layout()
        );
        if let Some(h) = &root.heading {
            let _ = writeln!(
                s,
                "facing       across '{}' (left) and '{}' (right), sides told by {:?}, smoothed over {} s",
                joint_name(h.left),
                joint_name(h.right),
                h.sides,
                h.smoothing
            );
        }
    }
    let contacts: Vec<&str> = l.contact_joints.iter().map(|&j| joint_name(j)).collect();
    let _ = writeln!(
        s,
        "contacts     {} (speed threshold {} heights/s)",
        if contacts.is_empty() {
            "none".to_string()
        } else {
            contacts.join(", ")
        },
        l.contact_speed_threshold
    );
    let _ = writeln!(
        s,
        "features     {} root, {} rotation joints x 6, {} position channels, {} contact labels",
        l.root.as_ref().map_or(0, |r| r.width()),
        l.rotation_joints.len(),
        l.position_channels.len(),
        l.contact_joints.len()
    );
    let _ = writeln!(
        s,
        "trained on   {} ({} frames, sha256 {})",
        t.clip, t.clip_frames, t.clip_sha256
    );
    if let Some(source) = &t.clip_source {
        let _ = writeln!(
            s,
            "clip source  {}, animation {} (one of {}){}",
            source.format,
            source.animation.as_deref().unwrap_or("?"),
            source.animations,
            source
                .file_unit_meters
                .map(|m| format!(", file unit {m} m, read as metres"))
                .unwrap_or_default()
        );
    }
    let _ = writeln!(
        s,
        "training     {} steps in {:.0} s, final loss {:.4e} (mean of last 100: {:.4e}), started {}",
        t.steps, t.seconds, t.final_loss, t.recent_loss, t.started
    );
    let _ = writeln!(s, "exported     {}", t.exported);
    let _ = writeln!(s, "config       {}", t.config);
    s
}

pub(crate) fn info(args: &InfoArgs) -> Result<()> {
    let show = |metadata: &ModelMetadata| -> Result<()> {
        if args.json {
            println!("{}", serde_json::to_string_pretty(metadata)?);
        } else {
            print!("{}", describe(&args.model, metadata));
        }
        Ok(())
    };
    match Model::open(&args.model, &ModelOptions { threads: Some(1) }) {
        Ok(model) => show(model.metadata()),
        Err(ModelError::Metadata(MetadataError::Invalid {
            problems, metadata, ..
        })) => {
            // Show what the file holds, then why it cannot be used.
            show(&metadata)?;
            eprintln!("{}: the metadata breaks these rules:", args.model.display());
            for problem in &problems {
                eprintln!("  - {problem}");
            }
            bail!(
                "{} is not a usable model ({} problems)",
                args.model.display(),
                problems.len()
            )
        }
        Err(e) => Err(e.into()),
    }
}

pub(crate) fn encode(args: &EncodeArgs) -> Result<()> {
    let model = Model::open(&args.model, &ModelOptions { threads: Some(1) })?;
    let features = reference_features(&model, &args.clip, &args.up)?;
    write_features(
        &args.output,
        &model.metadata().layout,
        features.insert_axis(Axis(0)).view(),
    )?;
    eprintln!("wrote {}", args.output.display());
    Ok(())
}
