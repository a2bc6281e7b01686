//! What the trainer does when a step goes non-finite, and the record it keeps of it.
//!
//! A step whose loss or any gradient is not finite changes nothing: its update is skipped (the
//! weights, the weight average and the optimiser's moments stay as they were) and the run goes
//! on with the next step's batch. When [`SKIPS_BEFORE_ROLLBACK`] such steps fall within
//! [`SKIP_WINDOW`] steps, the run rolls back to its last good checkpoint (or its start, before
//! the first one) and continues from there with the learning rate multiplied by
//! [`ROLLBACK_RATE_FACTOR`]. The record is saved in every checkpoint (and at once after a
//! roll-back), so a resumed run keeps the lowered rate and does not walk into the same failure
//! again. The run stops with an error only after [`MAX_ROLLBACKS`] roll-backs in a row that did
//! not reach a new checkpoint.

use serde::{Deserialize, Serialize};

/// Skipped steps within [`SKIP_WINDOW`] steps that make the run roll back.
pub const SKIPS_BEFORE_ROLLBACK: usize = 3;
/// Steps over which skipped steps are counted towards a roll-back.
pub const SKIP_WINDOW: u64 = 100;
/// The learning rate's factor at each roll-back.
pub const ROLLBACK_RATE_FACTOR: f64 = 0.5;
/// Roll-backs in a row, with no new checkpoint between them, after which the run stops.
pub const MAX_ROLLBACKS: u32 = 3;

/// Why a step's update was skipped.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NonFinite {
    /// The loss itself was NaN or infinite.
    Loss,
    /// The loss was finite but a gradient held NaN or infinity.
    Gradient,
}

impl std::fmt::Display for NonFinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NonFinite::Loss => "loss",
            NonFinite::Gradient => "gradient",
        })
    }
}

/// One thing the trainer did about a non-finite step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum RecoveryEvent {
    /// The update of step `step` (1-based, as in the loss log) was skipped.
    Skipped {
        /// The step.
        step: u64,
        /// What was not finite.
        cause: NonFinite,
    },
    /// At step `at`, the run went back to the checkpoint of step `to` with the learning rate
    /// scaled by `rate_scale` (all roll-backs so far multiplied together).
    RolledBack {
        /// The step at which the run gave up going forward.
        at: u64,
        /// The step it went back to (0: the start).
        to: u64,
        /// The configured learning rate's factor from then on.
        rate_scale: f64,
    },
}

impl std::fmt::Display for RecoveryEvent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RecoveryEvent::Skipped { step, cause } => {
                write!(f, "step {step}: non-finite {cause}, update skipped")
            }
            RecoveryEvent::RolledBack { at, to, rate_scale } => write!(
                f,
                "step {at}: repeated non-finite steps, rolled back to step {to} with the learning rate x{rate_scale}"
            ),
        }
    }
}

/// The run's record of non-finite steps (`recovery` in each checkpoint's `state.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecoveryRecord {
    /// Updates skipped so far.
    pub skipped_steps: u64,
    /// Roll-backs so far.
    pub rollbacks: u64,
    /// The factor on the configured learning rate (1 until a roll-back).
    pub rate_scale: f64,
    /// Every event, in order.
    pub events: Vec<RecoveryEvent>,
}

impl Default for RecoveryRecord {
    fn default() -> Self {
        RecoveryRecord {
            skipped_steps: 0,
            rollbacks: 0,
            rate_scale: 1.0,
            events: Vec::new(),
        }
    }
}

impl RecoveryRecord {
    /// Whether nothing ever went non-finite.
    pub fn is_clean(&self) -> bool {
        self.events.is_empty()
    }

