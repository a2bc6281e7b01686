//! The denoiser network's contract (SPEC section 3): what training, export and the runtime must
//! agree on, written once. The training crate builds the QnA-UNet with these constants, the
//! exporter writes them into the ONNX graph, and the runtime calls the graph by these names, so a
//! change on one side is a change on all.

use std::collections::BTreeMap;

/// Graph input: the noisy normalised features, `f32 [B, F, N]` (batch, feature rows, frames).
pub const INPUT_FEATURES: &str = "x_t";
/// Graph input: the original diffusion timestep of each batch row, `i64 [B]`.
pub const INPUT_STEP: &str = "t";
/// Graph output: the predicted clean features, `f32 [B, F, N]`.
pub const OUTPUT_FEATURES: &str = "x0";
/// Symbolic name of the graph's batch dimension.
pub const BATCH_AXIS: &str = "batch";
/// Symbolic name of the graph's frame dimension.
pub const FRAMES_AXIS: &str = "frames";

/// Groups of every GroupNorm in the network.
pub const NORM_GROUPS: usize = 32;
/// Epsilon of every GroupNorm.
pub const NORM_EPSILON: f32 = 1e-5;
/// QnA scores more than this below their sequence maximum are raised to it, so no window's
/// softmax can sum to zero.
pub const SCORE_FLOOR: f32 = -60.0;
/// QnA relative-position biases more than this below their head's largest are raised to it.
/// With the score floor, every weight of a window sum is at least `exp(-80)`, a normal f32, so
/// the graph's sums (which take the weights unshifted) never underflow to 0.
pub const RPE_SPREAD_FLOOR: f32 = -20.0;
/// The QnA position weights of the exported graph, `[H, k]` from the learned biases `rpe`
/// `[H, k]`: `exp(max(rpe_j, top + RPE_SPREAD_FLOOR) - top)` with `top` each head's largest
/// bias, so every weight lies in `[exp(RPE_SPREAD_FLOOR), 1]`. The softmax ignores the shift;
/// the floor is the training network's too, which applies it to the biases as tensors.
pub fn position_weights(rpe: &[f32], window: usize) -> Vec<f32> {
    rpe.chunks(window)
        .flat_map(|head| {
            let top = head.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            head.iter().map(move |&r| {
                (f64::from(r.max(top + RPE_SPREAD_FLOOR)) - f64::from(top)).exp() as f32
            })
        })
        .collect()
}

/// Width of the sinusoidal timestep features (cosines, then sines).
pub const SINUSOID_WIDTH: usize = 256;
/// Longest period of the timestep sinusoids.
pub const SINUSOID_MAX_PERIOD: f64 = 10_000.0;
/// The timestep embedding is this many times the channel count wide.
pub const EMBEDDING_MULTIPLIER: usize = 4;
/// Kernel of the frame convolutions (input, output, and each residual block's two).
pub const CONV_KERNEL: usize = 3;

/// The frequencies of the timestep features, `f_i = exp(-ln(MAX_PERIOD) i / (W / 2))` for
/// `i < W / 2`, computed in f64 and rounded once; the features are `[cos(t f), sin(t f)]`.
pub fn timestep_frequencies() -> Vec<f32> {
    let half = SINUSOID_WIDTH / 2;
    (0..half)
        .map(|i| (-SINUSOID_MAX_PERIOD.ln() * i as f64 / half as f64).exp() as f32)
        .collect()
}

/// QnA blocks in the network, each seeing `(window - 1) / 2` frames on each side.
pub const QNA_BLOCKS: usize = 3;

/// The part of the receptive half-width that does not depend on the QnA window: the input and
/// output convolutions (1 frame each) and two k3 convolutions in each of the 3 residual blocks.
pub const FIXED_RECEPTIVE_HALF_WIDTH: usize = 1 + 3 * 2 + 1;

