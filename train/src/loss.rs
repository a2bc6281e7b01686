//! The training loss: the MSE of the predicted clean motion x0 (SPEC §4), plus the optional
//! terms a configuration weights in.
//!
//! - The acceleration term compares second differences in time of the prediction and the clip,
//!   `x[n+1] - 2 x[n] + x[n-1]`, per feature in normalised units. White noise left in a
//!   prediction costs 6 times its variance there and a smooth error almost nothing, so the term
//!   aims at the frame-to-frame shake that makes samples jerkier than the clip.
//! - The foot-contact term ([`crate::foot_contact`]) holds predicted contact points still where
//!   the clip's label says a foot is down.

use burn::nn::loss::{MseLoss, Reduction};
use burn::tensor::Tensor;

use crate::foot_contact::FootContact;

/// The weighted terms added to the x0 MSE. The default adds none.
#[derive(Clone, Copy, Default)]
pub struct LossTerms<'a> {
    /// The foot-contact term and its weight.
    pub foot_contact: Option<(&'a FootContact, f64)>,
    /// Weight of the acceleration term (0: left out).
    pub acceleration_weight: f64,
    /// The acceleration term counts only for batch items whose diffusion timestep is below
    /// this (`None`: every item), so it can aim at the low noise levels where the samples'
    /// last details are drawn.
    pub acceleration_below_timestep: Option<usize>,
}

impl LossTerms<'_> {
    /// The loss of the prediction `x0_hat` of the clean batch `x0` (both `[B, F, N]`,
    /// normalised) at the items' diffusion timesteps `t` (`[B]`): the mean squared error plus
    /// each weighted term.
    pub fn loss(&self, x0_hat: &Tensor<3>, x0: &Tensor<3>, t: &Tensor<1>) -> Tensor<1> {
        let mut loss = MseLoss::new().forward(x0_hat.clone(), x0.clone(), Reduction::Mean);
        if self.acceleration_weight > 0.0 {
            let acceleration = self.acceleration(x0_hat, x0, t);
            loss = loss + acceleration.mul_scalar(self.acceleration_weight);
        }
        if let Some((term, weight)) = self.foot_contact {
            loss = loss + term.loss(x0_hat, x0).mul_scalar(weight);
        }
        loss
    }

    /// The acceleration term, unweighted: each item's mean squared second difference of its
    /// error, averaged over the batch with the items at or above the timestep cut counted as 0.
    fn acceleration(&self, x0_hat: &Tensor<3>, x0: &Tensor<3>, t: &Tensor<1>) -> Tensor<1> {
        let items = x0.dims()[0];
        let error = second_difference(x0_hat) - second_difference(x0);
        let per_item = error
            .powi_scalar(2)
            .mean_dim(2)
            .mean_dim(1)
            .reshape([items]);
        let per_item = match self.acceleration_below_timestep {
            Some(cut) => per_item * t.clone().lower_elem(cut as f32).float(),
            None => per_item,
        };
        per_item.mean()
    }
}

