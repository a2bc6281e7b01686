//! The residual block with timestep-conditioned scale and shift.

use burn::module::Module;
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::{
    Dropout, DropoutConfig, GroupNorm, Initializer, Linear, LinearConfig, PaddingConfig1d,
};
use burn::tensor::activation::silu;
use burn::tensor::{Device, Tensor};

use super::group_norm;

/// `ResBlock(in -> out)` of SPEC §3: GN, SiLU, conv k3, scale/shift from the embedding, GN,
/// SiLU, dropout, zero-initialised conv k3, plus the skip path (a k1 conv when `in != out`).
#[derive(Module, Debug)]
pub struct ResBlock {
    in_norm: GroupNorm,
    in_conv: Conv1d,
    embedding: Linear,
    out_norm: GroupNorm,
    dropout: Dropout,
    out_conv: Conv1d,
    skip: Option<Conv1d>,
}

impl ResBlock {
    /// A block from `input` to `output` channels, conditioned on an embedding of `embedding_width`.
    pub fn new(
        input: usize,
        output: usize,
        embedding_width: usize,
        dropout: f64,
        device: &Device,
    ) -> Self {
        let padding = PaddingConfig1d::Explicit(1, 1);
        ResBlock {
            in_norm: group_norm(input, device),
            in_conv: Conv1dConfig::new(input, output, 3)
                .with_padding(padding.clone())
                .init(device),
            embedding: LinearConfig::new(embedding_width, 2 * output).init(device),
            out_norm: group_norm(output, device),
            dropout: DropoutConfig::new(dropout).init(),
            out_conv: Conv1dConfig::new(output, output, 3)
                .with_padding(padding)
                .with_initializer(Initializer::Zeros)
                .init(device),
            skip: (input != output).then(|| Conv1dConfig::new(input, output, 1).init(device)),
        }
    }

    /// `x` `[B, in, N]`, `embedding` `[B, 4C]` to `[B, out, N]`.
    pub fn forward(&self, x: Tensor<3>, embedding: Tensor<2>) -> Tensor<3> {
        let h = self.in_conv.forward(silu(self.in_norm.forward(x.clone())));
        let [batch, channels, _] = h.dims();
        let scale_shift = self
            .embedding
            .forward(silu(embedding))
            .reshape([batch, 2 * channels, 1]);
        let scale = scale_shift.clone().narrow(1, 0, channels);
        let shift = scale_shift.narrow(1, channels, channels);
        let h = self.out_norm.forward(h) * (scale + 1.0) + shift;
        let h = self.out_conv.forward(self.dropout.forward(silu(h)));
        let skip = match &self.skip {
            Some(conv) => conv.forward(x),
            None => x,
        };
        skip + h
    }
}
