//! Ancestral DDPM sampling (SPEC section 4) with the two kinds of guidance of section 5:
//! blending the prediction with a reference through a mask (in-betweening, expansion,
//! composition) and replacing the low frequencies of the sample (harmonization).
//!
//! One sampling run, with `S` kept steps and schedule index `k` running from `S - 1` down to 0
//! (`step = S - 1 - k` counts the steps done):
//! 1. `x = noise(seed, stream 0)`, shape `[B, F, N]`, row-major.
//! 2. `x0 = denoiser(x, t_k)` with the ORIGINAL timestep `t_k`; with a mask,
//!    `x0 = x0 * (1 - M) + y * M`.
//! 3. `x = c0 x0 + ct x`, plus `sigma_k * noise(seed, stream step + 1)` when `k > 0`.
//! 4. Harmonization, unless the step is among the free final share:
//!    `x = x - up(down(x)) + up(down(a y + s noise(seed, stream 1_000_000 + step + 1)))`, with
//!    `(a, s)` the q-sample coefficients of index `k - 1`, and `(1, 0)` after the last step (so
//!    a free share of 0 makes the output's low-pass the content's).
//!
//! All arithmetic on features is f32 with coefficients computed in f64 and rounded once, in the
//! order written above, so the Python reference can reproduce it.

use std::sync::mpsc;

use ndarray::{Array2, Array3, ArrayView3, Axis, Zip};

use super::noise::{HARMONIZE_STREAM_BASE, INITIAL_NOISE_STREAM, fill_normals};
use super::schedule::Schedule;

/// What runs the network: a trained model (`crate::model::Model`) or anything with its contract.
pub trait Denoiser {
    /// The error of one call.
    type Error;
    /// Feature rows F.
    fn features(&self) -> usize;
    /// Predicted clean features `[B, F, N]` from noisy `x_t` at original timesteps `t`.
    fn denoise(&mut self, x_t: ArrayView3<'_, f32>, t: &[i64]) -> Result<Array3<f32>, Self::Error>;
}

/// Keep parts of a clean reference: `x0 <- x0 (1 - M) + y M` at every step.
#[derive(Debug, Clone, PartialEq)]
pub struct Inpainting {
    /// Normalised reference features `[F, N]` (any values where the mask is 0).
    pub reference: Array2<f32>,
    /// Mask `[F, N]` in `[0, 1]`: 1 keeps the reference, 0 generates.
    pub mask: Array2<f32>,
}

/// Replace the low frequencies of the sample with those of a content clip.
#[derive(Debug, Clone, PartialEq)]
pub struct Harmonization {
    /// Normalised content features `[F, N]`.
    pub content: Array2<f32>,
    /// Down-sampling factor of the low-pass (2 averages frame pairs).
    pub factor: usize,
    /// Share of the final steps left free of the low-pass replacement (the paper's ~2 %).
    pub free_share: f64,
}

impl Harmonization {
    /// Number of final steps of `steps` that run without the replacement.
    pub fn free_steps(&self, steps: usize) -> usize {
        (self.free_share * steps as f64).round() as usize
    }
}

/// Everything that steers a sampling run away from plain generation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Guidance {
    /// Mask blending of the prediction.
    pub inpainting: Option<Inpainting>,
    /// Low-frequency replacement after each step.
    pub harmonization: Option<Harmonization>,
}

/// The average of each group of `factor` frames along the last axis (the last group may be
/// shorter): `[.., N]` to `[.., ceil(N / factor)]`.
pub fn downsample(x: ArrayView3<'_, f32>, factor: usize) -> Array3<f32> {
    let (b, f, n) = x.dim();
    let m = n.div_ceil(factor);
    let mut out = Array3::<f32>::zeros((b, f, m));
    Zip::from(out.lanes_mut(Axis(2)))
        .and(x.lanes(Axis(2)))
        .for_each(|mut out, x| {
            for j in 0..m {
                let group = j * factor..((j + 1) * factor).min(n);
                let count = group.len() as f32;
                let mut sum = 0f32;
                for i in group {
                    sum += x[i];
                }
                out[j] = sum / count;
            }
        });
    out
}

