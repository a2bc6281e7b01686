//! The training data: one clip as normalised features, stretched in time and noised each step.

use ndarray::{Array2, ArrayView2};

use sinmdm::diffusion::Schedule;
use sinmdm::diffusion::noise;

/// Stream offset of the per-step draws (stretch factor and timesteps); the per-step noise uses
/// stream `step` itself.
pub const CONTROL_STREAM_BASE: u64 = 1 << 40;

/// Keys' cubic convolution kernel with `a = -0.75` (the kernel of PyTorch's bicubic mode).
fn cubic_weight(x: f64) -> f64 {
    const A: f64 = -0.75;
    let x = x.abs();
    if x <= 1.0 {
        ((A + 2.0) * x - (A + 3.0)) * x * x + 1.0
    } else if x < 2.0 {
        ((A * x - 5.0 * A) * x + 8.0 * A) * x - 4.0 * A
    } else {
        0.0
    }
}

/// Resamples `[F, N]` to `[F, width]` along frames with cubic convolution (half-pixel centres,
/// edge frames repeated), as `interpolate(mode="bicubic", align_corners=False)` does.
pub fn resample_cubic(features: ArrayView2<'_, f32>, width: usize) -> Array2<f32> {
    let (rows, frames) = features.dim();
    let mut out = Array2::<f32>::zeros((rows, width));
    if frames == 0 || width == 0 {
        return out;
    }
    let scale = frames as f64 / width as f64;
    for j in 0..width {
        let source = (j as f64 + 0.5) * scale - 0.5;
        let base = source.floor();
        let frac = source - base;
        let taps: [(usize, f64); 4] = std::array::from_fn(|k| {
            let index = (base as i64 + k as i64 - 1).clamp(0, frames as i64 - 1) as usize;
            (index, cubic_weight(frac - (k as f64 - 1.0)))
        });
        for r in 0..rows {
            let v: f64 = taps
                .iter()
                .map(|&(i, w)| w * f64::from(features[[r, i]]))
                .sum();
            out[[r, j]] = v as f32;
        }
    }
    out
}

/// One training batch, flat row-major `[B, F, W]`.
#[derive(Debug, Clone)]
pub struct Batch {
    /// Batch size B.
    pub batch: usize,
    /// Feature rows F.
    pub features: usize,
    /// Frames W after stretching.
    pub frames: usize,
    /// The clean stretched clip, repeated B times.
    pub clean: Vec<f32>,
    /// The noised input `x_t`.
    pub noised: Vec<f32>,
    /// Timestep of each batch item.
    pub timesteps: Vec<usize>,
}

