//! How fast a run goes: what the loop reports after each step, with the time the rest should
//! take.

use crate::run::recovery::RecoveryEvent;

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