/// Linear interpolation back to `n` frames from `[.., M]` made by [`downsample`] with `factor`:
/// frame `i` reads position `u = (i + 0.5) / factor - 0.5`, clamped to `[0, M - 1]`.
pub fn upsample(z: ArrayView3<'_, f32>, factor: usize, n: usize) -> Array3<f32> {
    let (b, f, m) = z.dim();
    let taps: Vec<(usize, usize, f32)> = (0..n)
        .map(|i| {
            let u = ((i as f64 + 0.5) / factor as f64 - 0.5).clamp(0.0, (m - 1) as f64);
            let i0 = u.floor() as usize;
            let i1 = (i0 + 1).min(m - 1);
            (i0, i1, (u - i0 as f64) as f32)
        })
        .collect();
    let mut out = Array3::<f32>::zeros((b, f, n));
    Zip::from(out.lanes_mut(Axis(2)))
        .and(z.lanes(Axis(2)))
        .for_each(|mut out, z| {
            for (i, &(i0, i1, w)) in taps.iter().enumerate() {
                out[i] = z[i0] * (1.0 - w) + z[i1] * w;
            }
        });
    out
}

/// The low-pass of SPEC section 5: `up(down(x))`.
pub fn low_pass(x: ArrayView3<'_, f32>, factor: usize) -> Array3<f32> {
    upsample(downsample(x, factor).view(), factor, x.dim().2)
}

/// Normals of one noise stream, shaped `[B, F, N]`.
fn noise(seed: u64, stream: u64, shape: (usize, usize, usize)) -> Array3<f32> {
    let mut out = Array3::<f32>::zeros(shape);
    fill_noise(seed, stream, &mut out);
    out
}

fn fill_noise(seed: u64, stream: u64, out: &mut Array3<f32>) {
    fill_normals(
        seed,
        stream,
        out.as_slice_mut().expect("noise buffers are contiguous"),
    );
}

/// A thread that draws noise streams into recycled buffers while the network runs, so a step
/// neither spawns a thread nor allocates.
struct NoiseWorker {
    requests: mpsc::Sender<(u64, Array3<f32>)>,
    filled: mpsc::Receiver<Array3<f32>>,
    spare: Vec<Array3<f32>>,
    shape: (usize, usize, usize),
}

impl NoiseWorker {
    fn start<'scope>(
        scope: &'scope std::thread::Scope<'scope, '_>,
        seed: u64,
        shape: (usize, usize, usize),
    ) -> NoiseWorker {
        let (requests, jobs) = mpsc::channel::<(u64, Array3<f32>)>();
        let (done, filled) = mpsc::channel();
        scope.spawn(move || {
            for (stream, mut buffer) in jobs {
                fill_noise(seed, stream, &mut buffer);
                if done.send(buffer).is_err() {
                    break;
                }
            }
        });
        NoiseWorker {
            requests,
            filled,
            spare: Vec::new(),
            shape,
        }
    }

    /// Asks for stream `stream`; results come back in the order asked.
    fn request(&mut self, stream: u64) {
        let buffer = self
            .spare
            .pop()
            .unwrap_or_else(|| Array3::zeros(self.shape));
        self.requests
            .send((stream, buffer))
            .expect("the noise thread runs until the worker is dropped");
    }

    /// The oldest stream asked for.
    fn receive(&mut self) -> Array3<f32> {
        self.filled
            .recv()
            .expect("the noise thread answers every request")
    }

    /// Gives a buffer back for reuse.
    fn recycle(&mut self, buffer: Array3<f32>) {
        self.spare.push(buffer);
    }
}

