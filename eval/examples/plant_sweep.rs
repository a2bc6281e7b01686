//! Foot planting under several settings on saved samples, to choose the defaults: for each
//! setting, the feet figures of SPEC section 9, how the body moves against the clip (its speed
//! ratios and acceleration distance) and the coverage and global diversity of the planted
//! motion (re-encoded, the model's contact labels kept), beside the raw samples'. It
//! also plants the clip itself with its own labels: a pass that changes the clip much is
//! holding feet that the clip lets move. Usage:
//! `cargo run --release -p sinmdm-eval --example plant_sweep -- MODEL.onnx CLIP.bvh SAMPLES.json`
//! (SAMPLES.json from `sinmdm generate --feet raw --features-json`).

use std::path::Path;

use ndarray::Array2;
use sinmdm::bvh::read_bvh;
use sinmdm::features_file::read_features;
use sinmdm::motion::feet::{Anchor, CONTACT_ON, Kept, PlantOptions, plant_feet};
use sinmdm::motion::{FeatureLayout, LocalMotion, decode, encode_for_model};
use sinmdm::{Model, ModelOptions};
use sinmdm_eval::{
    ClipKinematics, FeetReference, FeetScores, Kinematics, evaluate, mean_scores, metric_features,
    motion_metric_features,
};

/// The row of the default planted over a ground 0.03 H lower (every height then reads 0.03 H
/// higher, so the stance band shifts with it; a model file without a ground plants as the
/// default).
const LOWERED_GROUND: &str = "default, the ground 0.03 H lower (almost nothing lifted)";

/// The table's coverage / global diversity column of planted (or raw) samples' motions.
type Benchmark<'a> = dyn Fn(&[&LocalMotion]) -> Result<String, Box<dyn std::error::Error>> + 'a;

