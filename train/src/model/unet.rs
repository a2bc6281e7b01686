//! The one-level QnA-UNet denoiser of SPEC §3.

use super::pointwise::silu;
use burn::module::Module;
use burn::tensor::{Device, Tensor};

use super::dropout::DropoutKey;
use super::group_norm;
use super::layers::{ChannelNorm, FrameConv};
use super::qna::QnaBlock;
use super::resblock::ResBlock;
use super::timestep::TimestepEmbedding;
use crate::config::ModelConfig;

/// Predicts the clean motion `x0` `[B, F, N]` from the noised `x_t` and the timestep.
#[derive(Module, Debug)]
pub struct QnaUnet {
    time: TimestepEmbedding,
    input: FrameConv,
    block1: ResBlock,
    attention1: QnaBlock,
    block2: ResBlock,
    attention2: QnaBlock,
    block3: ResBlock,
    attention3: QnaBlock,
    out_norm: ChannelNorm,
    output: FrameConv,
}

impl QnaUnet {
    /// A freshly initialised network for `features` feature rows. Seed the device first for
    /// reproducible weights.
    pub fn new(features: usize, config: &ModelConfig, device: &Device) -> Self {
        let c = config.channels;
        let emb = 4 * c;
        let qna = || QnaBlock::new(c, config.heads, config.window, device);
        let net = QnaUnet {
            time: TimestepEmbedding::new(c, device),
            input: FrameConv::new(features, c, 3, device),
            block1: ResBlock::new(c, c, emb, config.dropout, 1, device),
            attention1: qna(),
            block2: ResBlock::new(c, c, emb, config.dropout, 2, device),
            attention2: qna(),
            block3: ResBlock::new(2 * c, c, emb, config.dropout, 3, device),
            attention3: qna(),
            out_norm: group_norm(c, device),
            output: FrameConv::zeros(c, features, 3, device),
        };
        super::materialize(&net);
        net
    }

    /// `x_t` `[B, F, N]` and `t` `[B]` (integer steps as floats) to the predicted `x0` `[B, F, N]`,
    /// without dropout (inference, export checks).
    pub fn forward(&self, x_t: Tensor<3>, t: Tensor<1>) -> Tensor<3> {
        self.forward_training(x_t, t, None)
    }

    /// [`QnaUnet::forward`] with the dropout masks of `dropout` (training).
    pub fn forward_training(
        &self,
        x_t: Tensor<3>,
        t: Tensor<1>,
        dropout: Option<DropoutKey>,
    ) -> Tensor<3> {
        let emb = self.time.forward(t);
        // Internally [B, N, C]: every layer is then a matrix product over B * N rows.
        let h0 = self.input.forward(x_t.swap_dims(1, 2));
        let h1 = self
            .attention1
            .forward(self.block1.forward(h0.clone(), emb.clone(), dropout));
        let h2 = self
            .attention2
            .forward(self.block2.forward(h1, emb.clone(), dropout));
        let h3 = self.attention3.forward(self.block3.forward(
            Tensor::cat(vec![h2, h0], 2),
            emb,
            dropout,
        ));
        self.output
            .forward(silu(self.out_norm.forward(h3)))
            .swap_dims(1, 2)
    }
}
