//! How fast a run goes: what the loop reports after each step (with the time the rest should
//! take), and the probe that turns a time budget into a step count.

use std::path::Path;
use std::time::Instant;

use burn::tensor::Device;

use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::recovery::RecoveryEvent;
use crate::trainer::Trainer;

/// What the loop reports after each step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Steps completed.
    pub step: u64,
    /// Steps configured.
    pub total: u64,
    /// This step's loss.
    pub loss: f64,
    /// Mean loss over the last 100 steps.
    pub recent_loss: f64,
    /// Learning rate used by this step.
    pub learning_rate: f64,
    /// Seconds of training so far, earlier sessions of a resumed run included.
    pub seconds: f64,
    /// What the trainer did about a non-finite step, when this step was one.
    pub event: Option<RecoveryEvent>,
}

impl StepReport {
    /// Seconds the remaining steps should take at the run's mean pace so far.
    pub fn seconds_left(&self) -> f64 {
        if self.step == 0 {
            return 0.0;
        }
        self.seconds / self.step as f64 * self.total.saturating_sub(self.step) as f64
    }
}

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

#[cfg(test)]
mod tests {
    use super::StepReport;

    fn report(step: u64, total: u64, seconds: f64) -> StepReport {
        StepReport {
            step,
            total,
            loss: 0.1,
            recent_loss: 0.1,
            learning_rate: 1e-4,
            seconds,
            event: None,
        }
    }

    #[test]
    fn time_left_follows_the_mean_pace() {
        // 100 steps in 60 s: 300 more take 180 s.
        assert_eq!(report(100, 400, 60.0).seconds_left(), 180.0);
        assert_eq!(report(400, 400, 240.0).seconds_left(), 0.0);
        assert_eq!(report(0, 400, 0.0).seconds_left(), 0.0);
    }
}