/// Runs the sampling loop for `batch` samples of `frames` frames; returns normalised features
/// `[B, F, N]`. `progress` is called after each step with (steps done, steps in all).
///
/// # Panics
/// If a guidance array is not `[F, frames]`, or a harmonization factor is 0.
pub fn sample<D: Denoiser>(
    denoiser: &mut D,
    schedule: &Schedule,
    batch: usize,
    frames: usize,
    seed: u64,
    guidance: &Guidance,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Array3<f32>, D::Error> {
    let f = denoiser.features();
    let shape = (batch, f, frames);
    if let Some(inpaint) = &guidance.inpainting {
        assert_eq!(inpaint.reference.dim(), (f, frames), "reference shape");
        assert_eq!(inpaint.mask.dim(), (f, frames), "mask shape");
    }
    if let Some(h) = &guidance.harmonization {
        assert_eq!(h.content.dim(), (f, frames), "content shape");
        assert!(h.factor >= 1, "harmonization factor must be at least 1");
    }
    let steps = schedule.len();
    let free = guidance
        .harmonization
        .as_ref()
        .map_or(0, |h| h.free_steps(steps));
    let mut x = noise(seed, INITIAL_NOISE_STREAM, shape);
    std::thread::scope(|scope| {
        // A step's noise does not depend on the network's output: it is drawn on the worker
        // while the network runs (for a crowd it costs as much as a twentieth of a step).
        let mut worker = NoiseWorker::start(scope, seed, shape);
        for step in 0..steps {
            let k = steps - 1 - step;
            let t = vec![schedule.timesteps[k] as i64; batch];
            let harmonizing = guidance.harmonization.is_some() && step < steps - free;
            if k > 0 {
                worker.request(step as u64 + 1);
                if harmonizing {
                    worker.request(HARMONIZE_STREAM_BASE + step as u64 + 1);
                }
            }
            let x0 = denoiser.denoise(x.view(), &t);
            let eps = (k > 0).then(|| worker.receive());
            let harmonize_eps = (k > 0 && harmonizing).then(|| worker.receive());
            let mut x0 = x0?;
            if let Some(inpaint) = &guidance.inpainting {
                for mut row in x0.outer_iter_mut() {
                    Zip::from(&mut row)
                        .and(&inpaint.mask)
                        .and(&inpaint.reference)
                        .for_each(|p, &m, &y| *p = *p * (1.0 - m) + y * m);
                }
            }
            let (c0, ct) = schedule.posterior_mean_coefficients(k);
            let (c0, ct) = (c0 as f32, ct as f32);
            match eps {
                Some(eps) => {
                    let sigma = schedule.posterior_std(k) as f32;
                    Zip::from(&mut x)
                        .and(&x0)
                        .and(&eps)
                        .for_each(|x, &p, &e| *x = (c0 * p + ct * *x) + sigma * e);
                    worker.recycle(eps);
                }
                None => Zip::from(&mut x)
                    .and(&x0)
                    .for_each(|x, &p| *x = c0 * p + ct * *x),
            }
            if let Some(h) = &guidance.harmonization
                && step < steps - free
            {
                // After the last step the sample is clean, so the target is the clean content.
                let (a, s) = if k > 0 {
                    schedule.q_sample_coefficients(k - 1)
                } else {
                    (1.0, 0.0)
                };
                let (a, s) = (a as f32, s as f32);
                let mut noisy = harmonize_eps.unwrap_or_else(|| Array3::zeros(shape));
                for mut row in noisy.outer_iter_mut() {
                    Zip::from(&mut row)
                        .and(&h.content)
                        .for_each(|e, &y| *e = a * y + s * *e);
                }
                let ours = low_pass(x.view(), h.factor);
                let theirs = low_pass(noisy.view(), h.factor);
                Zip::from(&mut x)
                    .and(&ours)
                    .and(&theirs)
                    .for_each(|x, &o, &c| *x = *x - o + c);
                worker.recycle(noisy);
            }
            progress(step + 1, steps);
        }
        Ok(x)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array3;

    #[test]
    fn low_pass_keeps_linear_ramps_and_constants() {
        let n = 9;
        let x = Array3::from_shape_fn(
            (1, 2, n),
            |(_, r, i)| {
                if r == 0 { 3.0 } else { 0.5 * i as f32 }
            },
        );
        let y = low_pass(x.view(), 2);
        for i in 0..n {
            assert!((y[[0, 0, i]] - 3.0).abs() < 1e-6);
        }
        // Interior frames of a ramp survive averaging and linear interpolation exactly; the
        // clamped ends and the short last group may not.
        for i in 1..n - 2 {
            assert!(
                (y[[0, 1, i]] - 0.5 * i as f32).abs() < 1e-5,
                "frame {i}: {}",
                y[[0, 1, i]]
            );
        }
    }

    #[test]
    fn low_pass_removes_the_fastest_oscillation() {
        let x = Array3::from_shape_fn((1, 1, 10), |(_, _, i)| if i % 2 == 0 { 1.0 } else { -1.0 });
        let y = low_pass(x.view(), 2);
        assert!(y.iter().all(|v| v.abs() < 1e-6), "{y:?}");
    }

    #[test]
    fn downsample_averages_groups_with_a_short_last_one() {
        let x = Array3::from_shape_vec((1, 1, 5), vec![1.0, 3.0, 5.0, 7.0, 10.0]).unwrap();
        let d = downsample(x.view(), 2);
        assert_eq!(d.as_slice().unwrap(), &[2.0, 6.0, 10.0]);
    }
}
