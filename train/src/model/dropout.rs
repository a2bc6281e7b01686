//! Inverted dropout with a cheap mask that does not depend on how the batch is split.
//!
//! burn's `Dropout` draws a Bernoulli tensor with ChaCha20, one float per element, from the
//! device's shared generator, and applies it with two multiplications: about 6 % of a paper-size
//! training step, and its masks would depend on the order in which shards of a batch run. Here a
//! training step draws one 64-bit seed, and element `i` of batch item `b` is kept according to
//! the runtime's counter hash of `(seed, layer, b * item_size + i)`: one product per layer, the
//! same masks for a batch run whole or in shards on several threads, and `device.seed` still
//! fixes everything, which resume relies on.

use burn::module::Module;
use burn::tensor::{Tensor, TensorData};
use rayon::prelude::*;
use sinmdm::diffusion::noise::word;

/// Mask elements per parallel task.
const CHUNK: usize = 1 << 14;

/// Which masks a training forward pass uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DropoutKey {
    /// The training step's seed.
    pub seed: u64,
    /// Index in the whole batch of this (sub-)batch's first item.
    pub first_item: usize,
}

/// Zeroes each element with probability `prob` and scales the rest by `1 / (1 - prob)` when
/// given a [`DropoutKey`]; the identity without one (inference).
#[derive(Module, Debug)]
pub struct HashDropout {
    prob: f64,
    /// Distinguishes the masks of the network's dropout layers.
    layer: u64,
}

impl HashDropout {
    /// Dropout with probability `prob` in `[0, 1)`; `layer` must differ between the layers of one
    /// network.
    pub fn new(prob: f64, layer: u64) -> Self {
        assert!((0.0..1.0).contains(&prob), "dropout must be in [0, 1)");
        HashDropout { prob, layer }
    }

    /// The mask of elements `first .. first + count` of layer `layer` under `seed`: `0` with
    /// probability `prob`, else `1 / (1 - prob)`. Element `i` is kept when the top 32 bits of
    /// hash word `i` fall below `(1 - prob) 2^32`.
    pub fn mask(prob: f64, seed: u64, layer: u64, first: u64, count: usize) -> Vec<f32> {
        let keep = 1.0 - prob;
        let threshold = (keep * 4_294_967_296.0).round() as u64;
        let scale = (1.0 / keep) as f32;
        let mut mask = vec![0.0f32; count];
        mask.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, values)| {
                let start = first + (chunk * CHUNK) as u64;
                for (i, m) in (start..).zip(values) {
                    if word(seed, layer, i) >> 32 < threshold {
                        *m = scale;
                    }
                }
            });
        mask
    }

    /// Applies dropout to `x` `[B, ..]`, batch first.
    pub fn forward<const D: usize>(&self, x: Tensor<D>, key: Option<DropoutKey>) -> Tensor<D> {
        let Some(key) = key else { return x };
        if self.prob == 0.0 {
            return x;
        }
        let shape = x.dims();
        let item_size: usize = shape[1..].iter().product();
        let first = (key.first_item * item_size) as u64;
        let mask = Self::mask(self.prob, key.seed, self.layer, first, shape[0] * item_size);
        let device = x.device();
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
            let mask = HashDropout::mask(prob, 7, 1, 0, 200_000);
            let scale = (1.0 / (1.0 - prob)) as f32;
            assert!(mask.iter().all(|&m| m == 0.0 || m == scale));
            let kept = mask.iter().filter(|&&m| m != 0.0).count() as f64 / mask.len() as f64;
            // Binomial standard deviation at n = 200 000 is at most 0.0011.
            assert!((kept - (1.0 - prob)).abs() < 0.006, "p {prob}: kept {kept}");
        }
    }

    #[test]
    fn shards_of_a_batch_get_the_masks_of_the_whole() {
        let device = Device::flex();
        let dropout = HashDropout::new(0.5, 2);
        let x = Tensor::<3>::ones([5, 6, 7], &device);
        let key = |first_item| {
            Some(DropoutKey {
                seed: 9,
                first_item,
            })
        };
        let whole = dropout.forward(x.clone(), key(0));
        let parts = Tensor::cat(
            vec![
                dropout.forward(x.clone().narrow(0, 0, 2), key(0)),
                dropout.forward(x.clone().narrow(0, 2, 3), key(2)),
            ],
            0,
        );
        let whole = whole.into_data().try_to_vec::<f32>().unwrap();
        assert_eq!(whole, parts.into_data().try_to_vec::<f32>().unwrap());
        assert!(whole.iter().all(|&v| v == 0.0 || v == 2.0));
        // Another seed or another layer gives other masks; no key is the identity.
        let other_seed = dropout.forward(
            x.clone(),
            Some(DropoutKey {
                seed: 10,
                first_item: 0,
            }),
        );
        assert_ne!(whole, other_seed.into_data().try_to_vec::<f32>().unwrap());
        let other_layer = HashDropout::new(0.5, 3).forward(x.clone(), key(0));
        assert_ne!(whole, other_layer.into_data().try_to_vec::<f32>().unwrap());
        let inference = dropout
            .forward(x, None)
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        assert_eq!(inference, vec![1.0; 5 * 6 * 7]);
    }
}