/// Mean over frames of the per-frame distance between two metric feature tables.
fn mean_frame_distance(a: &Array2<f64>, b: &Array2<f64>) -> f64 {
    let total: f64 = a
        .outer_iter()
        .zip(b.outer_iter())
        .map(|(x, y)| {
            x.iter()
                .zip(&y)
                .map(|(p, q)| (p - q).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
    total / a.nrows().max(1) as f64
}

/// How motions' bodies move against the clip's (the kinematic fidelity figures).
struct BodyMoves {
    clip: Kinematics,
    scores: ClipKinematics,
    height: f64,
}

impl BodyMoves {
    fn new(clip: &LocalMotion, height: f64) -> BodyMoves {
        let clip = Kinematics::of_motion(clip, height);
        BodyMoves {
            scores: ClipKinematics::new(&clip),
            clip,
            height,
        }
    }

    /// The speed ratios, acceleration distance and acceleration p99 (against the clip's: the
    /// snaps a pass may add) of `motions`, pooled, as text.
    fn of(&self, motions: &[LocalMotion]) -> String {
        let kinematics = Kinematics::of_motions(motions, self.height);
        let moves = self.scores.score(&self.clip, &kinematics);
        let [p25, p50, p90] = moves.speed_ratios;
        let p99 = |values: &[f64]| {
            let mut v = values.to_vec();
            v.sort_by(f64::total_cmp);
            v.get(((v.len().max(1) - 1) as f64 * 0.99).round() as usize)
                .copied()
                .unwrap_or(0.0)
        };
        format!(
            "body speed p25 / p50 / p90 {p25:.2} / {p50:.2} / {p90:.2} x the clip's, acceleration distance {:.2}, acceleration p99 {:.2} x the clip's",
            moves.acceleration_distance,
            p99(&kinematics.accelerations) / p99(&self.clip.accelerations).max(f64::MIN_POSITIVE)
        )
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        return Err("usage: plant_sweep MODEL.onnx CLIP.bvh SAMPLES.json".into());
    }
    let model = Model::open(&args[1], &ModelOptions::default())?;
    let layout = &model.metadata().layout;
    let clip = encode_for_model(&read_bvh(Path::new(&args[2]))?, layout, None)?;
    let clip_motion = decode(layout, clip.features.view())?;
    let clip_metric = metric_features(layout, clip.features.view());
    let reference = FeetReference::new(layout, &clip_motion);
    let (features, _) = read_features(Path::new(&args[3]))?;
    let samples = features
        .outer_iter()
        .map(|s| Ok((decode(layout, s)?, layout.contact_labels(s))))
        .collect::<Result<Vec<_>, sinmdm::motion::MotionError>>()?;
    let benchmark = |motions: &[&LocalMotion]| -> Result<String, Box<dyn std::error::Error>> {
        let rows: Vec<_> = motions
            .iter()
            .zip(features.outer_iter())
            .map(|(m, made)| motion_metric_features(layout, m, made))
            .collect();
        let r = evaluate(clip_metric.view(), &rows, 2)?;
        Ok(format!(
            "{:.1} / {:.3}",
            r.coverage.mean, r.global_diversity.mean
        ))
    };

    let settings = settings();
    let clip_labels = layout.contact_labels(clip.features.view());
    print_contact_heights(
        layout,
        reference.ground(),
        "the clip",
        &[(clip_motion.clone(), clip_labels.clone())],
    );
    print_contact_heights(layout, reference.ground(), "the samples", &samples);
    let body = BodyMoves::new(&clip_motion, layout.skeleton_height);
    println!(
        "the clip planted with its own labels (how much a setting changes motion that is right):"
    );
    for (name, options) in &settings[..span_settings().len()] {
        let (planted, _) = plant_feet(
            layout,
            &clip_motion,
            &clip_labels,
            &Kept::default(),
            options,
        )?;
        let moved = mean_frame_distance(
            &motion_metric_features(layout, &planted, clip.features.view()),
            &clip_metric,
        );
        println!(
            "  {name}: mean per-frame distance to the clip {moved:.3}, skating {:.1} %, {}",
            100.0 * reference.scores(&planted).skating_ratio,
            body.of(std::slice::from_ref(&planted))
        );
    }

    let raw = print_reference_rows(layout, &reference, &clip_motion, &samples, &benchmark)?;
    let raw_motions: Vec<LocalMotion> = samples.iter().map(|(m, _)| m.clone()).collect();
    println!("raw: {}", body.of(&raw_motions));
    // The default once more over a ground 0.03 H lower, where almost nothing is lifted: what
    // lifting the root costs the figures.
    let mut lowered = layout.clone();
    lowered.ground = layout.ground.map(|g| g - 0.03 * layout.skeleton_height);
    let mut settings = settings;
    settings.push((LOWERED_GROUND, PlantOptions::default()));
    for (name, options) in settings {
        let at = if name == LOWERED_GROUND {
            &lowered
        } else {
            layout
        };
        let planting = Planting {
            layout: at,
            options: &options,
            samples: &samples,
        };
        let row = planting.row(&reference, &raw, &benchmark, &body)?;
        println!("{name} | {row}");
    }
    Ok(())
}

/// One setting of the sweep over the saved samples.
struct Planting<'a> {
    layout: &'a FeatureLayout,
    options: &'a PlantOptions,
    samples: &'a [(LocalMotion, Vec<Vec<f32>>)],
}

impl Planting<'_> {
    /// The table's row of the samples planted so (after the setting's name).
    fn row(
        &self,
        reference: &FeetReference,
        raw: &FeetScores,
        benchmark: &Benchmark<'_>,
        body: &BodyMoves,
    ) -> Result<String, Box<dyn std::error::Error>> {
        let started = std::time::Instant::now();
        let planted = self
            .samples
            .iter()
            .map(|(m, l)| plant_feet(self.layout, m, l, &Kept::default(), self.options))
            .collect::<Result<Vec<_>, _>>()?;
        let ms = started.elapsed().as_secs_f64() * 1000.0 / self.samples.len() as f64;
        let s = mean_scores(
            &planted
                .iter()
                .map(|(m, _)| reference.scores(m))
                .collect::<Vec<_>>(),
        );
        let lifted: usize = planted.iter().map(|(_, s)| s.lifted_frames).sum();
        let miss = format!(
            "{:.4}/{:.4}",
            planted.iter().map(|(_, s)| s.mean_miss).sum::<f64>() / planted.len() as f64,
            planted.iter().map(|(_, s)| s.max_miss).fold(0.0, f64::max)
        );
        let scores = benchmark(&planted.iter().map(|(m, _)| m).collect::<Vec<_>>())?;
        let moves = body.of(&planted.iter().map(|(m, _)| m.clone()).collect::<Vec<_>>());
        Ok(format!(
            "{:.1} | {:.4} | {:.1} | {:.3} | {scores} | {lifted} | {miss} | {ms:.1} | {moves}",
            100.0 * s.skating_ratio,
            s.max_penetration,
            100.0 * s.penetrating_frames,
            s.jitter / raw.jitter,
        ))
    }
}

/// Per contact joint, how high its point is above the ground (in skeleton heights) in the
/// frames whose label is at least [`CONTACT_ON`] (those the stance band is read from) and in the
/// others (p10 / p50 / p90), and the share of the
/// others within 0.05 H: how low the feet swing against how they stand.
fn print_contact_heights(
    layout: &FeatureLayout,
    ground: f64,
    what: &str,
    motions: &[(LocalMotion, Vec<Vec<f32>>)],
) {
    use sinmdm::motion::up::{height_of, to_canonical};
    let quantiles = |mut v: Vec<f64>| -> String {
        if v.is_empty() {
            return "-".into();
        }
        v.sort_by(f64::total_cmp);
        let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
        format!("{:.3} / {:.3} / {:.3}", q(0.1), q(0.5), q(0.9))
    };
    println!("contact heights of {what} (H above the ground, p10 / p50 / p90):");
    for (c, &joint) in layout.contact_joints.iter().enumerate() {
        let (mut on, mut off) = (Vec::new(), Vec::new());
        for (motion, labels) in motions {
            let poses = sinmdm::motion::global_poses(&to_canonical(motion, layout.up));
            for (f, pose) in poses.iter().enumerate() {
                let h = (height_of(pose.contact_point(joint)) - ground) / layout.skeleton_height;
                if labels[c][f] >= CONTACT_ON {
                    on.push(h)
                } else {
                    off.push(h)
                }
            }
        }
        let low = off.iter().filter(|&&h| h < 0.05).count() as f64 / off.len().max(1) as f64;
        println!(
            "  {}: contact {} | swing {} | swing within 0.05 H {:.0} %",
            layout.skeleton.joints[joint].name,
            quantiles(on),
            quantiles(off),
            100.0 * low
        );
    }
}

/// Prints the ground and the table's header, clip and raw rows; returns the raw samples' mean
/// scores, against which the settings' jitter is given.
fn print_reference_rows(
    layout: &FeatureLayout,
    reference: &FeetReference,
    clip_motion: &LocalMotion,
    samples: &[(LocalMotion, Vec<Vec<f32>>)],
    benchmark: &Benchmark<'_>,
) -> Result<FeetScores, Box<dyn std::error::Error>> {
    let clip_scores = reference.scores(clip_motion);
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
        "setting | skating % | deepest H | floor frames % | jitter ratio to raw | coverage / global diversity | lifted | miss mean/max H | ms/sample | how the body moves"
    );
    println!(
        "clip | {:.1} | {:.4} | {:.1} | {:.3} | | | |",
        100.0 * clip_scores.skating_ratio,
        clip_scores.max_penetration,
        100.0 * clip_scores.penetrating_frames,
        clip_scores.jitter / raw.jitter
    );
    println!(
        "raw | {:.1} | {:.4} | {:.1} | 1.000 | {} | | |",
        100.0 * raw.skating_ratio,
        raw.max_penetration,
        100.0 * raw.penetrating_frames,
        benchmark(&samples.iter().map(|(m, _)| m).collect::<Vec<_>>())?
    );
    Ok(raw)
}

