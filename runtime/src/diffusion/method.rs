//! How a sampling step moves from `x_t` to the next, less noisy sample, given the network's
//! clean prediction `x0`: every method here is one update
//!
//! `x_next = c_x0 x0 + c_xt x_t + c_prev x0_prev + sigma noise`
//!
//! with coefficients from the (respaced) schedule, so masks (applied to `x0`) and
//! harmonization (applied to `x_next`) work the same with each. Writing `a = abar_k` and
//! `p = abar_{k-1}` (1 after the last step):
//! - [`Method::Ancestral`]: the DDPM posterior (SPEC section 4), `sigma` its standard deviation.
//! - [`Method::Ddim`] with `eta`: `sigma = eta sqrt((1 - p) / (1 - a)) sqrt(1 - a / p)`,
//!   `c_xt = sqrt(1 - p - sigma^2) / sqrt(1 - a)`, `c_x0 = sqrt(p) - c_xt sqrt(a)`; `eta = 0` is
//!   deterministic, `eta = 1` close to ancestral.
//! - [`Method::DpmSolver2M`]: DPM-Solver++(2M), deterministic and second order in the
//!   log-SNR `lambda = ln(sqrt(a) / sqrt(1 - a))`: with `h = lambda_p - lambda_a`,
//!   `c_xt = sqrt(1 - p) / sqrt(1 - a)` and `m = sqrt(p) (1 - e^-h)`; the first step (no
//!   earlier prediction) and the last (to the clean sample) are first order (`c_x0 = m`), the
//!   others use `r = h_prev / h`: `c_x0 = m (1 + 1 / 2r)`, `c_prev = -m / 2r`.

use super::schedule::Schedule;

/// The update rule of each sampling step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Method {
    /// Ancestral DDPM: the posterior mean plus its noise (the paper's sampler).
    #[default]
    Ancestral,
    /// DDIM with noise scale `eta` in `[0, 1]` (0: deterministic).
    Ddim {
        /// Share of the ancestral noise kept.
        eta: f64,
    },
    /// DPM-Solver++(2M): deterministic, second-order multistep.
    DpmSolver2M,
}

/// One step's coefficients (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCoefficients {
    /// Of the (guided) clean prediction of this step.
    pub x0: f64,
    /// Of the current sample.
    pub xt: f64,
    /// Of the previous step's (guided) clean prediction.
    pub x0_prev: f64,
    /// Of fresh noise (0: none is drawn).
    pub sigma: f64,
}

impl Method {
    /// Why the method cannot run, if it cannot.
    pub fn problem(&self) -> Option<String> {
        match self {
            Method::Ddim { eta } if !(0.0..=1.0).contains(eta) => {
                Some(format!("DDIM's eta must be between 0 and 1, got {eta}"))
            }
            _ => None,
        }
    }

    /// A short name for tables and messages (`ancestral`, `ddim`, `ddim-eta0.5`, `dpm2m`).
    pub fn name(&self) -> String {
        match self {
            Method::Ancestral => "ancestral".into(),
            Method::Ddim { eta } if *eta == 0.0 => "ddim".into(),
            Method::Ddim { eta } => format!("ddim-eta{eta}"),
            Method::DpmSolver2M => "dpm2m".into(),
        }
    }

