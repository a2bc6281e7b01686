//! The low-pass steering works through: a triangular kernel (a box filter run twice), whose
//! integer weights make it exact in `f64` in any language.

/// `values` smoothed by a triangular kernel of half-width `reach` (weights `reach + 1 - |k|`),
/// renormalised where it runs past the ends, so a constant stays that constant. `reach` 0
/// returns the values.
pub fn triangular(values: &[f64], reach: usize) -> Vec<f64> {
    let n = values.len();
    if reach == 0 || n == 0 {
        return values.to_vec();
    }
    let r = reach as isize;
    (0..n as isize)
        .map(|i| {
            let (mut sum, mut norm) = (0.0f64, 0.0f64);
            for k in -r..=r {
                let j = i + k;
                if j < 0 || j >= n as isize {
                    continue;
                }
                let w = (r + 1 - k.abs()) as f64;
                sum += w * values[j as usize];
                norm += w;
            }
            sum / norm
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_constants_and_means_and_spreads_a_spike_as_a_triangle() {
        assert_eq!(triangular(&[3.0; 7], 2), vec![3.0; 7]);
        let mut values = [0.0; 9];
        values[4] = 9.0;
        // Weights 1 2 3 2 1 over 9: the spike spreads as 1 2 3 2 1.
        let spike = triangular(&values, 2);
        assert_eq!(spike, vec![0.0, 0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0, 0.0]);
        // Near an end the kernel is cut and renormalised: 2 3 over 5 at frame 0.
        let edge = triangular(&[5.0, 10.0, 0.0, 0.0], 1);
        assert!((edge[0] - (2.0 * 5.0 + 10.0) / 3.0).abs() < 1e-12);
        assert_eq!(triangular(&[1.0, 5.0], 0), vec![1.0, 5.0]);
    }
}