/// The settings the sweep compares: the default, then one change each.
fn settings() -> Vec<(&'static str, PlantOptions)> {
    let mut settings = span_settings();
    settings.extend(hold_settings());
    settings.extend(release_and_solver_settings());
    settings
}

/// The default and the settings that change which frames are planted (each also plants the
/// clip).
fn span_settings() -> Vec<(&'static str, PlantOptions)> {
    let base = PlantOptions::default();
    vec![
        ("default", base),
        (
            "labelled spans only (no growth)",
            PlantOptions {
                grow_within: 0.0,
                ..base
            },
        ),
        (
            "spans grown within 0.08 H, not read from the stance",
            PlantOptions {
                grow_within: 0.08,
                grow_stance_quantile: None,
                ..base
            },
        ),
        (
            "spans grown by height alone, max hold 0.3 H, band 0.05 H (an earlier default)",
            PlantOptions {
                grow_stance_quantile: None,
                grow_below_speed: f64::INFINITY,
                release_above_speed: f64::INFINITY,
                max_hold: 0.3,
                ..base
            },
        ),
        (
            "spans grown by height alone",
            PlantOptions {
                grow_below_speed: f64::INFINITY,
                release_above_speed: f64::INFINITY,
                ..base
            },
        ),
        (
            "band 0.05 H, spans kept whole (the default before the stance band)",
            PlantOptions {
                grow_stance_quantile: None,
                release_above_speed: f64::INFINITY,
                ..base
            },
        ),
        (
            "band: stance p50",
            PlantOptions {
                grow_stance_quantile: Some(0.5),
                ..base
            },
        ),
        (
            "band: stance p90, below 1 H/s",
            PlantOptions {
                grow_stance_quantile: Some(0.9),
                grow_below_speed: 1.0,
                ..base
            },
        ),
        (
            "spans grown only below 0.3 H/s",
            PlantOptions {
                grow_below_speed: 0.3,
                ..base
            },
        ),
        (
            "spans grown only below 0.6 H/s",
            PlantOptions {
                grow_below_speed: 0.6,
                ..base
            },
        ),
        (
            "spans grown only below 1 H/s",
            PlantOptions {
                grow_below_speed: 1.0,
                ..base
            },
        ),
        (
            "spans grown only below 2 H/s",
            PlantOptions {
                grow_below_speed: 2.0,
                ..base
            },
        ),
        (
            "spans grown only below 3 H/s, kept whole",
            PlantOptions {
                grow_below_speed: 3.0,
                release_above_speed: f64::INFINITY,
                ..base
            },
        ),
    ]
}

