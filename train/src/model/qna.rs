//! The learned-query local attention block (QnA) of SPEC §3.

use burn::module::{Module, Param};
use burn::tensor::ops::PadMode;
use burn::tensor::{Device, Distribution, Tensor};

use super::group_norm;
use super::layers::{ChannelNorm, FrameConv};

use sinmdm::network::SCORE_FLOOR;

/// `x + proj(window-softmax(q . key(GN(x))) * value(GN(x)))` with a learned relative-position bias.
#[derive(Module, Debug)]
pub struct QnaBlock {
    norm: ChannelNorm,
    /// The learned query `[C]`.
    query: Param<Tensor<1>>,
    /// Key projection `[C_out, C_in]` (`k = W x + b`).
    key_weight: Param<Tensor<2>>,
    /// Key bias `[C]`.
    key_bias: Param<Tensor<1>>,
    value: FrameConv,
    proj: FrameConv,
    /// Relative-position bias `[H, k]`; index `j` is the neighbour at offset `j - (k - 1) / 2`.
    rpe: Param<Tensor<2>>,
    heads: usize,
    window: usize,
}

impl QnaBlock {
    /// A block over `channels` with `heads` heads and an odd `window`.
    pub fn new(channels: usize, heads: usize, window: usize, device: &Device) -> Self {
        let head_width = channels / heads;
        let std = 1.0 / (head_width as f64).sqrt();
        let normal = Distribution::Normal(0.0, std);
        QnaBlock {
            norm: group_norm(channels, device),
            query: Param::from_tensor(Tensor::random([channels], normal, device)),
            key_weight: Param::from_tensor(Tensor::random([channels, channels], normal, device)),
            key_bias: Param::from_tensor(Tensor::zeros([channels], device)),
            value: FrameConv::new(channels, channels, 1, device),
            proj: FrameConv::new(channels, channels, 1, device),
            rpe: Param::from_tensor(Tensor::zeros([heads, window], device)),
            heads,
            window,
        }
    }

    /// The query split into heads, each of unit length divided by `sqrt(C / H)`: `[H, C/H]`.
    fn head_queries(&self) -> Tensor<2> {
        let channels = self.query.dims()[0];
        let width = channels / self.heads;
        let q = self.query.val().reshape([self.heads, width]);
        let norm = q.clone().square().sum_dim(1).sqrt().clamp_min(1e-12);
        q / norm / (width as f64).sqrt()
    }

    /// Attention scores `[B, N, H]`: `s_h[n] = <q_h, (W x[n] + b)_h>`, computed through the
    /// equivalent `C -> H` projection (the same numbers, a fraction of the work).
    fn scores(&self, x: Tensor<3>) -> Tensor<3> {
        let [batch, frames, channels] = x.dims();
        let heads = self.heads;
        let width = channels / heads;
        let q = self.head_queries();
        let weight = (self.key_weight.val().reshape([heads, width, channels])
            * q.clone().reshape([heads, width, 1]))
        .sum_dim(1)
        .reshape([heads, channels])
        .transpose();
        let bias = (self.key_bias.val().reshape([heads, width]) * q)
            .sum_dim(1)
            .reshape([1, heads]);
        (x.reshape([batch * frames, channels]).matmul(weight) + bias)
            .reshape([batch, frames, heads])
    }

    /// `x` `[B, N, C]` to `[B, N, C]`.
    ///
    /// With `e[n] = exp(s[n] - max s)` and `b_j = exp(rpe_j)`, the attention of frame `n` to
    /// neighbour `m = n + j - (k-1)/2` inside the clip is `a_j[n] = b_j e[m] / sum_j' b_j' e[..]`.
    /// These weights are only `[B, N, H]` each, so they are normalised first and the full-size
    /// values are touched once per neighbour (a product and a sum), with no full-size division.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let [batch, frames, channels] = x.dims();
        let heads = self.heads;
        let width = channels / heads;
        let pad = (self.window - 1) / 2;
        let normed = self.norm.forward(x.clone());
        let scores = self.scores(normed.clone());
        let top = scores.clone().max_dim(1);
        let weights = (scores - top).clamp_min(f64::from(SCORE_FLOOR)).exp();
        let bias = self.rpe.val().exp();
        // Each neighbour's unnormalised weight seen from frame n, zero outside the clip: [B, N, H].
        let padded = weights.pad([(0, 0), (pad, pad), (0, 0)], PadMode::Constant(0.0));
        let neighbour: Vec<Tensor<3>> = (0..self.window)
            .map(|j| {
                padded.clone().narrow(1, j, frames)
                    * bias.clone().narrow(1, j, 1).reshape([1, 1, heads])
            })
            .collect();
        let total = neighbour
            .iter()
            .cloned()
            .reduce(|a, b| a + b)
            .expect("window >= 1");
        let values = self
            .value
            .forward(normed)
            .reshape([batch, frames, heads, width])
            .pad([(0, 0), (pad, pad), (0, 0), (0, 0)], PadMode::Constant(0.0));
        let attended = neighbour
            .into_iter()
            .enumerate()
            .map(|(j, w)| {
                values.clone().narrow(1, j, frames)
                    * (w / total.clone()).reshape([batch, frames, heads, 1])
            })
            .reduce(|a, b| a + b)
            .expect("window >= 1")
            .reshape([batch, frames, channels]);
        x + self.proj.forward(attended)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::weights::{named_tensors, perturb};
    use burn::tensor::TensorData;

