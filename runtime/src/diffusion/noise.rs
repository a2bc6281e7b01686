//! The portable noise generator (SPEC section 7): a counter-based stream that Rust and Python
//! compute identically from `(seed, stream)`, with no shared state.
//!
//! Word `i` of a stream is the splitmix64 finaliser of `base + (i + 1) * GOLDEN`, where
//! `base = seed ^ (stream * STREAM_MIX)`, all in wrapping `u64`. Words become uniforms in (0, 1],
//! and pairs of uniforms become normals by Box-Muller in `f64`, cast to `f32`.

/// Stream 0: `x_T` of the whole batch, row-major `[B, F, N]`. Stream `k` (1..=S) is the noise of
/// sampling step `k`.
pub const INITIAL_NOISE_STREAM: u64 = 0;
/// Harmonization's `q_sample` noise of step `k` uses stream `HARMONIZE_STREAM_BASE + k`.
pub const HARMONIZE_STREAM_BASE: u64 = 1_000_000;

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;
const STREAM_MIX: u64 = 0xD1B5_4A32_D192_ED03;

/// The splitmix64 finaliser.
pub fn mix(mut z: u64) -> u64 {
    z ^= z >> 30;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Word `index` of stream `stream` under `seed`.
pub fn word(seed: u64, stream: u64, index: u64) -> u64 {
    let base = seed ^ stream.wrapping_mul(STREAM_MIX);
    mix(base.wrapping_add(index.wrapping_add(1).wrapping_mul(GOLDEN)))
}

/// A word as a uniform number in (0, 1]: `((word >> 11) + 1) * 2^-53`.
pub fn uniform(word: u64) -> f64 {
    ((word >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Fills `out` with normals `0..out.len()` of stream `stream` under `seed`.
pub fn fill_normals(seed: u64, stream: u64, out: &mut [f32]) {
    for (pair, chunk) in out.chunks_mut(2).enumerate() {
        let p = pair as u64;
        let u0 = uniform(word(seed, stream, 2 * p));
        let u1 = uniform(word(seed, stream, 2 * p + 1));
        let r = (-2.0 * u0.ln()).sqrt();
        let (sin, cos) = (std::f64::consts::TAU * u1).sin_cos();
        chunk[0] = (r * cos) as f32;
        if let Some(second) = chunk.get_mut(1) {
            *second = (r * sin) as f32;
        }
    }
}

/// The first `count` normals of stream `stream` under `seed`.
pub fn normals(seed: u64, stream: u64, count: usize) -> Vec<f32> {
    let mut out = vec![0.0; count];
    fill_normals(seed, stream, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_published_values() {
        // SPEC section 7: seed 42, stream 0, normals 0..3.
        assert_eq!(
            normals(42, 0, 4),
            vec![0.414_719_76, 0.652_681_23, -0.891_886_23, 1.326_833_6]
        );
    }

    #[test]
    fn an_odd_count_is_a_prefix_of_the_even_one() {
        assert_eq!(normals(7, 3, 5), normals(7, 3, 6)[..5].to_vec());
    }

    #[test]
    fn streams_and_seeds_differ() {
        assert_ne!(normals(42, 0, 8), normals(42, 1, 8));
        assert_ne!(normals(42, 0, 8), normals(43, 0, 8));
    }

    #[test]
    fn uniforms_stay_in_the_half_open_interval() {
        assert_eq!(uniform(u64::MAX), 1.0);
        assert_eq!(uniform(0), 1.0 / (1u64 << 53) as f64);
    }

    #[test]
    fn normals_have_unit_moments() {
        let n = normals(1, 0, 200_000);
        let mean = n.iter().map(|&v| f64::from(v)).sum::<f64>() / n.len() as f64;
        let var = n
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n.len() as f64;
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.01, "{var}");
    }
}
