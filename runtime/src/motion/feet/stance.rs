//! The root carried by the feet on the ground: where a planted foot slides, the body travels
//! with it instead, so the legs need turning only for what the feet do differently from each
//! other. A root move changes no joint rotation and no bone length.

use crate::motion::math::Vec3;
use crate::motion::up::horizontal;

/// Per frame, the horizontal offset to add to the root so that the contact points in stance
/// stop sliding together.
///
/// `points[k][f]` is contact point `k` at frame `f` and `weights[k][f]` in `0..=1` how firmly it
/// is planted there (1 inside a contact span, easing to 0 outside). Between two frames, each
/// point's horizontal step counts with the smaller of its two weights; the root takes the
/// opposite of their weighted mean step, scaled by the total weight (up to 1), so a point
/// planted alone stays put and a swinging one pulls nothing. The per-frame moves are averaged
/// over `2 radius + 1` frames with triangular weights (a root that follows every tremor of a
/// foot would shake the whole body; a triangle lets through less of that tremor than a flat
/// average of the same width) and summed into offsets.
///
/// Where `kept[f]` the root is a task's reference and its offset is 0; a run of free frames
/// that ends at a kept frame hands its accumulated offset back linearly over the run, so the
/// root meets the kept frame exactly. A run without a kept frame after it keeps its offset
/// (the motion travels as far as its feet carry it).
pub(super) fn stance_travel(
    points: &[Vec<Vec3>],
    weights: &[Vec<f64>],
    kept: &[bool],
    radius: usize,
) -> Vec<Vec3> {
    let frames = kept.len();
    let mut step = vec![Vec3::ZERO; frames];
    for f in 1..frames {
        if kept[f] {
            continue;
        }
        let (mut sum, mut total) = (Vec3::ZERO, 0.0);
        for (p, w) in points.iter().zip(weights) {
            let weight = w[f].min(w[f - 1]);
            if weight > 0.0 {
                sum += horizontal(p[f] - p[f - 1]) * weight;
                total += weight;
            }
        }
        if total > 0.0 {
            step[f] = sum * (-total.min(1.0) / total);
        }
    }
    let smoothed: Vec<Vec3> = (0..frames)
        .map(|f| {
            if kept[f] {
                return Vec3::ZERO;
            }
            let window = f.saturating_sub(radius)..(f + radius + 1).min(frames);
            let (mut sum, mut total) = (Vec3::ZERO, 0.0);
            for g in window {
                let w = (radius + 1 - g.abs_diff(f)) as f64;
                sum += step[g] * w;
                total += w;
            }
            sum * (1.0 / total)
        })
        .collect();
    let mut offset = vec![Vec3::ZERO; frames];
    let mut start = 0;
    while start < frames {
        if kept[start] {
            start += 1;
            continue;
        }
        let end = (start..frames).find(|&f| kept[f]).unwrap_or(frames);
        let mut running = Vec3::ZERO;
        for f in start..end {
            running += smoothed[f];
            offset[f] = running;
        }
        if end < frames {
            // Hand the offset back so that the kept frame at `end` is met exactly.
            let span = (end - start + 1) as f64;
            for (i, f) in (start..end).enumerate() {
                offset[f] -= running * ((i + 1) as f64 / span);
            }
        }
        start = end;
    }
    offset
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::up::UP;

    fn along(x: f64, z: f64) -> Vec3 {
        let mut v = [0.0; 3];
        v[(UP + 1) % 3] = x;
        v[(UP + 2) % 3] = z;
        Vec3(v)
    }

    #[test]
    fn a_foot_planted_alone_is_held_by_the_root() {
        // The foot slides 0.01 per frame (and bobs vertically) through a span of frames 3..12.
        let frames = 16;
        let points: Vec<Vec3> = (0..frames)
            .map(|f| {
                let mut p = along(0.01 * f as f64, -0.002 * f as f64);
                p[UP] = 0.1 * (f % 3) as f64;
                p
            })
            .collect();
        let weights: Vec<f64> = (0..frames)
            .map(|f| if (3..12).contains(&f) { 1.0 } else { 0.0 })
            .collect();
        let offset = stance_travel(
            std::slice::from_ref(&points),
            &[weights],
            &vec![false; frames],
            0,
        );
        for f in 3..12 {
            let held = points[f] + offset[f];
            let first = points[3] + offset[3];
            let d = horizontal(held - first);
            assert!(d.norm() < 1e-12, "frame {f}: {d:?}");
            assert_eq!(offset[f][UP], 0.0);
        }
        // Outside the span the root keeps the offset it had (no pull from a swinging foot).
        assert_eq!(offset[0], Vec3([0.0; 3]));
        assert_eq!(offset[15], offset[11]);
    }

    #[test]
    fn two_planted_feet_share_and_a_half_weight_pulls_half() {
        let frames = 6;
        let a: Vec<Vec3> = (0..frames).map(|f| along(0.02 * f as f64, 0.0)).collect();
        let b: Vec<Vec3> = (0..frames).map(|_| along(0.0, 1.0)).collect();
        let full = vec![1.0; frames];
        // Both planted: the mean step is 0.01, so the root moves back 0.01 per frame.
        let offset = stance_travel(&[a.clone(), b], &[full.clone(), full], &[false; 6], 0);
        assert!((offset[5][(UP + 1) % 3] + 0.05).abs() < 1e-12);
        // One foot at weight 0.5: half of its step.
        let half = vec![0.5; frames];
        let offset = stance_travel(&[a], &[half], &[false; 6], 0);
        assert!((offset[5][(UP + 1) % 3] + 0.05).abs() < 1e-12);
    }

    #[test]
    fn kept_frames_are_met_exactly_and_smoothing_spreads_the_moves() {
        let frames = 20;
        let points: Vec<Vec3> = (0..frames).map(|f| along(0.01 * f as f64, 0.0)).collect();
        let weights = vec![1.0; frames];
        let mut kept = vec![false; frames];
        kept[0] = true;
        kept[19] = true;
        let offset = stance_travel(
            std::slice::from_ref(&points),
            std::slice::from_ref(&weights),
            &kept,
            2,
        );
        assert_eq!(offset[0], Vec3([0.0; 3]));
        assert_eq!(offset[19], Vec3([0.0; 3]));
        // The hand-back leaves the run's middle moving less than the foot, but still against it.
        assert!(offset[10][(UP + 1) % 3] < 0.0);
        // With nothing kept and a constant slide, smoothing changes nothing inside the clip.
        let offset = stance_travel(&[points], &[weights], &vec![false; frames], 2);
        for f in 4..frames - 3 {
            let step = offset[f][(UP + 1) % 3] - offset[f - 1][(UP + 1) % 3];
            assert!((step + 0.01).abs() < 1e-12, "frame {f}: {step}");
        }
    }
}
