//! Smoothing of per-frame signals.

/// `values` smoothed by a Gaussian of `sigma` samples (cut at 4 sigma; edges mirrored).
pub fn gaussian_smooth(values: &[f64], sigma: f64) -> Vec<f64> {
    let n = values.len() as isize;
    if n == 0 || sigma <= 0.0 {
        return values.to_vec();
    }
    // The kernel never needs to reach past the input (an absurd frame rate would ask for more).
    let reach = (4.0 * sigma).ceil().min(n as f64) as isize;
    let kernel: Vec<f64> = (-reach..=reach)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let norm: f64 = kernel.iter().sum();
    let mirror = |mut i: isize| -> usize {
        // Reflect about the ends (…2 1 0 | 0 1 2…), repeatedly for short inputs.
        loop {
            if i < 0 {
                i = -i - 1;
            } else if i >= n {
                i = 2 * n - i - 1;
            } else {
                return i as usize;
            }
        }
    };
    (0..n)
        .map(|t| {
            kernel
                .iter()
                .enumerate()
                .map(|(k, w)| w * values[mirror(t + k as isize - reach)])
                .sum::<f64>()
                / norm
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_keeps_a_constant_and_a_mean() {
        let flat = gaussian_smooth(&[2.0; 9], 1.5);
        assert!(flat.iter().all(|v| (v - 2.0).abs() < 1e-12));
        let spike = gaussian_smooth(&[0.0, 0.0, 0.0, 0.0, 7.0, 0.0, 0.0, 0.0, 0.0], 1.0);
        assert!((spike.iter().sum::<f64>() - 7.0).abs() < 1e-9);
        assert!(spike[4] > spike[3] && spike[3] > spike[2] && (spike[3] - spike[5]).abs() < 1e-12);
    }
}
