//! The quality metrics on hand-built cases from the shipped CMU walk: the clip itself, the clip
//! cut into short pieces and shuffled, and random noise.

use ndarray::{Array2, Axis, concatenate, s};
use sinmdm::bvh::read_bvh;
use sinmdm::motion::{EncodeOptions, encode};
use sinmdm_eval::{Report, body_metric_features, evaluate, metric_features};

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
    // The clip's first two seconds (at its 120 fps): the scores' cost grows with the square of
    // the frames, and the split over threads is what is checked, not the size.
    let clip = walk().slice(s![..240, ..]).to_owned();
    let samples: Vec<Array2<f64>> = (0..3).map(|seed| reordered(&clip, 40, seed)).collect();
    let one = evaluate(clip.view(), &samples, 1).unwrap();
    let two = evaluate(clip.view(), &samples, 2).unwrap();
    assert_eq!(one, two);
}

#[test]
fn the_body_metric_leaves_out_the_root_rotation_and_nothing_else() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/bvh/human_walk_cmu_131_01.bvh"
    );
    let encoded = encode(&read_bvh(path).unwrap(), &EncodeOptions::default()).unwrap();
    let layout = &encoded.layout;
    let all = metric_features(layout, encoded.features.view());
    let body = body_metric_features(layout, encoded.features.view());
    // The CMU walk's Hips are both its top joint and the joint that travels, and its rotation
    // comes first among the metric's columns: the body's are the rest, in order.
    assert_eq!(layout.skeleton.joints[0].parent, None);
    assert_eq!(layout.root.as_ref().unwrap().joint, 0);
    assert_eq!(body.ncols(), all.ncols() - 6);
    assert_eq!(body.nrows(), all.nrows());
    for (i, column) in body.columns().into_iter().enumerate() {
        assert_eq!(column, all.column(i + 6), "column {i}");
    }
}
