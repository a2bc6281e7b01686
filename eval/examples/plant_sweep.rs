//! Foot planting under several settings on saved samples: the feet figures of SPEC section 9
//! for each, to choose the defaults. Usage:
//! `cargo run --release -p sinmdm-eval --example plant_sweep -- MODEL.onnx CLIP.bvh SAMPLES.json`
//! (SAMPLES.json from `sinmdm generate --features-json`).

use std::path::Path;

use sinmdm::bvh::read_bvh;
use sinmdm::features_file::read_features;
use sinmdm::motion::feet::{Anchor, Kept, PlantOptions, plant_feet};
use sinmdm::motion::{decode, encode_for_model};
use sinmdm::{Model, ModelOptions};
use sinmdm_eval::{FeetReference, mean_scores};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let model = Model::open(&args[1], &ModelOptions::default())?;
    let layout = &model.metadata().layout;
    let clip = encode_for_model(&read_bvh(Path::new(&args[2]))?, layout, None)?;
    let clip_motion = decode(layout, clip.features.view())?;
    let reference = FeetReference::new(layout, &clip_motion);
    let (features, _) = read_features(Path::new(&args[3]))?;
    let contact_rows = layout.contact_rows();
    let samples: Vec<_> = features
        .outer_iter()
        .map(|s| {
            let labels: Vec<Vec<f32>> = contact_rows.iter().map(|&r| s.row(r).to_vec()).collect();
            (decode(layout, s).unwrap(), labels)
        })
        .collect();
    let clip_scores = reference.scores(&clip_motion);
    let raw = mean_scores(
        &samples
            .iter()
            .map(|(m, _)| reference.scores(m))
            .collect::<Vec<_>>(),
    );
    println!(
        "ground {:.4} (layout {:?})",
        reference.ground(),
        layout.ground
    );
    println!(
        "setting | skating % | deepest H | floor frames % | jitter ratio to raw | lifted | reach | unreached | ms/sample"
    );
    println!(
        "clip | {:.1} | {:.4} | {:.1} | {:.3}",
        100.0 * clip_scores.skating_ratio,
        clip_scores.max_penetration,
        100.0 * clip_scores.penetrating_frames,
        clip_scores.jitter / raw.jitter
    );
    println!(
        "raw | {:.1} | {:.4} | {:.1} | 1.000",
        100.0 * raw.skating_ratio,
        raw.max_penetration,
        100.0 * raw.penetrating_frames
    );
    let base = PlantOptions::default();
    let settings = [
        ("default", base),
        (
            "max hold 0.1 H",
            PlantOptions {
                max_hold: 0.1,
                ..base
            },
        ),
        (
            "max hold 0.3 H",
            PlantOptions {
                max_hold: 0.3,
                ..base
            },
        ),
        (
            "soft reach 0.1",
            PlantOptions {
                soft_reach: 0.1,
                ..base
            },
        ),
        (
            "labelled spans only",
            PlantOptions {
                grow_within: 0.0,
                ..base
            },
        ),
        (
            "landing anchor",
            PlantOptions {
                anchor: Anchor::Landing,
                ..base
            },
        ),
        (
            "blend 0.3 s",
            PlantOptions {
                blend_seconds: 0.3,
                ..base
            },
        ),
        (
            "legs only (the root does not follow the stance)",
            PlantOptions {
                root_follows_stance: false,
                ..base
            },
        ),
        (
            "stance smoothed over 0.2 s",
            PlantOptions {
                stance_smoothing_seconds: 0.2,
                ..base
            },
        ),
        (
            "stance smoothed over 0.3 s",
            PlantOptions {
                stance_smoothing_seconds: 0.3,
                ..base
            },
        ),
        (
            "stance smoothed over 0.5 s",
            PlantOptions {
                stance_smoothing_seconds: 0.5,
                ..base
            },
        ),
        (
            "root moves to reach",
            PlantOptions {
                reach_with_root: true,
                ..base
            },
        ),
    ];
    for (name, options) in settings {
        let started = std::time::Instant::now();
        let planted: Vec<_> = samples
            .iter()
            .map(|(m, l)| plant_feet(layout, m, l, &Kept::default(), &options).unwrap())
            .collect();
        let ms = started.elapsed().as_secs_f64() * 1000.0 / samples.len() as f64;
        let s = mean_scores(
            &planted
                .iter()
                .map(|(m, _)| reference.scores(m))
                .collect::<Vec<_>>(),
        );
        let lifted: usize = planted.iter().map(|(_, s)| s.lifted_frames).sum();
        let reach: usize = planted.iter().map(|(_, s)| s.reach_frames).sum();
        let unreached = format!(
            "{:.4}/{:.4}",
            planted.iter().map(|(_, s)| s.mean_miss).sum::<f64>() / planted.len() as f64,
            planted.iter().map(|(_, s)| s.max_miss).fold(0.0, f64::max)
        );
        println!(
            "{name} | {:.1} | {:.4} | {:.1} | {:.3} | {lifted} | {reach} | {unreached} | {ms:.1}",
            100.0 * s.skating_ratio,
            s.max_penetration,
            100.0 * s.penetrating_frames,
            s.jitter / raw.jitter
        );
    }
    Ok(())
}
