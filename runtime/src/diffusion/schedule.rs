//! The diffusion schedule (SPEC section 4): cosine noise levels over T steps, respacing to S
//! steps, and the coefficients of the forward process and of the posterior step. One
//! implementation, used by training and by every sampler.

use thiserror::Error;

/// The number of diffusion steps the models are trained with.
pub const DEFAULT_DIFFUSION_STEPS: usize = 1000;

/// The largest beta of the cosine schedule.
const MAX_BETA: f64 = 0.999;

/// A schedule that cannot be built.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ScheduleError {
    /// T must be at least 2.
    #[error("the diffusion needs at least 2 steps, got {0}")]
    TooFewSteps(usize),
    /// S must lie in 2..=T.
    #[error("sampling steps must be between 2 and {total}, got {asked}")]
    BadRespacing {
        /// Steps asked for.
        asked: usize,
        /// Steps of the trained schedule.
        total: usize,
    },
}

/// `abar(s) = cos^2(((s + 0.008) / 1.008) * pi / 2)` for `s` in [0, 1].
pub fn cosine_alpha_bar(s: f64) -> f64 {
    (((s + 0.008) / 1.008) * std::f64::consts::FRAC_PI_2)
        .cos()
        .powi(2)
}

/// A (possibly respaced) schedule. Index `k` is the `k`-th kept step, whose original timestep
/// (what the network is fed) is `timesteps[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// Original timestep of each kept step, increasing.
    pub timesteps: Vec<usize>,
    /// beta of each kept step.
    pub betas: Vec<f64>,
    /// abar after each kept step.
    pub alphas_cumprod: Vec<f64>,
    /// abar before each kept step (1 before the first).
    pub alphas_cumprod_prev: Vec<f64>,
}

impl Schedule {
    /// The full cosine schedule of `steps` steps:
    /// `beta_i = min(1 - abar((i + 1) / T) / abar(i / T), 0.999)`.
    pub fn cosine(steps: usize) -> Result<Schedule, ScheduleError> {
        if steps < 2 {
            return Err(ScheduleError::TooFewSteps(steps));
        }
        let t = steps as f64;
        let betas: Vec<f64> = (0..steps)
            .map(|i| {
                let ratio = cosine_alpha_bar((i + 1) as f64 / t) / cosine_alpha_bar(i as f64 / t);
                (1.0 - ratio).min(MAX_BETA)
            })
            .collect();
        Ok(Schedule::from_betas((0..steps).collect(), betas))
    }

    /// Keeps `kept` of the `steps` steps, `t_k = (2k(T-1) + (S-1)) div (2(S-1))`, with betas
    /// recomputed so the kept steps reach the same noise levels:
    /// `beta_k = 1 - abar(t_k) / abar(t_{k-1})`, `abar(t_{-1}) = 1`.
    pub fn respaced(steps: usize, kept: usize) -> Result<Schedule, ScheduleError> {
        let full = Schedule::cosine(steps)?;
        if kept < 2 || kept > steps {
            return Err(ScheduleError::BadRespacing {
                asked: kept,
                total: steps,
            });
        }
        if kept == steps {
            return Ok(full);
        }
        let (t1, s1) = (steps - 1, kept - 1);
        let timesteps: Vec<usize> = (0..kept).map(|k| (2 * k * t1 + s1) / (2 * s1)).collect();
        let mut previous = 1.0;
        let betas = timesteps
            .iter()
            .map(|&t| {
                let abar = full.alphas_cumprod[t];
                let beta = 1.0 - abar / previous;
                previous = abar;
                beta
            })
            .collect();
        Ok(Schedule::from_betas(timesteps, betas))
    }

    fn from_betas(timesteps: Vec<usize>, betas: Vec<f64>) -> Schedule {
        let mut alphas_cumprod = Vec::with_capacity(betas.len());
        let mut alphas_cumprod_prev = Vec::with_capacity(betas.len());
        let mut product = 1.0;
        for beta in &betas {
            alphas_cumprod_prev.push(product);
            product *= 1.0 - beta;
            alphas_cumprod.push(product);
        }
        Schedule {
            timesteps,
            betas,
            alphas_cumprod,
            alphas_cumprod_prev,
        }
    }

    /// Number of kept steps.
    pub fn len(&self) -> usize {
        self.betas.len()
    }

    /// Whether the schedule has no steps.
    pub fn is_empty(&self) -> bool {
        self.betas.is_empty()
    }

