//! Seconds per training step and GFLOP/s for the two reference sizes (F = 174, N = 200):
//! C 256 / batch 64 (the paper) and C 128 / batch 8. Run: `cargo bench -p sinmdm-train`.
//! `SINMDM_BENCH_STEPS` sets the timed steps per size (default 5 and 20).

use std::time::Instant;

use burn::tensor::{Device, Distribution, Tensor, TensorData};
use sinmdm_train::config::{ModelConfig, TrainConfig};
use sinmdm_train::model::QnaUnet;
use sinmdm_train::run::trainer::{StepOutcome, new_optimizer, optimisation_step};

/// Multiply-adds per frame of one forward pass (convolutions, 1x1 projections and the QnA score
/// projection; normalisation and element-wise work left out).
fn forward_macs_per_frame(f: usize, c: usize, heads: usize) -> usize {
    let input = f * c * 3;
    let block = 2 * c * c * 3;
    let wide_block = 2 * c * c * 3 + c * c * 3 + 2 * c * c;
    let qna = 2 * c * c + c * heads;
    let output = c * f * 3;
    input + 2 * block + wide_block + 3 * qna + output
}

fn main() {
    sinmdm_train::memory::keep_freed_memory();
    let config: TrainConfig =
        TrainConfig::parse(include_str!("../../configs/paper.yaml")).expect("paper config");
    let steps_override: Option<usize> = std::env::var("SINMDM_BENCH_STEPS")
        .ok()
        .and_then(|s| s.parse().ok());
    let threads = rayon::current_num_threads();
    println!("training step, flex CPU backend, {threads} threads, F 174, N 200");
    println!(
        "{:>4} {:>6} {:>10} {:>10} {:>9} {:>14}",
        "C", "batch", "s/step", "GFLOP", "GFLOP/s", "reference s"
    );
    for (channels, batch, reference, timed) in [(256, 64, 1.02, 5), (128, 8, 0.067, 20)] {
        let (f, n) = (174, 200);
        let model_config = ModelConfig {
            channels,
            ..config.model.clone()
        };
        let device = Device::flex().autodiff();
        device.seed(0);
        let mut model = QnaUnet::new(f, &model_config, &device);
        let mut optimizer = new_optimizer(&config);
        let x0 = Tensor::<3>::random([batch, f, n], Distribution::Normal(0.0, 1.0), &device);
        let xt = Tensor::<3>::random([batch, f, n], Distribution::Normal(0.0, 1.0), &device);
        let t: Vec<f32> = (0..batch).map(|b| (b * 997 % 1000) as f32).collect();
        let t = Tensor::<1>::from_data(TensorData::new(t, [batch]), &device);
        let timed = steps_override.unwrap_or(timed);
        let mut seconds = Vec::new();
        for step in 0..timed + 2 {
            let start = Instant::now();
            let (next, loss) = optimisation_step(
                model,
                &mut optimizer,
                xt.clone(),
                t.clone(),
                x0.clone(),
                1e-4,
            );
            model = next;
            assert!(matches!(loss, StepOutcome::Updated(_)), "{loss:?}");
            if step >= 2 {
                seconds.push(start.elapsed().as_secs_f64());
            }
        }
        seconds.sort_by(f64::total_cmp);
        let median = seconds[seconds.len() / 2];
        let gflop = 3.0 * 2.0 * (forward_macs_per_frame(f, channels, 4) * batch * n) as f64 / 1e9;
        println!(
            "{channels:>4} {batch:>6} {median:>10.3} {gflop:>10.1} {:>9.1} {reference:>14.3}",
            gflop / median
        );
    }
}
