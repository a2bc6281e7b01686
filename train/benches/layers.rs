//! Forward and forward + backward time of each layer of the denoiser at the paper's size (C 256,
//! batch 64, 200 frames), best of 4: where a training step's time goes. Run:
//! `cargo bench -p sinmdm-train --bench layers` (`SINMDM_BENCH_SIZE=128,8` for the CPU config,
//! `64,1,1024,11` for the 60 fps dog).

use std::time::Instant;

use burn::tensor::{Device, Distribution, Tensor};
use sinmdm_train::model::dropout::{DropoutKey, HashDropout};
use sinmdm_train::model::layers::{ChannelNorm, FrameConv};
use sinmdm_train::model::pointwise::silu;
use sinmdm_train::model::qna::QnaBlock;
use sinmdm_train::model::resblock::ResBlock;

/// Prints the best time of `layer`'s forward pass, and of the forward pass plus the backward
/// pass of its sum.
fn time(name: &str, mut layer: impl FnMut() -> Tensor<3>) {
    let (mut forward, mut both) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..4 {
        let start = Instant::now();
        let y = layer();
        forward = forward.min(start.elapsed().as_secs_f64());
        let _grads = y.sum().backward();
        both = both.min(start.elapsed().as_secs_f64());
    }
    println!("{name:<28} {:>8.1} {:>8.1}", forward * 1e3, both * 1e3);
}

fn main() {
    sinmdm_train::memory::keep_freed_memory();
    let device = Device::flex().autodiff();
    device.seed(1);
    // `SINMDM_BENCH_SIZE=C,BATCH[,FRAMES[,WINDOW]]` picks another size (default the paper's
    // 256,64,200,3; the 60 fps dog's step is 64,1,1024,11).
    let size: Vec<usize> = std::env::var("SINMDM_BENCH_SIZE")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_default();
    let at = |i: usize, default: usize| size.get(i).copied().unwrap_or(default);
    let (c, batch, frames, window) = (at(0, 256), at(1, 64), at(2, 200), at(3, 3));
    let x = Tensor::<3>::random([batch, frames, c], Distribution::Normal(0.0, 1.0), &device)
        .require_grad();
    let embedding = Tensor::<2>::random([batch, 4 * c], Distribution::Normal(0.0, 1.0), &device);
    let conv3 = FrameConv::new(c, c, 3, &device);
    let conv1 = FrameConv::new(c, c, 1, &device);
    let norm = ChannelNorm::new(
        sinmdm::network::NORM_GROUPS,
        c,
        f64::from(sinmdm::network::NORM_EPSILON),
        &device,
    );
    let dropout = HashDropout::new(0.5, 1);
    let qna = QnaBlock::new(c, 4, window, &device);
    let block = ResBlock::new(c, c, 4 * c, 0.5, 1, &device);
    let key = Some(DropoutKey {
        seed: 1,
        first_item: 0,
    });
    println!(
        "layer, [{batch}, {frames}, {c}], QnA window {window}, flex, {} threads   ms: fwd, fwd+bwd",
        rayon::current_num_threads()
    );
    time("x * x (reference point)", || x.clone() * x.clone());
    time("burn silu", || burn::tensor::activation::silu(x.clone()));
    time("silu (pointwise)", || silu(x.clone()));
    time("burn dropout 0.5", || {
        burn::nn::DropoutConfig::new(0.5).init().forward(x.clone())
    });
    time("dropout 0.5 (hash mask)", || {
        dropout.forward(x.clone(), key)
    });
    time("group norm", || norm.forward(x.clone()));
    time("frame conv k3", || conv3.forward(x.clone()));
    time("frame conv k1", || conv1.forward(x.clone()));
    time("QnA block", || qna.forward(x.clone()));
    time("residual block", || {
        block.forward(x.clone(), embedding.clone(), key)
    });
}
