//! Inverted dropout with a cheap mask.
//!
//! burn's `Dropout` draws a Bernoulli tensor with ChaCha20, one float per element, and applies
//! it with two multiplications: about 6 % of a paper-size training step. This one takes a
//! 64-bit seed from the device's generator (so `device.seed` still fixes it, which resume
//! relies on), hashes the element index with the runtime's counter-based noise hash, and
//! applies a mask that already holds `0` or `1 / (1 - p)` in one multiplication.

use burn::module::Module;
use burn::tensor::{Distribution, Tensor, TensorData};
use rayon::prelude::*;
use sinmdm::diffusion::noise::word;

/// Mask elements per parallel task.
const CHUNK: usize = 1 << 14;

/// Zeroes each element with probability `prob` and scales the rest by `1 / (1 - prob)` while
/// training (on an autodiff device); the identity otherwise.
#[derive(Module, Debug)]
pub struct HashDropout {
    prob: f64,
}

impl HashDropout {
    /// Dropout with probability `prob` in `[0, 1)`.
    pub fn new(prob: f64) -> Self {
        assert!((0.0..1.0).contains(&prob), "dropout must be in [0, 1)");
        HashDropout { prob }
    }

    /// The mask for `count` elements under `seed`: `0` with probability `prob`, else
    /// `1 / (1 - prob)`. Element `i` is kept when the top 32 bits of hash word `i` fall below
    /// `(1 - prob) 2^32`.
    pub fn mask(prob: f64, seed: u64, count: usize) -> Vec<f32> {
        let keep = 1.0 - prob;
        let threshold = (keep * 4_294_967_296.0).round() as u64;
        let scale = (1.0 / keep) as f32;
        let mut mask = vec![0.0f32; count];
        mask.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, values)| {
                let first = (chunk * CHUNK) as u64;
                for (i, m) in (first..).zip(values) {
                    if word(seed, 0, i) >> 32 < threshold {
                        *m = scale;
                    }
                }
            });
        mask
    }

    /// Applies dropout to `x` of any shape.
    pub fn forward<const D: usize>(&self, x: Tensor<D>) -> Tensor<D> {
        let device = x.device();
        if self.prob == 0.0 || !device.is_autodiff() {
            return x;
        }
        // Two uniform floats from the seeded device generator make the mask's seed.
        let draw = Tensor::<1>::random([2], Distribution::Default, &device)
            .into_data()
            .try_to_vec::<f32>()
            .expect("f32 draw");
        let seed = (u64::from(draw[0].to_bits()) << 32) | u64::from(draw[1].to_bits());
        let shape = x.dims();
        let mask = Self::mask(self.prob, seed, shape.iter().product());
        x * Tensor::<D>::from_data(TensorData::new(mask, shape), &device)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::Device;

    #[test]
    fn keeps_the_expected_share_scaled_to_keep_the_mean() {
        for prob in [0.1, 0.5, 0.9] {
            let mask = HashDropout::mask(prob, 7, 200_000);
            let scale = (1.0 / (1.0 - prob)) as f32;
            assert!(mask.iter().all(|&m| m == 0.0 || m == scale));
            let kept = mask.iter().filter(|&&m| m != 0.0).count() as f64 / mask.len() as f64;
            // Binomial standard deviation at n = 200 000 is at most 0.0011.
            assert!((kept - (1.0 - prob)).abs() < 0.006, "p {prob}: kept {kept}");
        }
    }

    #[test]
    fn the_device_seed_fixes_the_mask_and_inference_is_the_identity() {
        let device = Device::flex().autodiff();
        let dropout = HashDropout::new(0.5);
        let x = Tensor::<2>::ones([40, 50], &device);
        let run = |seed| {
            device.seed(seed);
            dropout
                .forward(x.clone())
                .into_data()
                .try_to_vec::<f32>()
                .unwrap()
        };
        let first = run(3);
        assert_eq!(first, run(3));
        assert_ne!(first, run(4));
        assert!(first.iter().all(|&v| v == 0.0 || v == 2.0));
        let inference = Device::flex();
        let y = dropout.forward(Tensor::<2>::ones([4, 5], &inference));
        assert_eq!(y.into_data().try_to_vec::<f32>().unwrap(), vec![1.0; 20]);
    }
}
