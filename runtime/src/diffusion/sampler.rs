//! Ancestral DDPM sampling (SPEC section 4) with the two kinds of guidance of section 5
//! ([`Guidance`]), one step at a time ([`Sampler`]); `Plan::run` steps one to the end.
//!
//! One sampling run, with `S` kept steps and schedule index `k` running from `S - 1` down to 0
//! (`step = S - 1 - k` counts the steps done):
//! 1. `x = noise(seed, stream 0)`, shape `[B, F, N]`, row-major.
//! 2. `x0 = denoiser(x, t_k)` with the ORIGINAL timestep `t_k`; with a mask,
//!    `x0 = x0 * (1 - M) + y * M`.
//! 3. `x = c0 x0 + ct x`, plus `sigma_k * noise(seed, stream step + 1)` when `k > 0` and the
//!    step draws noise; the coefficients are the run's [`Method`]'s (ancestral by default), and
//!    a multistep method adds `c_prev x0_prev` (the previous step's guided `x0`) instead of noise:
//!    `x = (c0 x0 + ct x) + c_prev x0_prev`.
//! 4. Harmonization, unless the step is among the free final share:
//!    `x = x - up(down(x)) + up(down(a y + s noise(seed, stream 1_000_000 + step + 1)))`, with
//!    `(a, s)` the q-sample coefficients of index `k - 1`, and `(1, 0)` after the last step (so
//!    a free share of 0 makes the output's low-pass the content's).
//!
//! All arithmetic on features is f32 with coefficients computed in f64 and rounded once, in the
//! order written above, so the Python reference can reproduce it.

use ndarray::{Array3, ArrayView3, Zip};
use thiserror::Error;

pub use super::error::SamplerError;
pub use super::guidance::{Guidance, Harmonization, Inpainting, downsample, low_pass, upsample};
use super::method::Method;
use super::noise::{HARMONIZE_STREAM_BASE, INITIAL_NOISE_STREAM};
use super::noise_worker::{NoiseWorker, fill_noise};
use super::schedule::Schedule;

/// What runs the network: a trained model (`crate::Model`) or anything with its contract.
pub trait Denoiser {
    /// The error of one call.
    type Error;
    /// Feature rows F.
    fn features(&self) -> usize;
    /// Predicted clean features `[B, F, N]` from noisy `x_t` `[B, F, N]` at original timesteps
    /// `t` (one per batch row).
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, Self::Error>;
    /// [`Denoiser::denoise`] written into `out`, a buffer the caller reuses from call to call
    /// (any shape: a denoiser gives it the shape of `x_t`). The default calls `denoise` and
    /// replaces `out`; a denoiser that can write in place saves an allocation per step.
    fn denoise_into(
        &mut self,
        x_t: ArrayView3<'_, f32>,
        t: &[i64],
        out: &mut Array3<f32>,
    ) -> Result<(), Self::Error> {
        *out = self.denoise(x_t, t)?;
        Ok(())
    }
}

/// A sampling run in progress: noise drawn, steps taken one at a time by [`Sampler::step`].
///
/// Stepping to the end gives exactly what `Plan::run` gives (it is the same code), so a caller
/// can spread a run over frames of a game, report progress or stop early. It owns its schedule
/// and guidance (`Send + 'static`), so it can be kept across frames or moved to a worker.
pub struct Sampler {
    schedule: Schedule,
    guidance: Guidance,
    shape: (usize, usize, usize),
    x: Array3<f32>,
    done: usize,
    free: usize,
    noise: NoiseWorker,
    method: Method,
    /// The last step's guided clean prediction (read by multistep methods, and the partial
    /// result of a run finished early).
    x0_prev: Option<Array3<f32>>,
    /// The buffer the next step's prediction is written into (the one before last, reused).
    spare: Option<Array3<f32>>,
    /// Whether [`Sampler::begin_step`] has asked for the next step's noise.
    begun: bool,
}

impl std::fmt::Debug for Sampler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sampler")
            .field("shape", &self.shape)
            .field("done", &self.done)
            .field("steps", &self.schedule.len())
            .finish_non_exhaustive()
    }
}

impl Sampler {
    /// Draws the initial noise of `batch` samples of `features` rows and `frames` frames (the
    /// schedule and guidance are copied into the sampler).
    pub fn new(
        schedule: &Schedule,
        guidance: &Guidance,
        batch: usize,
        features: usize,
        frames: usize,
        seed: u64,
    ) -> Result<Sampler, SamplerError> {
        Sampler::build(schedule, guidance, (batch, features, frames), seed, true)
    }

    /// [`Sampler::new`] drawing each step's noise on the calling thread, the same values: for
    /// many runs on one thread (a crowd), where a worker thread per run would cost more than
    /// it overlaps.
    pub fn new_on_this_thread(
        schedule: &Schedule,
        guidance: &Guidance,
        batch: usize,
        features: usize,
        frames: usize,
        seed: u64,
    ) -> Result<Sampler, SamplerError> {
        Sampler::build(schedule, guidance, (batch, features, frames), seed, false)
    }