/// The settings that change how a planted foot is held: root travel, hold, anchor, blend,
/// stance smoothing and reach.
fn hold_settings() -> Vec<(&'static str, PlantOptions)> {
    let base = PlantOptions::default();
    vec![
        (
            "root carried with the stance (share 1)",
            PlantOptions {
                root_stance_share: 1.0,
                ..base
            },
        ),
        (
            "root follows half the stance",
            PlantOptions {
                root_stance_share: 0.5,
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
            "max hold 0.5 H",
            PlantOptions {
                max_hold: 0.5,
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
            "blend 0.2 s",
            PlantOptions {
                blend_seconds: 0.2,
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
            "stance smoothed over 0.4 s",
            PlantOptions {
                stance_smoothing_seconds: 0.4,
                ..base
            },
        ),
        (
            "max hold 0.2 H",
            PlantOptions {
                max_hold: 0.2,
                ..base
            },
        ),
        (
            "soft reach 0",
            PlantOptions {
                soft_reach: 0.0,
                ..base
            },
        ),
    ]
}

/// The settings that let a stepping foot go inside its span, and the solver's iterations.
fn release_and_solver_settings() -> Vec<(&'static str, PlantOptions)> {
    let base = PlantOptions::default();
    vec![
        (
            "spans kept whole (released above no speed, the previous default)",
            PlantOptions {
                release_above_speed: f64::INFINITY,
                ..base
            },
        ),
        (
            "released above 1.5 H/s",
            PlantOptions {
                release_above_speed: 1.5,
                ..base
            },
        ),
        (
            "released above 1 H/s",
            PlantOptions {
                release_above_speed: 1.0,
                ..base
            },
        ),
        (
            "iterations 80",
            PlantOptions {
                iterations: 80,
                ..base
            },
        ),
    ]
}