    /// The coefficients of step index `k` (counting down from `schedule.len() - 1`).
    pub fn coefficients(&self, schedule: &Schedule, k: usize) -> StepCoefficients {
        let a = schedule.alphas_cumprod[k];
        let p = schedule.alphas_cumprod_prev[k];
        match self {
            Method::Ancestral => {
                let (x0, xt) = schedule.posterior_mean_coefficients(k);
                StepCoefficients {
                    x0,
                    xt,
                    x0_prev: 0.0,
                    sigma: if k > 0 {
                        schedule.posterior_std(k)
                    } else {
                        0.0
                    },
                }
            }
            Method::Ddim { eta } => {
                let sigma = if k > 0 {
                    eta * ((1.0 - p) / (1.0 - a)).sqrt() * (1.0 - a / p).sqrt()
                } else {
                    0.0
                };
                let xt = (1.0 - p - sigma * sigma).max(0.0).sqrt() / (1.0 - a).sqrt();
                StepCoefficients {
                    x0: p.sqrt() - xt * a.sqrt(),
                    xt,
                    x0_prev: 0.0,
                    sigma,
                }
            }
            Method::DpmSolver2M => {
                let last = schedule.len() - 1;
                if k == 0 {
                    // To the clean sample: first order, which is x0 itself.
                    return StepCoefficients {
                        x0: 1.0,
                        xt: 0.0,
                        x0_prev: 0.0,
                        sigma: 0.0,
                    };
                }
                let lambda = |abar: f64| 0.5 * (abar / (1.0 - abar)).ln();
                let h = lambda(p) - lambda(a);
                let m = p.sqrt() * (1.0 - (-h).exp());
                let xt = ((1.0 - p) / (1.0 - a)).sqrt();
                if k == last {
                    return StepCoefficients {
                        x0: m,
                        xt,
                        x0_prev: 0.0,
                        sigma: 0.0,
                    };
                }
                let before = schedule.alphas_cumprod[k + 1];
                let r = (lambda(a) - lambda(before)) / h;
                StepCoefficients {
                    x0: m * (1.0 + 0.5 / r),
                    xt,
                    x0_prev: -m * 0.5 / r,
                    sigma: 0.0,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The update applied to a sample that is exactly `a x0 + b eps` with the true x0 (and the
    /// same x0 before): a deterministic method must land on the same x0 and eps at the next
    /// noise level.
    fn lands_on_the_next_level(method: Method) {
        let schedule = Schedule::respaced(1000, 20).unwrap();
        let (x0, eps) = (0.7, -1.3);
        for k in (1..schedule.len()).rev() {
            let c = method.coefficients(&schedule, k);
            let (a, b) = schedule.q_sample_coefficients(k);
            let x = a * x0 + b * eps;
            let next = c.x0 * x0 + c.xt * x + c.x0_prev * x0;
            let (a, b) = schedule.q_sample_coefficients(k - 1);
            let want = a * x0 + b * eps;
            assert!(
                (next - want).abs() < 1e-9,
                "{method:?} k {k}: {next} vs {want}"
            );
            assert_eq!(c.sigma, 0.0);
        }
        let last = method.coefficients(&schedule, 0);
        assert!((last.x0 + last.x0_prev - 1.0).abs() < 1e-12 && last.xt.abs() < 1e-12);
    }

    #[test]
    fn deterministic_methods_follow_the_forward_process_exactly() {
        lands_on_the_next_level(Method::Ddim { eta: 0.0 });
        lands_on_the_next_level(Method::DpmSolver2M);
    }

    #[test]
    fn ddim_with_full_noise_has_the_ancestral_variance() {
        // eta = 1 gives sigma^2 = (1 - p) / (1 - a) (1 - a / p) = the posterior variance.
        let schedule = Schedule::respaced(1000, 50).unwrap();
        for k in 1..schedule.len() {
            let c = Method::Ddim { eta: 1.0 }.coefficients(&schedule, k);
            let want = schedule.posterior_variance(k);
            assert!(
                (c.sigma * c.sigma - want).abs() < 1e-12 * want.max(1.0),
                "{k}"
            );
            let (m0, mt) = schedule.posterior_mean_coefficients(k);
            assert!((c.x0 - m0).abs() < 1e-9 && (c.xt - mt).abs() < 1e-9, "{k}");
        }
    }

    #[test]
    fn eta_outside_zero_to_one_is_refused() {
        assert!(Method::Ddim { eta: 1.5 }.problem().is_some());
        assert!(Method::Ddim { eta: f64::NAN }.problem().is_some());
        assert!(Method::Ddim { eta: 0.3 }.problem().is_none());
    }
}
