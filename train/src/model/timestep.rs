//! The timestep embedding: sinusoidal features of the integer step, then a two-layer MLP.

use super::pointwise::silu;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor, TensorData};
use sinmdm::network::{EMBEDDING_MULTIPLIER, SINUSOID_WIDTH, timestep_frequencies};

/// `t -> Linear(256, 4C) -> SiLU -> Linear(4C, 4C)` over `[cos(t f), sin(t f)]`.
#[derive(Module, Debug)]
pub struct TimestepEmbedding {
    first: Linear,
    second: Linear,
}

impl TimestepEmbedding {
    /// An embedding of width `4 * channels`.
    pub fn new(channels: usize, device: &Device) -> Self {
        TimestepEmbedding {
            first: LinearConfig::new(SINUSOID_WIDTH, EMBEDDING_MULTIPLIER * channels).init(device),
            second: LinearConfig::new(
                EMBEDDING_MULTIPLIER * channels,
                EMBEDDING_MULTIPLIER * channels,
            )
            .init(device),
        }
    }

    /// `t` `[B]` (timesteps as floats) to `[B, 4C]`.
    pub fn forward(&self, t: Tensor<1>) -> Tensor<2> {
        let [batch] = t.dims();
        let freqs = timestep_frequencies();
        let half = freqs.len();
        let freqs = Tensor::<2>::from_data(TensorData::new(freqs, [1, half]), &t.device());
        let args = t.reshape([batch, 1]) * freqs;
        let sinusoid = Tensor::cat(vec![args.clone().cos(), args.sin()], 1);
        self.second.forward(silu(self.first.forward(sinusoid)))
    }
}
