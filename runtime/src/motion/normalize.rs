//! Per-feature standardisation with the clip's own statistics.

use ndarray::{Array2, ArrayView2, Axis as NdAxis};
use serde::{Deserialize, Serialize};

/// The default floor on a feature's standard deviation, as a share of the mean standard
/// deviation: a feature that barely varies (a still joint's rounding noise) is not scaled up to
/// the motion's size, where the network would learn its noise as motion
/// (lab/EXPERIMENTS.md, "The normaliser's floor").
pub const STD_FLOOR_SHARE: f32 = 0.05;

/// The floor of models trained before [`STD_FLOOR_SHARE`] became the default, which a
/// configuration without `data.std_floor` still means.
pub const STD_FLOOR_SHARE_BEFORE: f32 = 1e-3;

/// Per-feature mean and standard deviation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalizer {
    /// Mean of each feature row.
    pub mean: Vec<f32>,
    /// Standard deviation of each feature row (already floored).
    pub std: Vec<f32>,
}

impl Normalizer {
    /// Statistics of `features` `[F, N]` over frames (population standard deviation, floored at
    /// `floor_share` times the mean standard deviation; [`STD_FLOOR_SHARE`] by default).
    pub fn fit(features: ArrayView2<'_, f32>, floor_share: f32) -> Normalizer {
        let rows = features.nrows();
        let frames = features.ncols().max(1) as f64;
        let mut mean = Vec::with_capacity(rows);
        let mut std = Vec::with_capacity(rows);
        for row in features.axis_iter(NdAxis(0)) {
            let m = row.iter().map(|&v| f64::from(v)).sum::<f64>() / frames;
            let var = row.iter().map(|&v| (f64::from(v) - m).powi(2)).sum::<f64>() / frames;
            mean.push(m as f32);
            std.push(var.sqrt() as f32);
        }
        let mean_std = if rows == 0 {
            0.0
        } else {
            std.iter().sum::<f32>() / rows as f32
        };
        let floor = (mean_std * floor_share).max(f32::MIN_POSITIVE);
        for s in &mut std {
            *s = s.max(floor);
        }
        Normalizer { mean, std }
    }

    /// `(x - mean) / std`, row by row.
    pub fn normalize(&self, features: ArrayView2<'_, f32>) -> Array2<f32> {
        let mut out = features.to_owned();
        for (r, mut row) in out.axis_iter_mut(NdAxis(0)).enumerate() {
            row.mapv_inplace(|v| (v - self.mean[r]) / self.std[r]);
        }
        out
    }

    /// `x * std + mean`, row by row.
    pub fn denormalize(&self, features: ArrayView2<'_, f32>) -> Array2<f32> {
        let mut out = features.to_owned();
        for (r, mut row) in out.axis_iter_mut(NdAxis(0)).enumerate() {
            row.mapv_inplace(|v| v * self.std[r] + self.mean[r]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    #[test]
    fn standardises_rows_and_floors_constant_ones() {
        let x = array![[1.0f32, 3.0, 5.0, 7.0], [2.0, 2.0, 2.0, 2.0]];
        let n = Normalizer::fit(x.view(), STD_FLOOR_SHARE_BEFORE);
        // Row 0: mean 4, population std sqrt(5). Row 1: std floored at 1e-3 * mean std.
        assert_eq!(n.mean, vec![4.0, 2.0]);
        assert!((n.std[0] - 5f32.sqrt()).abs() < 1e-6);
        assert!((n.std[1] - 1e-3 * 5f32.sqrt() / 2.0).abs() < 1e-9);
        let z = n.normalize(x.view());
        assert!((z[[0, 0]] + 3.0 / 5f32.sqrt()).abs() < 1e-6);
        assert_eq!(z[[1, 2]], 0.0);
        let back = n.denormalize(z.view());
        for (a, b) in back.iter().zip(x.iter()) {
            assert!((a - b).abs() < 1e-5);
        }
    }

    #[test]
    fn the_default_floor_holds_a_barely_varying_row_at_a_twentieth_of_the_mean_spread() {
        // Row 0: std 2; row 1: std 0.01 (a still joint's noise). Mean std 1.005, so the
        // default floor is 0.05025 and lifts row 1 to it, while the old one leaves it at 0.01.
        let x = array![[-2.0f32, 2.0, -2.0, 2.0], [-0.01, 0.01, -0.01, 0.01]];
        let new = Normalizer::fit(x.view(), STD_FLOOR_SHARE);
        let old = Normalizer::fit(x.view(), STD_FLOOR_SHARE_BEFORE);
        assert!((new.std[0] - 2.0).abs() < 1e-6);
        assert!((new.std[1] - 0.05 * 1.005).abs() < 1e-6, "{}", new.std[1]);
        assert!((old.std[1] - 0.01).abs() < 1e-7, "{}", old.std[1]);
        // Standardised, the noise row now swings by a fifth of a unit, not by one.
        let z = new.normalize(x.view());
        assert!((z[[1, 1]] - 0.01 / (0.05 * 1.005)).abs() < 1e-5);
    }
}
