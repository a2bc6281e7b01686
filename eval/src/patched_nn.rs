//! Global diversity: the patched nearest neighbour of a sample in the clip.
//!
//! The sample is cut into consecutive segments of at least `min_segment` frames, each segment is
//! matched frame by frame to the clip at the offset that fits it best, and the cut with the least
//! total distance wins. Its cost per sample frame is the global diversity: near 0 when the sample
//! is the clip (or long pieces of it) replayed, larger when the sample makes new motion.
//!
//! The direct dynamic programme `G[j] = min over l <= j - m, k of G[l] + cost(l..j at k)` looks at
//! a table of `La^2 x Lb` segment costs. Written per diagonal `d = k - l` of the frame distance
//! table, a segment's cost is `C_d(j) - C_d(l)` with `C_d` the running sum along that diagonal,
//! so `G[j] = min over d of C_d(j) + min over l <= j - m of (G[l] - C_d(l))`. The inner minimum
//! only gains one candidate `l = j - m` per step, so one running minimum per diagonal replaces the
//! table: `O(La (La + Lb))` time and `O(La + Lb)` memory beyond the distance table.

use super::window_match::DiagonalSums;

/// The least cost per frame of covering all of `a` with segments of at least `min_segment`
/// frames, each matched to `b` (the clip) at its best offset. `None` when no cut exists (`a` or
/// `b` shorter than `min_segment`, or `min_segment` 0).
pub fn patched_nearest_neighbour(sums: &DiagonalSums, min_segment: usize) -> Option<f64> {
    let (la, lb) = (sums.a_frames(), sums.b_frames());
    if min_segment == 0 || la < min_segment || lb < min_segment {
        return None;
    }
    // Diagonal d = k - l runs over -la..=lb; index d + la.
    let diagonals = la + lb + 1;
    let mut best_start = vec![f64::INFINITY; diagonals];
    let mut g = vec![f64::INFINITY; la + 1];
    g[0] = 0.0;
    for j in min_segment..=la {
        // The newest possible segment start.
        let l = j - min_segment;
        if g[l].is_finite() {
            // Diagonals on which a segment may start at l: 0 <= l + d <= lb.
            let d_lo = -(l as isize);
            let d_hi = lb as isize - l as isize;
            for d in d_lo..=d_hi {
                let candidate = g[l] - sums.prefix(l, (l as isize + d) as usize);
                let slot = &mut best_start[(d + la as isize) as usize];
                if candidate < *slot {
                    *slot = candidate;
                }
            }
        }
        // A segment ending at j on diagonal d needs j + d <= lb.
        let d_hi = lb as isize - j as isize;
        let mut best = f64::INFINITY;
        for d in -(la as isize)..=d_hi {
            let start = best_start[(d + la as isize) as usize];
            if start.is_finite() {
                let k_end = j as isize + d;
                if k_end >= 0 {
                    let value = sums.prefix(j, k_end as usize) + start;
                    if value < best {
                        best = value;
                    }
                }
            }
        }
        g[j] = best;
    }
    g[la].is_finite().then(|| g[la].max(0.0) / la as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_data::{frame_distance, random_motion as motion};
    use ndarray::{Array2, s};

    /// Every cut of `a` into segments of >= m frames, each matched to `b` at every offset, with
    /// each segment's cost summed frame by frame: the definition, without shortcuts.
    fn brute_force(a: &Array2<f64>, b: &Array2<f64>, m: usize) -> Option<f64> {
        let frame = |i: usize, k: usize| frame_distance(a, i, b, k);
        let segment = |l: usize, j: usize| -> f64 {
            let n = j - l;
            if n > b.nrows() {
                return f64::INFINITY;
            }
            (0..=b.nrows() - n)
                .map(|k| (0..n).map(|t| frame(l + t, k + t)).sum::<f64>())
                .fold(f64::INFINITY, f64::min)
        };
        fn best(
            j: usize,
            m: usize,
            segment: &dyn Fn(usize, usize) -> f64,
            memo: &mut Vec<Option<f64>>,
        ) -> f64 {
            if j == 0 {
                return 0.0;
            }
            if let Some(v) = memo[j] {
                return v;
            }
            let mut v = f64::INFINITY;
            if j >= m {
                for l in 0..=j - m {
                    v = v.min(best(l, m, segment, memo) + segment(l, j));
                }
            }
            memo[j] = Some(v);
            v
        }
        let la = a.nrows();
        let mut memo = vec![None; la + 1];
        let total = best(la, m, &segment, &mut memo);
        total.is_finite().then(|| total / la as f64)
    }

    #[test]
    fn agrees_with_brute_force_on_small_inputs() {
        for (seed, la, lb, m) in [
            (1, 12, 8, 3),
            (2, 10, 10, 4),
            (3, 15, 6, 2),
            (4, 9, 20, 3),
            (5, 7, 7, 7),
            (6, 16, 5, 5),
            (7, 11, 9, 1),
        ] {
            let a = motion(la, 3, seed);
            let b = motion(lb, 3, seed + 100);
            let sums = DiagonalSums::new(a.view(), b.view(), false);
            let fast = patched_nearest_neighbour(&sums, m);
            let slow = brute_force(&a, &b, m);
            match (fast, slow) {
                (Some(x), Some(y)) => assert!((x - y).abs() < 1e-12, "{seed}: {x} vs {y}"),
                (x, y) => assert_eq!(x.is_some(), y.is_some(), "{seed}: {x:?} vs {y:?}"),
            }
        }
    }

    #[test]
    fn pieces_of_the_clip_cost_nothing() {
        let clip = motion(40, 3, 9);
        // 15 frames from the end, then 20 from the start: both pieces exist in the clip.
        let mut sample = Array2::zeros((35, 3));
        sample
            .slice_mut(s![..15, ..])
            .assign(&clip.slice(s![25..40, ..]));
        sample
            .slice_mut(s![15.., ..])
            .assign(&clip.slice(s![0..20, ..]));
        let sums = DiagonalSums::new(sample.view(), clip.view(), false);
        assert_eq!(patched_nearest_neighbour(&sums, 10), Some(0.0));
        // Segments of at least 20 frames must straddle the seam, so they cost something.
        assert!(patched_nearest_neighbour(&sums, 20).unwrap() > 0.05);
    }

    #[test]
    fn no_cut_when_too_short() {
        let a = motion(5, 2, 1);
        let b = motion(30, 2, 2);
        let sums = DiagonalSums::new(a.view(), b.view(), false);
        assert_eq!(patched_nearest_neighbour(&sums, 6), None);
        assert_eq!(patched_nearest_neighbour(&sums, 0), None);
        let sums = DiagonalSums::new(b.view(), a.view(), false);
        assert_eq!(patched_nearest_neighbour(&sums, 6), None);
    }
}
