//! The time budget (`sinmdm-train --minutes`): the steps a run of the chosen network can train
//! in a number of minutes on this machine, from a timing probe.

use std::path::Path;
use std::time::Instant;

use burn::tensor::Device;

use crate::clip::ClipData;
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::run::Trainer;

/// Timed steps of the probe.
pub const PROBE_STEPS: u64 = 16;
/// Seconds kept back from a budget for checkpoints and the export.
pub const RESERVE_SECONDS: f64 = 5.0;
/// Share of a budget kept back for steps slower than the probe's.
pub const MARGIN: f64 = 0.06;

/// What a budget bought.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fitted {
    /// The steps that fit.
    pub steps: u64,
    /// Their warm-up: the configuration's, at most a tenth of the steps.
    pub warmup: u64,
    /// Seconds one step took in the probe.
    pub seconds_per_step: f64,
}

/// The steps of the final configuration `config` on the clip `data` (read from `clip`) that
/// end within `minutes` counted from `began`, on `device`. A rule that changes the network
/// has been applied already, so the probe times the network that trains.
pub fn fit(
    clip: &Path,
    data: &ClipData,
    config: &TrainConfig,
    device: Device,
    minutes: f64,
    began: Instant,
) -> Result<Fitted, TrainError> {
    let seconds_per_step = seconds_per_step(clip, data, config, device, PROBE_STEPS)?;
    let left = minutes * 60.0 - began.elapsed().as_secs_f64() - RESERVE_SECONDS;
    let steps = (left * (1.0 - MARGIN) / seconds_per_step).floor();
    if steps < 1.0 {
        return Err(TrainError::NoTimeToTrain {
            minutes,
            seconds_per_step,
        });
    }
    let steps = steps as u64;
    Ok(Fitted {
        steps,
        warmup: config.training.warmup_steps.min(steps / 10),
        seconds_per_step,
    })
}

/// Seconds one optimiser step of the final configuration `config` on the clip `data` (read from
/// `clip`) takes on `device`: the mean of `steps` timed steps (after two untimed ones) of a
/// throw-away run in a temporary folder. The mean, not the median: each step stretches the clip
/// by its own random factor, and a budget is spent on the sum of the steps, slow ones included.
pub fn seconds_per_step(
    clip: &Path,
    data: &ClipData,
    config: &TrainConfig,
    device: Device,
    steps: u64,
) -> Result<f64, TrainError> {
    let folder = std::env::temp_dir().join(format!("sinmdm-timing-probe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    let mut probe_config = config.clone();
    probe_config.training.steps = steps + 2;
    probe_config.training.warmup_steps = 0;
    let measured = (|| {
        let mut trainer =
            Trainer::start_chosen(clip, data.clone(), probe_config, None, &folder, device)?;
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