    fn build(
        schedule: &Schedule,
        guidance: &Guidance,
        (batch, features, frames): (usize, usize, usize),
        seed: u64,
        worker: bool,
    ) -> Result<Sampler, SamplerError> {
        if batch == 0 || frames == 0 {
            return Err(SamplerError::Empty { batch, frames });
        }
        guidance.check(features, frames)?;
        let shape = (batch, features, frames);
        let mut x = Array3::zeros(shape);
        fill_noise(seed, INITIAL_NOISE_STREAM, &mut x);
        let free = guidance
            .harmonization
            .as_ref()
            .map_or(0, |h| h.free_steps(schedule.len()));
        Ok(Sampler {
            schedule: schedule.clone(),
            guidance: guidance.clone(),
            shape,
            x,
            done: 0,
            free,
            // A step's noise does not depend on the network's output: it is drawn on the
            // worker while the network runs (for a crowd it costs a twentieth of a step).
            noise: if worker {
                NoiseWorker::start(seed, shape)
            } else {
                NoiseWorker::in_place(seed, shape)
            },
            begun: false,
            method: Method::Ancestral,
            x0_prev: None,
            spare: None,
        })
    }

    /// The same run with another update rule (ancestral until changed); only before the first
    /// step.
    pub fn with_method(mut self, method: Method) -> Result<Sampler, SamplerError> {
        if let Some(problem) = method.problem() {
            return Err(SamplerError::Method(problem));
        }
        self.method = method;
        Ok(self)
    }

    /// Steps taken.
    pub fn done(&self) -> usize {
        self.done
    }

    /// Steps in the whole run.
    pub fn steps(&self) -> usize {
        self.schedule.len()
    }

    /// Whether every step has been taken.
    pub fn is_finished(&self) -> bool {
        self.done >= self.schedule.len()
    }

