//! The residual block with timestep-conditioned scale and shift.

use super::pointwise::silu;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor};

use super::dropout::{DropoutKey, HashDropout};
use super::group_norm;
use super::layers::{ChannelNorm, FrameConv};

/// `ResBlock(in -> out)` of SPEC §3: GN, SiLU, conv k3, scale/shift from the embedding, GN,
/// SiLU, dropout, zero-initialised conv k3, plus the skip path (a k1 conv when `in != out`).
#[derive(Module, Debug)]
pub struct ResBlock {
    in_norm: ChannelNorm,
    in_conv: FrameConv,
    embedding: Linear,
    out_norm: ChannelNorm,
    dropout: HashDropout,
    out_conv: FrameConv,
    skip: Option<FrameConv>,
}

impl ResBlock {
    /// A block from `input` to `output` channels, conditioned on an embedding of `embedding_width`;
    /// `layer` numbers the block's dropout among the network's.
    pub fn new(
        input: usize,
        output: usize,
        embedding_width: usize,
        dropout: f64,
        layer: u64,
        device: &Device,
    ) -> Self {
        ResBlock {
            in_norm: group_norm(input, device),
            in_conv: FrameConv::new(input, output, 3, device),
            embedding: LinearConfig::new(embedding_width, 2 * output).init(device),
            out_norm: group_norm(output, device),
            dropout: HashDropout::new(dropout, layer),
            out_conv: FrameConv::zeros(output, output, 3, device),
            skip: (input != output).then(|| FrameConv::new(input, output, 1, device)),
        }
    }

    /// `x` `[B, N, in]`, `embedding` `[B, 4C]` to `[B, N, out]`; dropout only with a key.
    pub fn forward(
        &self,
        x: Tensor<3>,
        embedding: Tensor<2>,
        dropout: Option<DropoutKey>,
    ) -> Tensor<3> {
        let h = self.in_conv.forward(silu(self.in_norm.forward(x.clone())));
        let [batch, _, channels] = h.dims();
        let scale_shift = self
            .embedding
            .forward(silu(embedding))
            .reshape([batch, 1, 2 * channels]);
        let scale = scale_shift.clone().narrow(2, 0, channels);
        let shift = scale_shift.narrow(2, channels, channels);
        let h = self.out_norm.forward_modulated(h, scale, shift);
        let h = self
            .out_conv
            .forward(self.dropout.forward(silu(h), dropout));
        let skip = match &self.skip {
            Some(conv) => conv.forward(x),
            None => x,
        };
        skip + h
    }
}