/// Makes the batch of step `step`: stretch factor, timesteps, windows and noise all come from
/// the counter-based generator keyed by `(seed, step)`, so any step can be rebuilt after a
/// resume. With `window`, each item is its own random window of that many frames of the
/// stretched clip (the whole clip when it is shorter).
pub fn make_batch(
    clip: ArrayView2<'_, f32>,
    schedule: &Schedule,
    batch: usize,
    stretch: (f64, f64),
    window: Option<usize>,
    seed: u64,
    step: u64,
) -> Batch {
    let (rows, frames) = clip.dim();
    let control = CONTROL_STREAM_BASE + step;
    let u = noise::uniform(noise::word(seed, control, 0));
    let factor = stretch.0 + (stretch.1 - stretch.0) * u;
    let width = ((frames as f64 * factor).round() as usize).max(1);
    let stretched = resample_cubic(clip, width);
    let steps = schedule.len();
    let timesteps: Vec<usize> = (0..batch)
        .map(|b| {
            let u = noise::uniform(noise::word(seed, control, 1 + b as u64));
            ((u * steps as f64) as usize).min(steps - 1)
        })
        .collect();
    let frames_out = window.map_or(width, |w| w.min(width));
    let mut clean = Vec::with_capacity(batch * rows * frames_out);
    for b in 0..batch {
        let start = if frames_out < width {
            let u = noise::uniform(noise::word(seed, control, 1 + (batch + b) as u64));
            ((u * (width - frames_out + 1) as f64) as usize).min(width - frames_out)
        } else {
            0
        };
        let item = stretched.slice(ndarray::s![.., start..start + frames_out]);
        clean.extend(item.as_standard_layout().iter().copied());
    }
    let item_len = rows * frames_out;
    let mut noised = vec![0f32; clean.len()];
    noise::fill_normals(seed, step, &mut noised);
    for (b, &t) in timesteps.iter().enumerate() {
        let (a, s) = schedule.q_sample_coefficients(t);
        let range = b * item_len..(b + 1) * item_len;
        for (n, &x) in noised[range.clone()].iter_mut().zip(&clean[range]) {
            *n = (a * f64::from(x) + s * f64::from(*n)) as f32;
        }
    }
    Batch {
        batch,
        features: rows,
        frames: frames_out,
        clean,
        noised,
        timesteps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    #[test]
    fn same_width_is_identity_and_linear_ramps_survive() {
        let clip = array![
            [0.0f32, 1.0, 2.0, 3.0, 4.0, 5.0],
            [3.0, 3.0, 3.0, 3.0, 3.0, 3.0]
        ];
        let same = resample_cubic(clip.view(), 6);
        for (a, b) in same.iter().zip(clip.iter()) {
            assert!((a - b).abs() < 1e-6);
        }
        // Cubic convolution reproduces a linear ramp exactly away from the clamped edges,
        // and a constant everywhere.
        let stretched = resample_cubic(clip.view(), 12);
        for j in 3..9 {
            let source = (j as f32 + 0.5) * 0.5 - 0.5;
            // a = -0.75 is not exactly linear-preserving; it stays within a few hundredths.
            assert!((stretched[[0, j]] - source).abs() < 0.05, "{j}");
            assert!(stretched[[0, j]] > stretched[[0, j - 1]]);
            assert!((stretched[[1, j]] - 3.0).abs() < 1e-6);
        }
    }

    #[test]
    fn batch_is_reproducible_and_noised_by_the_schedule() {
        let clip = Array2::from_shape_fn((5, 40), |(r, c)| (r as f32 * 0.3 + c as f32 * 0.1).sin());
        let schedule = Schedule::cosine(1000).unwrap();
        let a = make_batch(clip.view(), &schedule, 3, (0.75, 1.25), None, 7, 11);
        let b = make_batch(clip.view(), &schedule, 3, (0.75, 1.25), None, 7, 11);
        assert_eq!(a.noised, b.noised);
        assert!((30..=50).contains(&a.frames));
        let c = make_batch(clip.view(), &schedule, 3, (0.75, 1.25), None, 7, 12);
        assert_ne!(a.noised, c.noised);
        // x_t = sqrt(abar) x0 + sqrt(1 - abar) eps with eps the portable normals of stream `step`.
        let eps = noise::normals(7, 11, a.clean.len());
        let (sa, sn) = schedule.q_sample_coefficients(a.timesteps[1]);
        let i = a.features * a.frames + 4;
        let expected = sa * f64::from(a.clean[i]) + sn * f64::from(eps[i]);
        assert!((f64::from(a.noised[i]) - expected).abs() < 1e-5);
    }

    #[test]
    fn windows_are_random_slices_of_the_stretched_clip() {
        let clip =
            Array2::from_shape_fn((4, 300), |(r, c)| (r as f32 * 0.7 + c as f32 * 0.05).sin());
        let schedule = Schedule::cosine(1000).unwrap();
        let whole = make_batch(clip.view(), &schedule, 4, (0.75, 1.25), None, 3, 5);
        let windowed = make_batch(clip.view(), &schedule, 4, (0.75, 1.25), Some(64), 3, 5);
        assert_eq!(windowed.frames, 64);
        assert_eq!(windowed.timesteps, whole.timesteps);
        let (rows, width) = (whole.features, whole.frames);
        let stretched = &whole.clean[..rows * width];
        let mut starts = Vec::new();
        for b in 0..4 {
            let item = &windowed.clean[b * rows * 64..(b + 1) * rows * 64];
            let start = (0..=width - 64)
                .find(|&s| {
                    (0..rows).all(|r| {
                        item[r * 64..(r + 1) * 64] == stretched[r * width + s..r * width + s + 64]
                    })
                })
                .expect("each item is a window of the stretched clip");
            starts.push(start);
        }
        starts.dedup();
        assert!(
            starts.len() > 1,
            "every item got the same window: {starts:?}"
        );
        // A window longer than the clip is the whole clip.
        let long = make_batch(clip.view(), &schedule, 2, (1.0, 1.0), Some(1000), 3, 5);
        assert_eq!(long.frames, 300);
    }
}
