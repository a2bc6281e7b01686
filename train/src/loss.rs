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
}

impl LossTerms<'_> {
    /// The loss of the prediction `x0_hat` of the clean batch `x0` (both `[B, F, N]`,
    /// normalised): the mean squared error plus each weighted term.
    pub fn loss(&self, x0_hat: &Tensor<3>, x0: &Tensor<3>) -> Tensor<1> {
        let mut loss = MseLoss::new().forward(x0_hat.clone(), x0.clone(), Reduction::Mean);
        if self.acceleration_weight > 0.0 {
            let acceleration = MseLoss::new().forward(
                second_difference(x0_hat),
                second_difference(x0),
                Reduction::Mean,
            );
            loss = loss + acceleration.mul_scalar(self.acceleration_weight);
        }
        if let Some((term, weight)) = self.foot_contact {
            loss = loss + term.loss(x0_hat, x0).mul_scalar(weight);
        }
        loss
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

    #[test]
    fn the_acceleration_term_is_the_mean_squared_second_difference_of_the_error() {
        // Naive reference: for each item and feature, the error e = x0_hat - x0 and its second
        // differences e[n+1] - 2 e[n] + e[n-1], squared and averaged.
        let (b, f, n) = (2, 3, 7);
        let x0: Vec<f32> = (0..b * f * n)
            .map(|i| ((i * 37 % 11) as f32) * 0.1)
            .collect();
        let hat: Vec<f32> = (0..b * f * n)
            .map(|i| ((i * 53 % 13) as f32) * 0.07)
            .collect();
        let error: Vec<f64> = hat.iter().zip(&x0).map(|(a, c)| f64::from(a - c)).collect();
        let mut mse = 0.0;
        let mut acceleration = 0.0;
        for row in error.chunks(n) {
            mse += row.iter().map(|e| e * e).sum::<f64>() / (b * f * n) as f64;
            for k in 1..n - 1 {
                let d = row[k + 1] - 2.0 * row[k] + row[k - 1];
                acceleration += d * d / (b * f * (n - 2)) as f64;
            }
        }
        let terms = LossTerms {
            acceleration_weight: 0.5,
            ..LossTerms::default()
        };
        let got = scalar(terms.loss(
            &tensor(hat.clone(), [b, f, n]),
            &tensor(x0.clone(), [b, f, n]),
        ));
        let expected = mse + 0.5 * acceleration;
        assert!((got - expected).abs() < 1e-5 * expected, "{got} {expected}");
        // Without terms: the MSE alone.
        let plain =
            scalar(LossTerms::default().loss(&tensor(hat, [b, f, n]), &tensor(x0, [b, f, n])));
        assert!((plain - mse).abs() < 1e-5 * mse, "{plain} {mse}");
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
        let a = scalar(with.loss(
            &tensor(hat.clone(), [1, 1, n]),
            &tensor(x0.clone(), [1, 1, n]),
        ));
        let b = scalar(LossTerms::default().loss(&tensor(hat, [1, 1, n]), &tensor(x0, [1, 1, n])));
        assert!((a - b).abs() < 1e-6, "{a} {b}");
    }
}
