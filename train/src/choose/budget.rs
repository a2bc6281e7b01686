//! The timing probe: what one optimiser step costs on this machine, which a time budget
//! (`sinmdm-train --minutes`) turns into a step count.

use std::path::Path;
use std::time::Instant;

use burn::tensor::Device;

use crate::choose::clip_rule;
use crate::clip::ClipData;
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::run::Trainer;

/// Seconds one optimiser step of `config` on `clip` takes on `device`: the mean of `steps`
/// timed steps (after two untimed ones) of a throw-away run in a temporary folder, of the
/// network the rule that reads the clip chooses where `config` asks for it. The mean,
/// not the median: each step stretches the clip by its own random factor, and a budget is
/// spent on the sum of the steps, slow ones included. This is what a time budget
/// (`sinmdm-train --minutes`) turns into a step count.
pub fn seconds_per_step(
    clip: &Path,
    config: &TrainConfig,
    device: Device,
    steps: u64,
) -> Result<f64, TrainError> {
    let folder = std::env::temp_dir().join(format!("sinmdm-timing-probe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    let mut probe_config = config.clone();
    probe_config.training.steps = steps + 2;
    probe_config.training.warmup_steps = 0;
    probe_config.from_clip.steps = false;
    let measured = (|| {
        let data = ClipData::load(clip, &probe_config.data, &probe_config.model)?;
        let probe_config = match clip_rule::apply(&probe_config, &data) {
            Some(choice) => choice.config,
            None => probe_config,
        };
        let mut trainer = Trainer::start_chosen(clip, data, probe_config, None, &folder, device)?;
        let mut times = Vec::new();
        for i in 0..steps + 2 {
            let begun = Instant::now();
            trainer.step()?;
            if i >= 2 {
                times.push(begun.elapsed().as_secs_f64());
            }
        }
        Ok(times.iter().sum::<f64>() / times.len().max(1) as f64)
    })();
    let _ = std::fs::remove_dir_all(&folder);
    measured
}
