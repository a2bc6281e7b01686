//! Seconds per training step against the clip's length: the whole clip in each of 8 batch items,
//! random windows of 256 frames (the windowing that lost to the frame budget), and the default's frame budget
//! (`training.frames_per_step`: fewer whole-clip items for a longer clip). The batch is made from
//! a clip of 250, 1 000 and 2 000 frames (F 191, the CMU skeleton) and one optimisation step
//! taken with the default configuration's model. Medians of the timed steps, side by side in one
//! run.
//! Run: `cargo bench -p sinmdm-train --bench clip_length` (`SINMDM_BENCH_STEPS`, default 3).

use std::time::Instant;

use burn::tensor::{Device, Tensor, TensorData};
use ndarray::Array2;
use sinmdm::diffusion::Schedule;
use sinmdm_train::clip::batch::make_batch;
use sinmdm_train::config::TrainConfig;
use sinmdm_train::model::QnaUnet;
use sinmdm_train::run::trainer::{StepOutcome, new_optimizer, optimisation_step};

fn main() {
    sinmdm_train::memory::keep_freed_memory();
    let config: TrainConfig =
        TrainConfig::parse(include_str!("../../configs/default.yaml")).expect("default config");
    let timed: usize = std::env::var("SINMDM_BENCH_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let f = 191;
    let batch = config.training.batch_size;
    let schedule = Schedule::cosine(config.diffusion.steps).expect("schedule");
    println!(
        "training step against clip length: C {}, F {f}, stretch 0.75-1.25, seconds per step",
        config.model.channels
    );
    println!(
        "{:>7} {:>22} {:>22} {:>26}",
        "frames",
        format!("whole clip x {batch}"),
        format!("windows of 256 x {batch}"),
        "default (frames_per_step)"
    );
    for frames in [250usize, 1000, 2000] {
        let clip = Array2::from_shape_fn((f, frames), |(r, c)| {
            ((r as f32) * 0.37 + (c as f32) * 0.05).sin()
        });
        let default = config.training.batch_shape(frames);
        let mut row = Vec::new();
        for (items, window) in [
            (batch, None),
            (batch, Some(256)),
            (default.items, default.window),
        ] {
            let device = Device::flex().autodiff();
            device.seed(0);
            let mut model = QnaUnet::new(f, &config.model, &device);
            let mut optimizer = new_optimizer(&config);
            let mut seconds = Vec::new();
            for step in 0..timed + 1 {
                let start = Instant::now();
                let b = make_batch(
                    clip.view(),
                    &schedule,
                    items,
                    (0.75, 1.25),
                    window,
                    0,
                    step as u64,
                );
                let shape = [b.batch, b.features, b.frames];
                let xt = Tensor::<3>::from_data(TensorData::new(b.noised, shape), &device);
                let x0 = Tensor::<3>::from_data(TensorData::new(b.clean, shape), &device);
                let t: Vec<f32> = b.timesteps.iter().map(|&t| t as f32).collect();
                let t = Tensor::<1>::from_data(TensorData::new(t, [items]), &device);
                let (next, loss) = optimisation_step(model, &mut optimizer, xt, t, x0, 1e-4);
                model = next;
                assert!(matches!(loss, StepOutcome::Updated(_)), "{loss:?}");
                if step >= 1 {
                    seconds.push(start.elapsed().as_secs_f64());
                }
            }
            seconds.sort_by(f64::total_cmp);
            row.push(seconds[seconds.len() / 2]);
        }
        println!(
            "{frames:>7} {:>22.3} {:>22.3} {:>26}",
            row[0],
            row[1],
            format!(
                "{:.3} ({} item{})",
                row[2],
                default.items,
                if default.items == 1 { "" } else { "s" }
            )
        );
    }
}