/// `x[n+1] - 2 x[n] + x[n-1]` along the last (frame) axis: `[B, F, N]` to `[B, F, N - 2]`.
/// Any training sequence is longer than the receptive field, so N > 2.
fn second_difference(x: &Tensor<3>) -> Tensor<3> {
    let frames = x.dims()[2];
    let inner = frames - 2;
    x.clone().narrow(2, 2, inner) - x.clone().narrow(2, 1, inner).mul_scalar(2.0)
        + x.clone().narrow(2, 0, inner)
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::{Device, TensorData};

    fn tensor(values: Vec<f32>, shape: [usize; 3]) -> Tensor<3> {
        Tensor::<3>::from_data(TensorData::new(values, shape), &Device::flex())
    }

    fn scalar(t: Tensor<1>) -> f64 {
        f64::from(t.into_scalar::<f32>())
    }

    fn timesteps(values: &[f32]) -> Tensor<1> {
        Tensor::<1>::from_data(
            TensorData::new(values.to_vec(), [values.len()]),
            &Device::flex(),
        )
    }

    /// A batch of `b` items, `f` features, `n` frames: (prediction, clean).
    fn batch(b: usize, f: usize, n: usize) -> (Vec<f32>, Vec<f32>) {
        let x0 = (0..b * f * n)
            .map(|i| ((i * 37 % 11) as f32) * 0.1)
            .collect();
        let hat = (0..b * f * n)
            .map(|i| ((i * 53 % 13) as f32) * 0.07)
            .collect();
        (hat, x0)
    }

    /// Naive reference: the MSE and each item's acceleration term, from the error
    /// e = x0_hat - x0 and its second differences e[n+1] - 2 e[n] + e[n-1], squared and
    /// averaged over the item's features and frames.
    fn reference(hat: &[f32], x0: &[f32], b: usize, f: usize, n: usize) -> (f64, Vec<f64>) {
        let error: Vec<f64> = hat.iter().zip(x0).map(|(a, c)| f64::from(a - c)).collect();
        let mse = error.iter().map(|e| e * e).sum::<f64>() / (b * f * n) as f64;
        let per_item = error
            .chunks(f * n)
            .map(|item| {
                let mut sum = 0.0;
                for row in item.chunks(n) {
                    for k in 1..n - 1 {
                        let d = row[k + 1] - 2.0 * row[k] + row[k - 1];
                        sum += d * d;
                    }
                }
                sum / (f * (n - 2)) as f64
            })
            .collect();
        (mse, per_item)
    }

    #[test]
    fn the_acceleration_term_is_the_mean_squared_second_difference_of_the_error() {
        let (b, f, n) = (2, 3, 7);
        let (hat, x0) = batch(b, f, n);
        let (mse, per_item) = reference(&hat, &x0, b, f, n);
        let acceleration = per_item.iter().sum::<f64>() / b as f64;
        let terms = LossTerms {
            acceleration_weight: 0.5,
            ..LossTerms::default()
        };
        let t = timesteps(&[3.0, 700.0]);
        let got = scalar(terms.loss(
            &tensor(hat.clone(), [b, f, n]),
            &tensor(x0.clone(), [b, f, n]),
            &t,
        ));
        let expected = mse + 0.5 * acceleration;
        assert!((got - expected).abs() < 1e-5 * expected, "{got} {expected}");
        // Without terms: the MSE alone.
        let plain =
            scalar(LossTerms::default().loss(&tensor(hat, [b, f, n]), &tensor(x0, [b, f, n]), &t));
        assert!((plain - mse).abs() < 1e-5 * mse, "{plain} {mse}");
    }

    #[test]
    fn a_timestep_cut_counts_the_acceleration_of_the_low_noise_items_only() {
        let (b, f, n) = (3, 2, 8);
        let (hat, x0) = batch(b, f, n);
        let (mse, per_item) = reference(&hat, &x0, b, f, n);
        // Items at t 10 and 250 are under a cut of 300; the one at 300 is not. The mean is
        // still taken over all three items.
        let expected = mse + 2.0 * (per_item[0] + per_item[2]) / 3.0;
        let terms = LossTerms {
            acceleration_weight: 2.0,
            acceleration_below_timestep: Some(300),
            ..LossTerms::default()
        };
        let got = scalar(terms.loss(
            &tensor(hat, [b, f, n]),
            &tensor(x0, [b, f, n]),
            &timesteps(&[10.0, 300.0, 250.0]),
        ));
        assert!((got - expected).abs() < 1e-5 * expected, "{got} {expected}");
        assert!(
            per_item[1] > 0.01 * expected,
            "the excluded item must matter"
        );
    }

    #[test]
    fn an_error_that_changes_linearly_in_time_costs_no_acceleration() {
        // e[n] = a + b n has zero second difference: only the MSE remains.
        let n = 9;
        let x0 = vec![0.0f32; n];
        let hat: Vec<f32> = (0..n).map(|k| 0.3 + 0.05 * k as f32).collect();
        let with = LossTerms {
            acceleration_weight: 10.0,
            ..LossTerms::default()
        };
        let t = timesteps(&[5.0]);
        let a = scalar(with.loss(
            &tensor(hat.clone(), [1, 1, n]),
            &tensor(x0.clone(), [1, 1, n]),
            &t,
        ));
        let b =
            scalar(LossTerms::default().loss(&tensor(hat, [1, 1, n]), &tensor(x0, [1, 1, n]), &t));
        assert!((a - b).abs() < 1e-6, "{a} {b}");
    }
}
