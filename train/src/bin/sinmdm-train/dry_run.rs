//! `sinmdm-train --dry-run`: what a new run would train, and why, without training.

use anyhow::{Result, bail};
use burn::module::Module;
use burn::tensor::Device;

use sinmdm_train::choose::clip_rule;
use sinmdm_train::clip::ClipData;
use sinmdm_train::clip::motion_span;
use sinmdm_train::{QnaUnet, TrainConfig};

use super::{Args, new_run_config};

/// Prints what a new run on the clip would train, and why.
pub(super) fn dry_run(args: &Args) -> Result<()> {
    let Some(clip) = &args.clip else {
        bail!("--dry-run needs a CLIP");
    };
    let config = new_run_config(args)?;
    let data = ClipData::load(clip, &config.data)?;
    let (config, rule, ladder, window_from_clip) = match clip_rule::apply(&config, &data) {
        Some(choice) => (
            choice.config,
            Some(choice.choices.lines()),
            choice.climb_ladder,
            choice.choices.window_from_clip(),
        ),
        None => (config, None, false, false),
    };
    let config = config.at_fps(data.facts.layout.fps);
    data.check_length(clip, config.model.receptive_field())?;
    let features = data.features.nrows();
    let model = QnaUnet::new(features, &config.model, &Device::flex());
    print_clip(clip, &data, &config);
    println!("root            {}", data.facts.root);
    println!("channels C      {}", config.model.channels);
    println!("parameters      {}", model.num_params());
    println!(
        "receptive field {} frames (QnA window {})",
        config.model.receptive_field(),
        config.model.window
    );
    print_motion_span(&data, &config, window_from_clip);
    print_rule(rule.as_deref());
    let shape = config.training.batch_shape(data.features.ncols());
    let window = match shape.window {
        Some(w) if w < data.features.ncols() => format!("random windows of {w} frames"),
        _ => "the whole clip".into(),
    };
    println!(
        "steps           {}{} (batch {} x {window})",
        if ladder { "up to " } else { "" },
        config.training.steps,
        shape.items
    );
    Ok(())
}

/// The clip as read: its source, up axis, cycle, features and feet.
fn print_clip(clip: &std::path::Path, data: &ClipData, config: &TrainConfig) {
    let features = data.features.nrows();
    println!(
        "clip            {} ({} frames at {} fps)",
        clip.display(),
        data.facts.frames,
        data.facts.layout.fps
    );
    if let Some(source) = &data.facts.source {
        println!(
            "source          {} animation {} (one of {})",
            source.format,
            source.animation.as_deref().unwrap_or("?"),
            source.animations
        );
    }
    if let Some(dropped) = &data.facts.dropped {
        println!("left out        {dropped}");
    }
    println!("up axis         {}", data.facts.up);
    if data.facts.in_place {
        println!("cycle           in place: contacts measured against the treadmill");
    }
    println!("features F      {features}");
    let layout = &data.facts.layout;
    let feet: Vec<&str> = layout
        .contact_joints
        .iter()
        .map(|&j| layout.skeleton.joints[j].name.as_str())
        .collect();
    println!(
        "feet            {} ({}): {}",
        feet.len(),
        feet.join(", "),
        if config.data.contact_joints.is_some() {
            "data.contact_joints in the config"
        } else {
            "the chain ends that touch the ground (data.contact_joints overrides)"
        }
    );
}

/// How long the clip's motion stays correlated, with a wider window's hint unless the rule chose
/// the window.
fn print_motion_span(data: &ClipData, config: &TrainConfig, window_from_clip: bool) {
    let fps = data.facts.layout.fps;
    match motion_span::decorrelation_frames(data.features.view(), fps) {
        Some(frames) => {
            println!(
                "motion span     {:.2} s (the lag at which the features' autocorrelation first falls below zero)",
                frames as f64 / fps
            );
            // The rule's window is chosen from the clip; a hint would second-guess it.
            let hint = (!window_from_clip)
                .then(|| motion_span::wider_window_hint(frames, fps, &config.model))
                .flatten();
            if let Some(hint) = hint {
                println!("hint            {hint}");
            }
        }
        None => println!("motion span     longer than half the clip or 10 s"),
    }
}

/// The rule's choices, one line each, or that it is off.
fn print_rule(rule: Option<&[String]>) {
    match rule {
        Some(lines) => {
            println!(
                "the rule that reads the clip (from_clip; --config, --window and --minutes override it):"
            );
            for line in lines {
                println!("  {line}");
            }
        }
        None => println!("from_clip       off: the configuration's numbers train as written"),
    }
}