    /// `(sqrt(abar_k), sqrt(1 - abar_k))`: `x_t = a x0 + b eps`.
    pub fn q_sample_coefficients(&self, k: usize) -> (f64, f64) {
        let abar = self.alphas_cumprod[k];
        (abar.sqrt(), (1.0 - abar).sqrt())
    }

    /// `(c_x0, c_xt)` of the posterior mean `c_x0 x0hat + c_xt x_t` at step `k`.
    pub fn posterior_mean_coefficients(&self, k: usize) -> (f64, f64) {
        let (beta, abar, abar_prev) = (
            self.betas[k],
            self.alphas_cumprod[k],
            self.alphas_cumprod_prev[k],
        );
        (
            beta * abar_prev.sqrt() / (1.0 - abar),
            (1.0 - abar_prev) * (1.0 - beta).sqrt() / (1.0 - abar),
        )
    }

    /// The posterior variance `beta_k (1 - abar_{k-1}) / (1 - abar_k)`.
    pub fn posterior_variance(&self, k: usize) -> f64 {
        self.betas[k] * (1.0 - self.alphas_cumprod_prev[k]) / (1.0 - self.alphas_cumprod[k])
    }

    /// The standard deviation of the noise added at step `k` (`k > 0`): `exp(0.5 log var)`, with
    /// the log-variance of step 0 taken from step 1 as in the reference. No noise is added at
    /// step 0.
    pub fn posterior_std(&self, k: usize) -> f64 {
        let var = if k == 0 {
            self.posterior_variance(1.min(self.len() - 1))
        } else {
            self.posterior_variance(k)
        };
        (0.5 * var.ln()).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cumulative_product_telescopes_to_the_cosine_curve() {
        // Without clipping, prod (1 - beta_i) for i <= n is abar((n+1)/T) / abar(0).
        let s = Schedule::cosine(1000).unwrap();
        for n in [0, 1, 10, 500, 900, 980] {
            let want = cosine_alpha_bar((n + 1) as f64 / 1000.0) / cosine_alpha_bar(0.0);
            assert!((s.alphas_cumprod[n] - want).abs() < 1e-12, "{n}");
        }
        assert_eq!(*s.betas.last().unwrap(), 0.999);
        assert!(s.betas.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn respacing_keeps_the_documented_steps_and_noise_levels() {
        let full = Schedule::cosine(1000).unwrap();
        let s = Schedule::respaced(1000, 4).unwrap();
        // t_k = (2k * 999 + 3) div 6: 0, 333, 666, 999.
        assert_eq!(s.timesteps, vec![0, 333, 666, 999]);
        for (k, &t) in s.timesteps.iter().enumerate() {
            assert!((s.alphas_cumprod[k] - full.alphas_cumprod[t]).abs() < 1e-12);
        }
        assert_eq!(s.alphas_cumprod_prev[0], 1.0);
        assert_eq!(Schedule::respaced(1000, 1000).unwrap(), full);
        let fifty = Schedule::respaced(1000, 50).unwrap();
        assert_eq!(fifty.timesteps[1], 20); // (2 * 999 + 49) div 98 = 2047 div 98
        assert_eq!(*fifty.timesteps.last().unwrap(), 999);
    }

    #[test]
    fn posterior_coefficients_match_the_formulas_at_a_hand_checked_step() {
        let s = Schedule::cosine(1000).unwrap();
        let k = 500;
        let (beta, abar, prev) = (s.betas[k], s.alphas_cumprod[k], s.alphas_cumprod[k - 1]);
        let (c0, ct) = s.posterior_mean_coefficients(k);
        assert!((c0 - beta * prev.sqrt() / (1.0 - abar)).abs() < 1e-15);
        assert!((ct - (1.0 - prev) * (1.0 - beta).sqrt() / (1.0 - abar)).abs() < 1e-15);
        // A clean x_t (x_t = sqrt(abar) x0 with no noise) has a posterior mean of sqrt(prev) x0.
        assert!((c0 + ct * abar.sqrt() - prev.sqrt()).abs() < 1e-12);
        assert_eq!(s.posterior_std(0), s.posterior_std(1));
        assert!(s.posterior_variance(0) == 0.0);
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert_eq!(Schedule::cosine(1), Err(ScheduleError::TooFewSteps(1)));
        assert!(Schedule::respaced(1000, 1).is_err());
        assert!(Schedule::respaced(1000, 1001).is_err());
    }
}
