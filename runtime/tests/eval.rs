//! The quality metrics on hand-built cases from the shipped CMU walk: the clip itself, the clip
//! cut into short pieces and shuffled, and random noise.

use ndarray::{Array2, Axis, concatenate, s};
use sinmdm::bvh::read_bvh;
use sinmdm::eval::{Report, evaluate, metric_features};
use sinmdm::motion::{EncodeOptions, encode};

fn walk() -> Array2<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/bvh/human_walk_cmu_131_01.bvh"
    );
    let clip = read_bvh(path).expect("walk clip");
    let encoded = encode(&clip, &EncodeOptions::default()).expect("encode");
    metric_features(&encoded.layout, encoded.features.view())
}

/// A deterministic permutation of `0..n` (Fisher-Yates on a fixed LCG).
fn shuffled(n: usize, seed: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    let mut state = seed;
    for i in (1..n).rev() {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let j = (state >> 33) as usize % (i + 1);
        order.swap(i, j);
    }
    order
}

/// The clip cut into `piece`-frame pieces, put back in a shuffled order, twice over.
fn reordered(clip: &Array2<f64>, piece: usize, seed: u64) -> Array2<f64> {
    let pieces = clip.nrows() / piece;
    let mut parts = Vec::new();
    for round in 0..2 {
        for p in shuffled(pieces, seed + round) {
            parts.push(clip.slice(s![p * piece..(p + 1) * piece, ..]));
        }
    }
    concatenate(Axis(0), &parts).unwrap()
}

fn report(clip: &Array2<f64>, samples: &[Array2<f64>]) -> Report {
    evaluate(clip.view(), samples, 2).expect("evaluate")
}

#[test]
fn the_clip_itself_is_fully_covered_with_no_diversity() {
    let clip = walk();
    assert_eq!(
        clip.ncols(),
        31 * 6 + 2,
        "rotations of 31 joints and 2 foot contacts"
    );
    let twice = concatenate(Axis(0), &[clip.view(), clip.view()]).unwrap();
    for (sample, seams) in [(clip.clone(), 0), (twice, 1)] {
        let r = report(&clip, &[sample.clone(), sample]);
        assert_eq!(r.coverage.mean, 100.0);
        // The clip played twice is two pieces of the clip: still no global diversity.
        assert!(r.global_diversity.mean.abs() < 1e-9, "{r:?}");
        // Only the 14 windows across the seam of the replay are new locally.
        if seams == 0 {
            assert!(r.local_diversity.mean.abs() < 1e-9);
        } else {
            assert!(r.local_diversity.mean > 0.0 && r.local_diversity.mean < 0.1);
        }
        // Identical samples have no inter diversity.
        assert_eq!(r.inter_diversity.mean, 0.0);
    }
}

#[test]
fn shuffled_pieces_keep_coverage_and_raise_global_diversity() {
    let clip = walk();
    let copy = concatenate(Axis(0), &[clip.view(), clip.view()]).unwrap();
    let exact = report(&clip, std::slice::from_ref(&copy));
    // Pieces shorter than the 30-frame minimum segment: every matched segment crosses a seam.
    let samples: Vec<Array2<f64>> = (0..4).map(|seed| reordered(&clip, 20, seed)).collect();
    let r = report(&clip, &samples);
    assert!(
        r.coverage.mean >= 80.0,
        "coverage {:.1} should stay high",
        r.coverage.mean
    );
    assert!(
        r.global_diversity.mean > 0.5 && exact.global_diversity.mean < 1e-9,
        "global diversity {:.3} should rise well above the copy's {:.3}",
        r.global_diversity.mean,
        exact.global_diversity.mean
    );
    // Different shuffles differ from each other.
    assert!(r.inter_diversity.mean > 0.0);
    // The harmonic mean rewards the shuffle over the replay.
    assert!(r.harmonic_mean > exact.harmonic_mean);
}

