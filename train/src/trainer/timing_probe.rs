//! The timing probe: what one optimiser step costs on this machine, which a time budget
//! (`sinmdm-train --minutes`) turns into a step count.

use std::path::Path;
use std::time::Instant;

use burn::tensor::Device;

use super::Trainer;
use crate::config::TrainConfig;
use crate::error::TrainError;

/// Seconds one optimiser step of `config` on `clip` takes on `device`: the mean of `steps`
/// timed steps (after two untimed ones) of a throw-away run in a temporary folder. The mean,
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
        let mut trainer = Trainer::start(clip, probe_config, &folder, device)?;
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
