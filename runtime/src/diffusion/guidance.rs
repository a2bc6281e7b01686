//! What steers a sampling run away from plain generation (SPEC section 5): blending the
//! prediction with a reference through a mask, and replacing the sample's low frequencies.

use ndarray::{Array2, Array3, ArrayView3, Axis, Zip};

use super::error::SamplerError;

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
    /// The root's slow motion pulled to steering commands ([`crate::steer`]), before the mask
    /// blending.
    pub steering: Option<crate::steer::Steering>,
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

impl Guidance {
    /// Checks every array against samples of `features` rows and `frames` frames.
    pub fn check(&self, features: usize, frames: usize) -> Result<(), SamplerError> {
        let shape = |what: &'static str, a: &Array2<f32>| {
            if a.dim() == (features, frames) {
                Ok(())
            } else {
                Err(SamplerError::Shape {
                    what,
                    got: a.dim(),
                    features,
                    frames,
                })
            }
        };
        if let Some(inpaint) = &self.inpainting {
            shape("inpainting reference", &inpaint.reference)?;
            shape("inpainting mask", &inpaint.mask)?;
        }
        if let Some(steer) = &self.steering
            && (steer.frames() != frames || features < 3)
        {
            return Err(SamplerError::Shape {
                what: "steering",
                got: (features, steer.frames()),
                features,
                frames,
            });
        }
        if let Some(h) = &self.harmonization {
            shape("harmonization content", &h.content)?;
            if h.factor == 0 {
                return Err(SamplerError::ZeroFactor);
            }
        }
        Ok(())
    }
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
