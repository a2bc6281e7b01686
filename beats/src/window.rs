//! The two signal helpers the tracker uses in several places: a Hann window and a convolution
//! that keeps the input's length.

/// The periodic Hann window of `n` samples: `0.5 - 0.5 cos(2 pi i / n)`.
pub(crate) fn hann(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos())
        .collect()
}

/// `values` convolved with `kernel` (odd length, centred on its middle value), as long as
/// `values`: samples beyond either end count as 0.
pub(crate) fn convolve_same(values: &[f64], kernel: &[f64]) -> Vec<f64> {
    let n = values.len() as isize;
    let reach = (kernel.len() / 2) as isize;
    (0..n)
        .map(|i| {
            kernel
                .iter()
                .enumerate()
                .filter_map(|(k, w)| {
                    let at = i + k as isize - reach;
                    (at >= 0 && at < n).then(|| w * values[at as usize])
                })
                .sum()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hann_is_zero_at_the_start_and_one_in_the_middle() {
        let w = hann(8);
        assert!(w[0].abs() < 1e-15 && (w[4] - 1.0).abs() < 1e-15);
        assert!((w[2] - w[6]).abs() < 1e-15);
    }

    #[test]
    fn a_convolution_keeps_length_and_treats_the_outside_as_zero() {
        let out = convolve_same(&[1.0, 2.0, 3.0], &[1.0, 10.0, 100.0]);
        // out[i] = 1 x[i-1] + 10 x[i] + 100 x[i+1]
        assert_eq!(out, vec![210.0, 321.0, 32.0]);
    }
}
