//! Random motions and a direct frame distance for the metric tests.

use ndarray::Array2;

/// `frames x width` values in [-1, 1) from a fixed LCG, different for each seed.
pub fn random_motion(frames: usize, width: usize, seed: u64) -> Array2<f64> {
    let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
    Array2::from_shape_fn((frames, width), |_| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    })
}

/// Euclidean distance between frame `i` of `a` and frame `k` of `b`, written out.
pub fn frame_distance(a: &Array2<f64>, i: usize, b: &Array2<f64>, k: usize) -> f64 {
    a.row(i)
        .iter()
        .zip(b.row(k).iter())
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
}