    /// Records a skipped step and says whether the run should now roll back: whether
    /// [`SKIPS_BEFORE_ROLLBACK`] skips (this one included) fall within the last
    /// [`SKIP_WINDOW`] steps since the last roll-back.
    pub fn skip(&mut self, step: u64, cause: NonFinite) -> bool {
        self.skipped_steps += 1;
        self.events.push(RecoveryEvent::Skipped { step, cause });
        let recent = self
            .events
            .iter()
            .rev()
            .take_while(|e| !matches!(e, RecoveryEvent::RolledBack { .. }))
            .filter(
                |e| matches!(e, RecoveryEvent::Skipped { step: s, .. } if s + SKIP_WINDOW > step),
            )
            .count();
        recent >= SKIPS_BEFORE_ROLLBACK
    }

    /// Whether the run may roll back to step `to` once more: fewer than [`MAX_ROLLBACKS`]
    /// roll-backs went there before (checkpoints only move forward, so these were in a row).
    pub fn may_roll_back_to(&self, to: u64) -> bool {
        let before = self
            .events
            .iter()
            .filter(|e| matches!(e, RecoveryEvent::RolledBack { to: t, .. } if *t == to))
            .count();
        before < MAX_ROLLBACKS as usize
    }

    /// Records a roll-back from step `at` to step `to`, with the learning rate scaled down
    /// again, and returns the event.
    pub fn roll_back(&mut self, at: u64, to: u64) -> RecoveryEvent {
        self.rollbacks += 1;
        self.rate_scale *= ROLLBACK_RATE_FACTOR;
        let event = RecoveryEvent::RolledBack {
            at,
            to,
            rate_scale: self.rate_scale,
        };
        self.events.push(event);
        event
    }

    /// A one-line summary for logs and tables ("none" when clean).
    pub fn summary(&self) -> String {
        if self.is_clean() {
            return "none".into();
        }
        format!(
            "{} skipped step(s), {} roll-back(s), learning rate x{}",
            self.skipped_steps, self.rollbacks, self.rate_scale
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_skips_within_the_window_call_for_a_roll_back() {
        let mut record = RecoveryRecord::default();
        assert!(!record.skip(10, NonFinite::Gradient));
        assert!(!record.skip(50, NonFinite::Loss));
        // 10 is 100 steps before 110: out of the window.
        assert!(!record.skip(110, NonFinite::Gradient));
        assert!(record.skip(120, NonFinite::Gradient));
        assert!(record.may_roll_back_to(100));
        record.roll_back(120, 100);
        assert_eq!(record.rate_scale, 0.5);
        // Skips before the roll-back no longer count.
        assert!(!record.skip(121, NonFinite::Gradient));
        assert!(!record.skip(122, NonFinite::Gradient));
        assert!(record.skip(123, NonFinite::Gradient));
        assert_eq!(
            record.roll_back(123, 100),
            RecoveryEvent::RolledBack {
                at: 123,
                to: 100,
                rate_scale: 0.25
            }
        );
        assert_eq!(record.skipped_steps, 7);
        assert_eq!(record.rollbacks, 2);
        assert_eq!(
            record.summary(),
            "7 skipped step(s), 2 roll-back(s), learning rate x0.25"
        );
    }

    #[test]
    fn three_roll_backs_to_one_checkpoint_are_the_last() {
        let mut record = RecoveryRecord::default();
        for at in [10, 20, 30] {
            assert!(record.may_roll_back_to(5));
            record.roll_back(at, 5);
        }
        assert!(!record.may_roll_back_to(5));
        // A newer checkpoint may still be tried.
        assert!(record.may_roll_back_to(40));
    }

    #[test]
    fn the_record_reads_as_json_and_defaults_to_clean() {
        let mut record = RecoveryRecord::default();
        assert!(record.is_clean());
        assert_eq!(record.summary(), "none");
        record.skip(7, NonFinite::Loss);
        record.roll_back(9, 0);
        let json = serde_json::to_value(&record).unwrap();
        assert_eq!(json["events"][0]["event"], "skipped");
        assert_eq!(json["events"][0]["cause"], "loss");
        assert_eq!(json["events"][1]["event"], "rolled_back");
        assert_eq!(json["events"][1]["to"], 0);
        let back: RecoveryRecord = serde_json::from_value(json).unwrap();
        assert_eq!(back, record);
    }
}
