//! The timestep embedding: sinusoidal features of the integer step, then a two-layer MLP.

use super::pointwise::silu;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor, TensorData};

/// Width of the sinusoidal features (cosines then sines, 128 each).
pub const SINUSOID_WIDTH: usize = 256;

/// The frequencies `f_i = exp(-ln(10000) i / 128)`, `i = 0..128`.
pub fn frequencies() -> Vec<f32> {
    let half = SINUSOID_WIDTH / 2;
    (0..half)
        .map(|i| (-(10000f64.ln()) * i as f64 / half as f64).exp() as f32)
        .collect()
}

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
            first: LinearConfig::new(SINUSOID_WIDTH, 4 * channels).init(device),
            second: LinearConfig::new(4 * channels, 4 * channels).init(device),
        }
    }

    /// `t` `[B]` (timesteps as floats) to `[B, 4C]`.
    pub fn forward(&self, t: Tensor<1>) -> Tensor<2> {
        let [batch] = t.dims();
        let freqs = frequencies();
        let half = freqs.len();
        let freqs = Tensor::<2>::from_data(TensorData::new(freqs, [1, half]), &t.device());
        let args = t.reshape([batch, 1]) * freqs;
        let sinusoid = Tensor::cat(vec![args.clone().cos(), args.sin()], 1);
        self.second.forward(silu(self.first.forward(sinusoid)))
    }
}
