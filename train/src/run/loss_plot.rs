//! The loss curve as a PNG: every step in light blue, the 100-step running mean in dark blue,
//! on a log scale.

use std::path::Path;

use sinmdm_render::{Series, log_chart};

use crate::error::{TrainError, io};

/// Steps in the running mean.
const WINDOW: usize = 100;

/// Draws the loss log at `log` as a PNG at `png`.
pub fn write(log: &Path, png: &Path) -> Result<(), TrainError> {
    let rows = crate::run::loss_log::read(log)?;
    let raw: Vec<(f64, f64)> = rows.iter().map(|&(s, l)| (s as f64, l)).collect();
    let mut mean = Vec::with_capacity(raw.len());
    let mut sum = 0.0;
    for (i, &(step, loss)) in raw.iter().enumerate() {
        sum += loss;
        if i >= WINDOW {
            sum -= raw[i - WINDOW].1;
        }
        mean.push((step, sum / (i + 1).min(WINDOW) as f64));
    }
    let canvas = log_chart(
        &[
            Series {
                points: raw,
                colour: [170, 200, 235],
                width: 1.0,
            },
            Series {
                points: mean,
                colour: [20, 70, 160],
                width: 2.0,
            },
        ],
        "TRAINING LOSS",
        "STEP",
        "MSE (LOG)",
        800,
        420,
    );
    canvas
        .write_png(png)
        .map_err(io("write the loss curve", png))
}
