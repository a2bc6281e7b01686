//! The training loss: the mean squared error of the predicted clean motion x0 (SPEC §4).
//!
//! Two further terms were tried and lost (an acceleration term on the prediction's error, and a
//! foot-contact term holding predicted contact points still); lab/EXPERIMENTS.md has
//! their figures and names the commit that removed them.

use burn::nn::loss::{MseLoss, Reduction};
use burn::tensor::Tensor;

/// The loss of the prediction `x0_hat` of the clean batch `x0` (both `[B, F, N]`, normalised):
/// the mean squared error over every item, feature and frame.
pub fn x0_loss(x0_hat: &Tensor<3>, x0: &Tensor<3>) -> Tensor<1> {
    MseLoss::new().forward(x0_hat.clone(), x0.clone(), Reduction::Mean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::{Device, TensorData};

    #[test]
    fn the_loss_is_the_mean_squared_error() {
        let tensor = |values: Vec<f32>| {
            Tensor::<3>::from_data(TensorData::new(values, [1, 2, 2]), &Device::flex())
        };
        let loss = x0_loss(
            &tensor(vec![1.0, 2.0, 3.0, 4.0]),
            &tensor(vec![0.0, 2.0, 5.0, 4.0]),
        );
        let value: f32 = loss.into_scalar();
        // (1 + 0 + 4 + 0) / 4
        assert!((value - 1.25).abs() < 1e-7, "{value}");
    }
}
