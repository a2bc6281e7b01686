//! The rules a training configuration must follow, each refusal naming the key.

use super::{LrSchedule, TrainConfig};

impl TrainConfig {
    /// Checks every value; the error names the key.
    pub fn validate(&self) -> Result<(), String> {
        let m = &self.model;
        let t = &self.training;
        let positive = [
            ("model.channels", m.channels as f64),
            ("model.heads", m.heads as f64),
            ("model.window", m.window as f64),
            ("training.steps", t.steps as f64),
            ("training.batch_size", t.batch_size as f64),
            ("training.learning_rate", t.learning_rate),
            ("training.lr_decay", t.lr_decay),
            ("training.resample_min", t.resample_min),
            ("training.resample_max", t.resample_max),
            ("training.checkpoint_every", t.checkpoint_every as f64),
            ("data.contact_speed", self.data.contact_speed),
        ];
        for (key, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("{key} must be a positive number, got {value}"));
            }
        }
        // The network contract's shape rules, named by the config's keys.
        let shape = sinmdm::network::NetworkShape {
            features: 1,
            channels: m.channels,
            heads: m.heads,
            window: m.window,
        };
        if let Err(rule) = shape.check() {
            return Err(format!(
                "model (channels {}, heads {}, window {}): {rule}",
                m.channels, m.heads, m.window
            ));
        }
        if !(0.0..1.0).contains(&m.dropout) {
            return Err(format!(
                "model.dropout must be in [0, 1), got {}",
                m.dropout
            ));
        }
        if self.diffusion.steps < 2 {
            return Err(format!(
                "diffusion.steps must be at least 2, got {}",
                self.diffusion.steps
            ));
        }
        if t.lr_decay > 1.0 {
            return Err(format!(
                "training.lr_decay must be at most 1, got {}",
                t.lr_decay
            ));
        }
        if let Some(d) = t.ema_decay
            && !(d > 0.0 && d < 1.0)
        {
            return Err(format!(
                "training.ema_decay must be between 0 and 1 (exclusive) or null, got {d}"
            ));
        }
        if t.warmup_steps > 0 && t.lr_schedule != LrSchedule::Cosine {
            return Err("training.warmup_steps applies to lr_schedule: cosine only".into());
        }
        if t.warmup_steps >= t.steps {
            return Err(format!(
                "training.warmup_steps ({}) must be fewer than training.steps ({})",
                t.warmup_steps, t.steps
            ));
        }
        if !(self.data.std_floor.is_finite() && (0.0..1.0).contains(&self.data.std_floor)) {
            return Err(format!(
                "data.std_floor must be in [0, 1) (a share of the mean feature spread), got {}",
                self.data.std_floor
            ));
        }
        if !(t.weight_decay.is_finite() && t.weight_decay >= 0.0) {
            return Err(format!(
                "training.weight_decay must be zero or positive, got {}",
                t.weight_decay
            ));
        }
        if t.resample_min > t.resample_max {
            return Err(format!(
                "training.resample_min ({}) must not exceed training.resample_max ({})",
                t.resample_min, t.resample_max
            ));
        }
        if let Some(w) = t.frames_per_step
            && w < m.receptive_field()
        {
            return Err(format!(
                "training.frames_per_step must be at least the receptive field ({} frames), got {w}",
                m.receptive_field()
            ));
        }
        if let Some(fps) = self.data.fps
            && !(fps.is_finite() && fps > 0.0)
        {
            return Err(format!(
                "data.fps must be a positive number or null, got {fps}"
            ));
        }
        Ok(())
    }
}
