//! The learned-query local attention block (QnA) of SPEC §3.

use burn::module::{Module, Param};
use burn::tensor::ops::PadMode;
use burn::tensor::{Device, Distribution, Tensor};

use super::group_norm;
use super::layers::{ChannelNorm, FrameConv};

use sinmdm::network::{RPE_SPREAD_FLOOR, SCORE_FLOOR};

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
    /// The attention of frame `n` to neighbour `m = n + j - (k-1)/2` inside the clip is a
    /// softmax over the window of the logits `l_j[n] = max(s[m] - max s, SCORE_FLOOR) + rpe_j`
    /// (the score floor and the position bias floor of [`position_logits`] are the
    /// network contract's, so the exported graph computes the same function). Each frame's
    /// logits are shifted by their own largest before the exponential, a constant per frame
    /// that the softmax ignores (detached: it carries no gradient), so the largest weight is
    /// exactly 1 and the sum never falls below it. Shifting by the sequence maximum alone left
    /// the sum as small as `exp(-60)` wherever a whole window sat at the floor, and the
    /// division's backward pass (`-a / b^2`) then overflowed: gradients of inf and NaN with a
    /// finite loss. The weights are only `[B, N, H]` each, so they are normalised first and the
    /// full-size values are touched once per neighbour (a product and a sum).
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let [batch, frames, channels] = x.dims();
        let heads = self.heads;
        let width = channels / heads;
        let pad = (self.window - 1) / 2;
        let normed = self.norm.forward(x.clone());
        let scores = self.scores(normed.clone());
        let top = scores.clone().max_dim(1);
        let floored = (scores - top).clamp_min(f64::from(SCORE_FLOOR));
        let bias = position_logits(self.rpe.val());
        // Each neighbour's logit seen from frame n, [B, N, H]; neighbours outside the clip get
        // a logit whose exponential is exactly 0.
        let padded = floored.pad(
            [(0, 0), (pad, pad), (0, 0)],
            PadMode::Constant(OUTSIDE_LOGIT),
        );
        let logits: Vec<Tensor<3>> = (0..self.window)
            .map(|j| {
                padded.clone().narrow(1, j, frames)
                    + bias.clone().narrow(1, j, 1).reshape([1, 1, heads])
            })
            .collect();
        let largest = logits
            .iter()
            .map(|l| l.clone().detach())
            .reduce(|a, b| a.max_pair(b))
            .expect("window >= 1");
        let neighbour: Vec<Tensor<3>> = logits
            .into_iter()
            .map(|l| (l - largest.clone()).exp())
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

/// The relative-position logits `[H, k]` as the network uses them: each raised to at most
/// [`RPE_SPREAD_FLOOR`] below its head's largest (the rule of
/// [`sinmdm::network::position_weights`], here on tensors, so that gradients flow). The floor keeps the exported graph's window
/// sums (which take `exp(rpe)` as they are) clear of f32 underflow; trained biases spread by a
/// few units, so it changes nothing in practice. The head's largest is a detached constant.
pub(crate) fn position_logits(rpe: Tensor<2>) -> Tensor<2> {
    let window = rpe.dims()[1];
    let floor =
        (rpe.clone().detach().max_dim(1) + f64::from(RPE_SPREAD_FLOOR)).repeat_dim(1, window);
    rpe.max_pair(floor)
}

/// The logit of a neighbour outside the clip: far enough below any logit inside it (scores
/// are floored at [`SCORE_FLOOR`], position biases at most [`RPE_SPREAD_FLOOR`]
/// below their head's largest) that its exponential is 0 in f32, and finite, so nothing
/// becomes NaN on the way.
const OUTSIDE_LOGIT: f32 = -1.0e4;

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

    #[test]
    fn gradients_stay_finite_where_whole_windows_sit_at_the_score_floor() {
        use burn::module::ModuleVisitor;
        use burn::optim::GradientsParams;
        let _random = crate::device_random_lock();
        let device = Device::flex().autodiff();
        device.seed(5);
        let (c, h, window, n) = (64, 4, 5, 96);
        let mut block = perturb(QnaBlock::new(c, h, window, &device), 0.3);
        // Key weights 300 times larger: the scores spread over hundreds, so most frames' whole
        // windows fall more than 60 below the sequence's maximum, onto the floor.
        let scaled: Vec<f32> = block
            .key_weight
            .val()
            .into_data()
            .iter::<f32>()
            .map(|w| w * 300.0)
            .collect();
        block.key_weight =
            Param::from_tensor(Tensor::from_data(TensorData::new(scaled, [c, c]), &device));
        let x: Vec<f32> = (0..2 * n * c)
            .map(|i| (i as f32 * 0.377).sin() * 3.0 + ((i / c) % 11) as f32 * 0.4)
            .collect();
        let input = Tensor::<3>::from_data(TensorData::new(x, [2, n, c]), &device);
        let scores = block
            .scores(block.norm.forward(input.clone()))
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        let top = scores.iter().copied().fold(f32::MIN, f32::max);
        let floored = scores.iter().filter(|&&s| s - top < SCORE_FLOOR).count();
        assert!(
            floored > scores.len() / 4,
            "only {floored} of {} scores on the floor",
            scores.len()
        );
        let output = block.forward(input);
        let loss = output.powi_scalar(2).mean();
        assert!(loss.clone().into_scalar::<f32>().is_finite());
        let grads = GradientsParams::from_grads(loss.backward(), &block);
        struct Finite<'a>(&'a GradientsParams, Vec<String>);
        impl ModuleVisitor for Finite<'_> {
            fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
                if let Some(g) = self.0.get::<D>(param.id) {
                    let values = g.into_data().try_to_vec::<f32>().unwrap();
                    if values.iter().any(|v| !v.is_finite()) {
                        self.1.push(format!("{:?}", param.id));
                    }
                }
            }
        }
        let mut check = Finite(&grads, Vec::new());
        block.visit(&mut check);
        assert!(check.1.is_empty(), "non-finite gradients: {:?}", check.1);
    }

    #[test]
    fn position_biases_are_floored_below_their_heads_largest() {
        let rpe = Tensor::<2>::from_data(
            TensorData::new(vec![0.5f32, -30.0, 1.0, -2.0, -2.5, -23.0], [2, 3]),
            &Device::flex(),
        );
        let got = position_logits(rpe)
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        assert_eq!(got, vec![0.5, -19.0, 1.0, -2.0, -2.5, -22.0]);
        // The exported graph's weights are these logits' exponentials less each head's largest.
        let weights = sinmdm::network::position_weights(&[0.5, -30.0, 1.0, -2.0, -2.5, -23.0], 3);
        for (head, w) in got.chunks(3).zip(weights.chunks(3)) {
            let top = head.iter().copied().fold(f32::MIN, f32::max);
            for (l, w) in head.iter().zip(w) {
                assert!(
                    ((l - top).exp() - w).abs() <= 1e-6 * w.max(1e-30),
                    "{l} {w}"
                );
            }
        }
    }
}
