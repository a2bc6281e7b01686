//! A step that went non-finite: skipped, or, when skips repeat, the run rolled back to its
//! last good checkpoint with a lower learning rate; and the faults tests inject to cause it.

use std::time::Instant;

use super::{LOSS_LOG, StepReport, Trainer, fresh_parts, load_parts};
use crate::error::TrainError;
use crate::run::checkpoint::{self, CheckpointState};
use crate::run::loss_log::LossLog;
use crate::run::recovery::{NonFinite, RecoveryEvent, RecoveryRecord};

impl Trainer {
    /// A step whose update was skipped: recorded, then either passed over (its batch dropped,
    /// no row in the loss log) or, when skips repeat, the run rolled back.
    pub(super) fn skip(&mut self, loss: f64, cause: NonFinite) -> Result<StepReport, TrainError> {
        let learning_rate = self.state.learning_rate;
        let at = self.state.step + 1;
        if self.state.recovery.skip(at, cause) {
            let event = self.roll_back(at)?;
            return Ok(self.report(loss, learning_rate, Some(event)));
        }
        self.advance();
        let event = RecoveryEvent::Skipped { step: at, cause };
        Ok(self.report(loss, learning_rate, Some(event)))
    }

    /// Goes back to the last good checkpoint (or the start, before the first), lowers the
    /// learning rate, and saves that point with the record at once, so a resume starts from it.
    fn roll_back(&mut self, at: u64) -> Result<RecoveryEvent, TrainError> {
        let checkpoint = match &self.last_checkpoint {
            Some(dir) => Some(dir.clone()),
            None => checkpoint::latest(&self.run)?,
        };
        let target = match &checkpoint {
            Some(dir) => checkpoint::load_state(dir)?,
            None => CheckpointState {
                step: 0,
                learning_rate: self.state.config.training.first_rate(),
                loss: f64::NAN,
                recent_loss: f64::NAN,
                recovery: RecoveryRecord::default(),
                ..self.state.clone()
            },
        };
        let mut record = self.state.recovery.clone();
        if !record.may_roll_back_to(target.step) {
            return Err(TrainError::Unrecoverable {
                step: at,
                to: target.step,
                rollbacks: crate::run::recovery::MAX_ROLLBACKS,
                tried: record.summary(),
                last_checkpoint: checkpoint,
            });
        }
        let (model, average, optimizer) = match &checkpoint {
            Some(dir) => load_parts(dir, &target, &self.device)?,
            None => fresh_parts(&target.config, target.features, &self.device),
        };
        let event = record.roll_back(at, target.step);
        let elapsed = self.elapsed();
        self.state = CheckpointState {
            learning_rate: target.learning_rate / target.recovery.rate_scale * record.rate_scale,
            recovery: record,
            elapsed_seconds: elapsed,
            // The run's configuration as it is now: a resume may have raised its step count
            // since the checkpoint was written.
            config: self.state.config.clone(),
            ..target
        };
        self.model = Some(model);
        self.average = average;
        self.optimizer = optimizer;
        self.log = LossLog::resume(&self.run.join(LOSS_LOG), self.state.step)?;
        self.recent.clear();
        self.elapsed_before = elapsed;
        self.session_start = Instant::now();
        self.save()?;
        Ok(event)
    }

    /// Makes the gradients of the given steps (1-based, as in the loss log) NaN, once each: a
    /// test's stand-in for a numerical failure, met by the same checks.
    #[doc(hidden)]
    pub fn inject_non_finite_gradients(&mut self, steps: impl IntoIterator<Item = u64>) {
        self.injected_faults.extend(steps);
    }
}