/// Frames on each side of a frame that can change its prediction, for QnA window `window`.
pub fn receptive_half_width(window: usize) -> usize {
    FIXED_RECEPTIVE_HALF_WIDTH + QNA_BLOCKS * (window.max(1) - 1) / 2
}

/// The receptive field in frames for QnA window `window` (23 for window 3).
pub fn receptive_field(window: usize) -> usize {
    2 * receptive_half_width(window) + 1
}

/// The network's sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NetworkShape {
    /// Feature rows F.
    pub features: usize,
    /// Channels C.
    pub channels: usize,
    /// QnA heads H.
    pub heads: usize,
    /// QnA window k in frames (odd).
    pub window: usize,
}

impl NetworkShape {
    /// The receptive field in frames ([`receptive_field`]).
    pub fn receptive_field(&self) -> usize {
        receptive_field(self.window)
    }

    /// Checks the rules the layers need: C a multiple of the GroupNorm groups and of H, k odd,
    /// every size at least 1. The message names the size that breaks a rule.
    pub fn check(&self) -> Result<(), String> {
        let NetworkShape {
            features,
            channels,
            heads,
            window,
        } = *self;
        if features == 0 || channels == 0 || heads == 0 || window == 0 {
            return Err(format!(
                "every network size must be at least 1, got {self:?}"
            ));
        }
        if channels % NORM_GROUPS != 0 {
            return Err(format!(
                "channels ({channels}) must be a multiple of the {NORM_GROUPS} GroupNorm groups"
            ));
        }
        if channels % heads != 0 {
            return Err(format!(
                "channels ({channels}) must be a multiple of heads ({heads})"
            ));
        }
        if window % 2 == 0 {
            return Err(format!("the QnA window ({window}) must be odd"));
        }
        Ok(())
    }
}

/// One weight tensor, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightTensor {
    /// Dimensions.
    pub shape: Vec<usize>,
    /// Values, row-major.
    pub values: Vec<f32>,
}

/// Weights by dotted name, in the training crate's layouts:
///
/// | name | shape |
/// |---|---|
/// | `time.first.weight`, `time.second.weight` | `[in, out]` |
/// | `input.weight`, `output.weight`, `*.in_conv.weight`, `*.out_conv.weight`, `*.skip.weight`, `*.value.weight`, `*.proj.weight` | `[k, C_in, C_out]` |
/// | `*.embedding.weight` | `[4C, 2C]` |
/// | `*.gamma`, `*.beta`, every `bias` | `[C]` |
/// | `attentionN.query` | `[C]` |
/// | `attentionN.key_weight` | `[C_out, C_in]` |
/// | `attentionN.rpe` | `[H, k]` |
pub type Weights = BTreeMap<String, WeightTensor>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequencies_run_from_one_to_nearly_the_longest_period() {
        let f = timestep_frequencies();
        assert_eq!(f.len(), 128);
        assert_eq!(f[0], 1.0);
        // f_64 = 10000^(-1/2) = 0.01 exactly in real numbers.
        assert!((f[64] - 0.01).abs() < 1e-8, "{}", f[64]);
        assert!(f.windows(2).all(|w| w[1] < w[0]));
    }

    #[test]
    fn shape_rules_name_the_size_that_breaks_them() {
        let good = NetworkShape {
            features: 10,
            channels: 64,
            heads: 4,
            window: 7,
        };
        assert!(good.check().is_ok());
        let e = NetworkShape {
            channels: 48,
            ..good
        }
        .check()
        .unwrap_err();
        assert!(e.contains("channels (48)") && e.contains("32"), "{e}");
        let e = NetworkShape { heads: 3, ..good }.check().unwrap_err();
        assert!(e.contains("heads (3)"), "{e}");
        let e = NetworkShape { window: 8, ..good }.check().unwrap_err();
        assert!(e.contains("window (8)"), "{e}");
        assert!(
            NetworkShape {
                features: 0,
                ..good
            }
            .check()
            .is_err()
        );
    }
}