#[test]
fn random_noise_covers_nothing() {
    let clip = walk();
    let mut state = 7u64;
    let noise = Array2::from_shape_fn((2 * clip.nrows(), clip.ncols()), |_| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    });
    let r = report(&clip, &[noise]);
    assert_eq!(r.coverage.mean, 0.0);
    assert_eq!(r.harmonic_mean, 0.0);
}

#[test]
fn thread_count_does_not_change_the_result() {
    let clip = walk();
    let samples: Vec<Array2<f64>> = (0..5).map(|seed| reordered(&clip, 40, seed)).collect();
    let one = evaluate(clip.view(), &samples, 1).unwrap();
    let two = evaluate(clip.view(), &samples, 2).unwrap();
    assert_eq!(one, two);
}

fn repo_file(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn test_model() -> std::path::PathBuf {
    std::env::var_os("SINMDM_TEST_MODEL")
        .map(Into::into)
        .unwrap_or_else(|| repo_file("tests/data/models/walk_tiny.onnx"))
}

fn sinmdm(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sinmdm"))
        .args(args)
        .output()
        .expect("run sinmdm")
}

#[test]
fn eval_command_prints_the_table_and_writes_json() {
    let dir = std::env::temp_dir().join(format!("sinmdm-eval-{}", std::process::id()));
    let json = dir.join("scores.json");
    let model = test_model();
    let clip = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let out = sinmdm(&[
        "eval".as_ref(),
        "-m".as_ref(),
        model.as_os_str(),
        "--clip".as_ref(),
        clip.as_os_str(),
        "--samples".as_ref(),
        "3".as_ref(),
        "--steps".as_ref(),
        "4".as_ref(),
        "--quiet".as_ref(),
        "--json".as_ref(),
        json.as_os_str(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for row in [
        "| coverage (%) ↑ |",
        "| global diversity ↑ |",
        "| local diversity ↑ |",
        "| inter diversity ↑ |",
        "| intra diversity diff ↓ |",
        "| harmonic mean ↑ |",
    ] {
        assert!(stdout.contains(row), "missing {row} in\n{stdout}");
    }
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(value["format"], "sinmdm-eval");
    assert_eq!(value["samples"], 3);
    // Twice the clip: 249 frames at 30 fps.
    assert_eq!(value["frames"], 498);
    let report: Report = serde_json::from_value(value["report"].clone()).unwrap();
    assert_eq!(report.per_sample.len(), 3);
    assert_eq!(report.sample_frames, 498);
    assert!((0.0..=100.0).contains(&report.coverage.mean));
    assert!((0.0..=1.0).contains(&report.harmonic_mean));
    assert!(report.global_diversity.mean.is_finite() && report.global_diversity.mean >= 0.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn eval_command_refuses_bad_input_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("sinmdm-eval-bad-{}", std::process::id()));
    let json = dir.join("scores.json");
    let model = test_model();
    let walk = repo_file("tests/data/bvh/human_walk_cmu_131_01.bvh");
    let fox = repo_file("tests/data/bvh/fox_survey_khronos.bvh");
    let cases: [(&[&std::ffi::OsStr], &str); 3] = [
        (
            &[
                "--clip".as_ref(),
                walk.as_os_str(),
                "--samples".as_ref(),
                "0".as_ref(),
            ],
            "--samples must be at least 1",
        ),
        (
            &["--clip".as_ref(), fox.as_os_str()],
            "skeleton differs from the model's",
        ),
        (
            &[
                "--clip".as_ref(),
                walk.as_os_str(),
                "--frames".as_ref(),
                "12".as_ref(),
                "--steps".as_ref(),
                "2".as_ref(),
            ],
            "--frames must be at least 30",
        ),
    ];
    for (extra, message) in cases {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "eval".as_ref(),
            "-m".as_ref(),
            model.as_os_str(),
            "--quiet".as_ref(),
            "--json".as_ref(),
            json.as_os_str(),
        ];
        args.extend_from_slice(extra);
        let out = sinmdm(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?} was accepted");
        assert!(stderr.contains(message), "{extra:?}: {stderr}");
        assert!(!json.exists(), "{extra:?} left {}", json.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
