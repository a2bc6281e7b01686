//! How the learning rate moves over a run: the schedule a configuration names, and the rate
//! of each step under it.

use serde::{Deserialize, Serialize};

use super::TrainingConfig;

/// How the learning rate moves over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LrSchedule {
    /// Multiplied by `lr_decay` after every step.
    #[default]
    Exponential,
    /// A linear warm-up over `warmup_steps`, then half a cosine from `learning_rate` down to
    /// zero at `steps`.
    Cosine,
}

impl LrSchedule {
    pub(super) fn is_exponential(&self) -> bool {
        *self == LrSchedule::Exponential
    }
}

impl TrainingConfig {
    /// The learning rate of step `step` (counting from 0) under the `cosine` schedule.
    pub fn cosine_rate(&self, step: u64) -> f64 {
        let peak = self.learning_rate;
        if step < self.warmup_steps {
            return peak * (step + 1) as f64 / self.warmup_steps as f64;
        }
        let span = self.steps.saturating_sub(self.warmup_steps).max(1) as f64;
        let progress = ((step - self.warmup_steps) as f64 / span).min(1.0);
        0.5 * peak * (1.0 + (std::f64::consts::PI * progress).cos())
    }

    /// The learning rate of the first step.
    pub fn first_rate(&self) -> f64 {
        match self.lr_schedule {
            LrSchedule::Exponential => self.learning_rate,
            LrSchedule::Cosine => self.cosine_rate(0),
        }
    }

    /// The learning rate of the step after `completed` steps, given the rate of the last one.
    pub fn next_rate(&self, completed: u64, last: f64) -> f64 {
        match self.lr_schedule {
            LrSchedule::Exponential => last * self.lr_decay,
            LrSchedule::Cosine => self.cosine_rate(completed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TrainConfig;

    #[test]
    fn the_cosine_schedule_warms_up_then_falls_to_zero() {
        let mut t = TrainConfig::parse(include_str!("../../../configs/default.yaml"))
            .unwrap()
            .training;
        t.steps = 1100;
        t.warmup_steps = 100;
        t.learning_rate = 1.0;
        assert_eq!(t.lr_schedule, LrSchedule::Cosine);
        assert!((t.first_rate() - 0.01).abs() < 1e-12);
        assert!((t.cosine_rate(49) - 0.5).abs() < 1e-12);
        assert!((t.cosine_rate(100) - 1.0).abs() < 1e-12);
        // Half way through the cosine part: half the peak; a quarter: (1 + cos(pi/4)) / 2.
        assert!((t.cosine_rate(600) - 0.5).abs() < 1e-12);
        let quarter = 0.5 * (1.0 + std::f64::consts::FRAC_1_SQRT_2);
        assert!((t.cosine_rate(350) - quarter).abs() < 1e-12);
        assert!(t.cosine_rate(1100).abs() < 1e-12);
        assert!(t.cosine_rate(5000).abs() < 1e-12);
        // next_rate follows the formula, not the last rate.
        assert_eq!(t.next_rate(600, 123.0), t.cosine_rate(600));
        let mut e = t.clone();
        e.lr_schedule = LrSchedule::Exponential;
        e.lr_decay = 0.5;
        assert_eq!(e.first_rate(), 1.0);
        assert_eq!(e.next_rate(7, 0.25), 0.125);
    }
}