    /// The current sample `x` `[B, F, N]`: noise at first, clean features once finished.
    pub fn current(&self) -> ArrayView3<'_, f32> {
        self.x.view()
    }

    /// The finished (or partly denoised) sample `[B, F, N]`.
    pub fn into_sample(self) -> Array3<f32> {
        self.x
    }

    /// The last step's guided clean prediction `[B, F, N]` (what the network expects the
    /// sample to become; masks applied); `None` before the first step. Once the run is
    /// finished, [`Sampler::into_sample`] is the result.
    pub fn latest_prediction(&self) -> Option<ArrayView3<'_, f32>> {
        self.x0_prev.as_ref().map(|x0| x0.view())
    }

    /// Takes one denoising step; does nothing once finished. On a denoiser error the sample is
    /// left as it was before the step.
    pub fn step<D: Denoiser>(&mut self, denoiser: &mut D) -> Result<(), StepError<D::Error>> {
        if self.is_finished() {
            return Ok(());
        }
        let (batch, features, _) = self.shape;
        if denoiser.features() != features {
            return Err(StepError::Setup(SamplerError::Features {
                denoiser: denoiser.features(),
                run: features,
            }));
        }
        let Some(t) = self.begin_step() else {
            return Ok(());
        };
        let mut x0 = self
            .spare
            .take()
            .unwrap_or_else(|| Array3::zeros(self.shape));
        if let Err(e) = denoiser.denoise_into(self.x.view(), &vec![t; batch], &mut x0) {
            self.abandon_step();
            return Err(StepError::Denoiser(e));
        }
        self.complete_step(x0).map_err(StepError::Setup)
    }

    /// Starts the next step where the caller runs the network itself (a crowd batching many
    /// runs into one call): asks for the step's noise and gives the original timestep at which
    /// to denoise [`Sampler::current`]; `None` once finished. Calling it again before
    /// [`Sampler::finish_step`] or [`Sampler::abandon_step`] starts nothing new.
    pub fn begin_step(&mut self) -> Option<i64> {
        if self.is_finished() {
            return None;
        }
        let k = self.schedule.len() - 1 - self.done;
        if !self.begun {
            let (noisy, harmonizing) = self.draws(k);
            if noisy {
                self.noise.request(self.done as u64 + 1);
            }
            if k > 0 && harmonizing {
                self.noise
                    .request(HARMONIZE_STREAM_BASE + self.done as u64 + 1);
            }
            self.begun = true;
        }
        Some(self.schedule.timesteps[k] as i64)
    }

    /// Ends the step [`Sampler::begin_step`] started with the network's clean prediction `x0`
    /// `[B, F, N]`: the same update [`Sampler::step`] makes (it is the same code).
    pub fn finish_step(&mut self, x0: ArrayView3<'_, f32>) -> Result<(), SamplerError> {
        if !self.begun {
            return Err(SamplerError::StepNotBegun);
        }
        let mut buffer = match self.spare.take() {
            Some(b) if b.dim() == x0.dim() => b,
            _ => Array3::zeros(x0.dim()),
        };
        buffer.assign(&x0);
        self.complete_step(buffer)
    }

    /// Gives up the step [`Sampler::begin_step`] started (the network failed): the sample stays
    /// as it was before the step, and the step can be begun again.
    pub fn abandon_step(&mut self) {
        if !self.begun {
            return;
        }
        let k = self.schedule.len() - 1 - self.done;
        let (noisy, harmonizing) = self.draws(k);
        for _ in 0..usize::from(noisy) + usize::from(k > 0 && harmonizing) {
            if let Some(noise) = self.noise.receive() {
                self.noise.recycle(noise);
            }
        }
        self.begun = false;
    }

    /// Whether step index `k` draws the update's noise, and whether it harmonizes.
    fn draws(&self, k: usize) -> (bool, bool) {
        let steps = self.schedule.len();
        let harmonizing = self.guidance.harmonization.is_some() && self.done < steps - self.free;
        let c = self.method.coefficients(&self.schedule, k);
        (k > 0 && c.sigma > 0.0, harmonizing)
    }

    /// The update of a begun step from the network's clean prediction `x0`.
    fn complete_step(&mut self, mut x0: Array3<f32>) -> Result<(), SamplerError> {
        let (_, features, frames) = self.shape;
        let k = self.schedule.len() - 1 - self.done;
        let (noisy_step, harmonizing) = self.draws(k);
        let c = self.method.coefficients(&self.schedule, k);
        let eps = if noisy_step {
            self.noise.receive()
        } else {
            None
        };
        let harmonize_eps = if k > 0 && harmonizing {
            self.noise.receive()
        } else {
            None
        };
        self.begun = false;
        if x0.dim() != self.shape {
            return Err(SamplerError::Shape {
                what: "denoiser's output",
                got: (x0.dim().1, x0.dim().2),
                features,
                frames,
            });
        }
        self.guide_prediction(&mut x0);
        let (c0, ct) = (c.x0 as f32, c.xt as f32);
        match (eps, &self.x0_prev) {
            (Some(eps), _) => {
                let sigma = c.sigma as f32;
                Zip::from(&mut self.x)
                    .and(&x0)
                    .and(&eps)
                    .for_each(|x, &p, &e| *x = (c0 * p + ct * *x) + sigma * e);
                self.noise.recycle(eps);
            }
            (None, Some(prev)) if c.x0_prev != 0.0 => {
                let cp = c.x0_prev as f32;
                Zip::from(&mut self.x)
                    .and(&x0)
                    .and(prev)
                    .for_each(|x, &p, &q| *x = (c0 * p + ct * *x) + cp * q);
            }
            (None, _) => Zip::from(&mut self.x)
                .and(&x0)
                .for_each(|x, &p| *x = c0 * p + ct * *x),
        }
        self.spare = self.x0_prev.replace(x0);
        if harmonizing {
            self.harmonize(k, harmonize_eps);
        }
        self.done += 1;
        Ok(())
    }

    /// Steering, then the inpainting mask, on the network's clean prediction `x0`.
    fn guide_prediction(&self, x0: &mut Array3<f32>) {
        if let Some(steer) = &self.guidance.steering {
            for row in x0.outer_iter_mut() {
                steer.apply(row);
            }
        }
        if let Some(inpaint) = &self.guidance.inpainting {
            for mut row in x0.outer_iter_mut() {
                Zip::from(&mut row)
                    .and(&inpaint.mask)
                    .and(&inpaint.reference)
                    .for_each(|p, &m, &y| *p = *p * (1.0 - m) + y * m);
            }
        }
    }

    /// Harmonization after step `k`: the sample's low frequencies replaced by the content's,
    /// noised to the next step's level with `eps` (none after the last step: the sample is
    /// clean, so the target is the clean content).
    fn harmonize(&mut self, k: usize, eps: Option<Array3<f32>>) {
        let Some(h) = &self.guidance.harmonization else {
            return;
        };
        // After the last step the sample is clean, so the target is the clean content.
        let (a, s) = if k > 0 {
            self.schedule.q_sample_coefficients(k - 1)
        } else {
            (1.0, 0.0)
        };
        let (a, s) = (a as f32, s as f32);
        let mut noisy = eps.unwrap_or_else(|| Array3::zeros(self.shape));
        for mut row in noisy.outer_iter_mut() {
            Zip::from(&mut row)
                .and(&h.content)
                .for_each(|e, &y| *e = a * y + s * *e);
        }
        let ours = low_pass(self.x.view(), h.factor);
        let theirs = low_pass(noisy.view(), h.factor);
        Zip::from(&mut self.x)
            .and(&ours)
            .and(&theirs)
            .for_each(|x, &o, &c| *x = *x - o + c);
        self.noise.recycle(noisy);
    }
}

/// Why a step failed: the run's setup, or the denoiser.
#[derive(Debug, Error)]
pub enum StepError<E> {
    /// The run and the denoiser do not fit.
    #[error(transparent)]
    Setup(#[from] SamplerError),
    /// The denoiser failed.
    #[error("the denoiser failed")]
    Denoiser(E),
}