    /// GroupNorm(32) written out: population statistics per (item, group) over channels and
    /// frames, then the affine weights.
    fn naive_group_norm(x: &[f64], c: usize, n: usize, gamma: &[f32], beta: &[f32]) -> Vec<f64> {
        let per = c / 32;
        let mut out = vec![0.0; c * n];
        for g in 0..32 {
            let idx: Vec<usize> = (g * per * n..(g + 1) * per * n).collect();
            let mean = idx.iter().map(|&i| x[i]).sum::<f64>() / idx.len() as f64;
            let var = idx.iter().map(|&i| (x[i] - mean).powi(2)).sum::<f64>() / idx.len() as f64;
            for &i in &idx {
                let ch = i / n;
                out[i] = (x[i] - mean) / (var + 1e-5).sqrt() * f64::from(gamma[ch])
                    + f64::from(beta[ch]);
            }
        }
        out
    }

    /// The QnA block straight from SPEC §3, one item `[C, N]`, in f64: for every head and
    /// frame, a softmax over the window neighbours inside [0, N) of `s + rpe`.
    fn naive_qna(block: &QnaBlock, x: &[f32], c: usize, n: usize) -> Vec<f64> {
        let w = named_tensors(block);
        let get = |k: &str| &w[k].values;
        let (h, k) = (block.heads, block.window);
        let d = c / h;
        let pad = (k - 1) / 2;
        let x64: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
        let xn = naive_group_norm(&x64, c, n, get("norm.gamma"), get("norm.beta"));
        let linear = |weight: &[f32], bias: &[f32], input: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; c * n];
            for o in 0..c {
                for f in 0..n {
                    let mut acc = f64::from(bias[o]);
                    for i in 0..c {
                        acc += f64::from(weight[o * c + i]) * input[i * n + f];
                    }
                    out[o * n + f] = acc;
                }
            }
            out
        };
        let transpose =
            |w: &[f32]| -> Vec<f32> { (0..c * c).map(|k| w[(k % c) * c + k / c]).collect() };
        let keys = linear(get("key_weight"), get("key_bias"), &xn);
        let values = linear(&transpose(get("value.weight")), get("value.bias"), &xn);
        let query = get("query");
        let rpe = get("rpe");
        let mut attended = vec![0.0; c * n];
        for head in 0..h {
            let q: Vec<f64> = (0..d).map(|j| f64::from(query[head * d + j])).collect();
            let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            let score = |f: usize| -> f64 {
                (0..d)
                    .map(|j| q[j] / norm / (d as f64).sqrt() * keys[(head * d + j) * n + f])
                    .sum()
            };
            for f in 0..n {
                let neighbours: Vec<(usize, f64)> = (0..k)
                    .filter_map(|j| {
                        let g = f as i64 + j as i64 - pad as i64;
                        (0..n as i64)
                            .contains(&g)
                            .then(|| (g as usize, score(g as usize) + f64::from(rpe[head * k + j])))
                    })
                    .collect();
                let top = neighbours.iter().map(|p| p.1).fold(f64::MIN, f64::max);
                let total: f64 = neighbours.iter().map(|p| (p.1 - top).exp()).sum();
                for j in 0..d {
                    let ch = head * d + j;
                    attended[ch * n + f] = neighbours
                        .iter()
                        .map(|&(g, logit)| (logit - top).exp() / total * values[ch * n + g])
                        .sum();
                }
            }
        }
        let projected = linear(&transpose(get("proj.weight")), get("proj.bias"), &attended);
        x64.iter().zip(projected).map(|(a, b)| a + b).collect()
    }

    #[test]
    fn matches_a_naive_window_softmax_including_sequence_ends() {
        let _random = crate::device_random_lock();
        let device = Device::flex();
        device.seed(3);
        let (c, h) = (64, 4);
        for (window, n) in [(3, 1), (3, 2), (3, 9), (5, 4), (5, 13), (3, 700)] {
            let block = perturb(QnaBlock::new(c, h, window, &device), 0.3);
            // x is [2, C, N] for the naive code; the block takes [2, N, C].
            let x: Vec<f32> = (0..2 * c * n)
                .map(|i| (i as f32 * 0.731).sin() * 2.0 + (i % 7) as f32 * 0.1)
                .collect();
            let input = Tensor::<3>::from_data(TensorData::new(x.clone(), [2, c, n]), &device);
            let got = block
                .forward(input.swap_dims(1, 2))
                .swap_dims(1, 2)
                .into_data()
                .try_to_vec::<f32>()
                .unwrap();
            for item in 0..2 {
                let slice = &x[item * c * n..(item + 1) * c * n];
                let expected = naive_qna(&block, slice, c, n);
                let worst = expected
                    .iter()
                    .zip(&got[item * c * n..(item + 1) * c * n])
                    .map(|(e, g)| (e - f64::from(*g)).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-4, "window {window}, N {n}: max |diff| {worst}");
            }
        }
    }
}
