//! The denoiser's size and reach.

use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use sinmdm_train::config::ModelConfig;
use sinmdm_train::model::QnaUnet;
use sinmdm_train::model::weights::perturb;

/// The flex RNG is process-wide; tests that draw weights take turns so each is reproducible.
static RNG: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn paper() -> ModelConfig {
    ModelConfig {
        channels: 256,
        heads: 4,
        window: 3,
        dropout: 0.5,
        window_follows_fps: false,
    }
}

#[test]
fn paper_model_has_the_reference_parameter_count() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let device = Device::flex();
    let model = QnaUnet::new(174, &paper(), &device);
    assert_eq!(model.num_params(), 5_262_546);
}

/// GroupNorm statistics span the whole sequence, so any change anywhere moves every output a
/// little. To see the network's own reach, the input is a constant background with two distinct
/// frames `a` (at `i`) and `b` (at `j`), far apart; swapping them leaves every layer's multiset of
/// activations, hence every GroupNorm statistic, unchanged. The output may then change only within
/// 11 frames of `i` and of `j`.
#[test]
fn changing_one_frame_reaches_eleven_frames_each_side() {
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let device = Device::flex();
    device.seed(1);
    let config = ModelConfig {
        channels: 32,
        heads: 4,
        window: 3,
        dropout: 0.0,
        window_follows_fps: false,
    };
    assert_eq!(config.receptive_field(), 23);
    let (f, n, i, j) = (6, 200, 60, 140);
    let model = perturb(QnaUnet::new(f, &config, &device), 0.05);
    let background: Vec<f32> = (0..f).map(|r| 0.3 * r as f32 - 0.5).collect();
    let a: Vec<f32> = (0..f).map(|r| (r as f32 * 1.7).sin() * 2.0).collect();
    let b: Vec<f32> = (0..f).map(|r| (r as f32 * 0.9).cos() * 1.5).collect();
    let make = |at_i: &[f32], at_j: &[f32]| {
        let mut x = vec![0f32; f * n];
        for r in 0..f {
            for frame in 0..n {
                x[r * n + frame] = if frame == i {
                    at_i[r]
                } else if frame == j {
                    at_j[r]
                } else {
                    background[r]
                };
            }
        }
        x
    };
    let run = |x: Vec<f32>| {
        let x = Tensor::<3>::from_data(TensorData::new(x, [1, f, n]), &device);
        let t = Tensor::<1>::from_data(TensorData::new(vec![500.0f32], [1]), &device);
        model.forward(x, t).into_data().try_to_vec::<f32>().unwrap()
    };
    let (out, swapped) = (run(make(&a, &b)), run(make(&b, &a)));
    let change: Vec<f32> = (0..n)
        .map(|frame| {
            (0..f)
                .map(|r| (out[r * n + frame] - swapped[r * n + frame]).abs())
                .fold(0.0, f32::max)
        })
        .collect();
    let near = |frame: usize| {
        [i, j]
            .iter()
            .any(|&c| (frame as i64 - c as i64).abs() <= 11)
    };
    let outside = (0..n)
        .filter(|&k| !near(k))
        .map(|k| change[k])
        .fold(0.0, f32::max);
    let edge = change[i - 11]
        .min(change[i + 11])
        .min(change[j - 11])
        .min(change[j + 11]);
    eprintln!(
        "outside {outside:e} edges {:e} {:e} {:e} {:e} twelve {:e} {:e}",
        change[i - 11],
        change[i + 11],
        change[j - 11],
        change[j + 11],
        change[i - 12],
        change[j + 12]
    );
    assert!(
        outside < 1e-5,
        "output changed {outside:e} outside the 23-frame windows"
    );
    // Swapping frames reorders the GroupNorm sums, so float rounding (about 1e-6 here) shows up
    // everywhere; the reach of the window at +-11 frames is about 1e-4, well above it.
    assert!(
        edge > 30.0 * outside.max(1e-7),
        "frames i +- 11 changed only {edge:e}, against {outside:e} outside"
    );
}
