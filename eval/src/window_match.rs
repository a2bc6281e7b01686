//! Per-frame distances between two motions and sums of them along matched windows.
//!
//! Matching frames `a[s..s+n]` against `b[k..k+n]` frame by frame costs
//! `sum_t dist(a[s+t], b[k+t])`: a sum along one diagonal of the frame distance table. Keeping
//! the running sums along every diagonal turns each window query into one subtraction, so the
//! metrics never store anything bigger than the `La x Lb` distance table itself.

use ndarray::ArrayView2;

/// Independent partial sums of [`squared_distance`]: enough to hide the latency of the adds and
/// fill a vector register, in a fixed order (the result does not depend on the machine).
const LANES: usize = 8;

/// `sum (x - y)^2` over two rows of the same width, summed in [`LANES`] interleaved partial sums
/// that are then added in order (the frame distance table's inner loop, where a single running
/// sum waits on each add).
fn squared_distance(x: &[f64], y: &[f64]) -> f64 {
    let mut partial = [0.0; LANES];
    let whole = x.len() / LANES * LANES;
    for (p, q) in x[..whole]
        .chunks_exact(LANES)
        .zip(y[..whole].chunks_exact(LANES))
    {
        for lane in 0..LANES {
            let d = p[lane] - q[lane];
            partial[lane] += d * d;
        }
    }
    let mut sum = partial.iter().sum::<f64>();
    for (p, q) in x[whole..].iter().zip(&y[whole..]) {
        let d = p - q;
        sum += d * d;
    }
    sum
}

/// Running sums of frame distances along the diagonals of the `a x b` distance table.
#[derive(Debug, Clone)]
pub struct DiagonalSums {
    a_frames: usize,
    b_frames: usize,
    /// `sums[(i) * (b_frames + 1) + k]` = sum of `dist(a[i - 1 - t], b[k - 1 - t])` for
    /// `t` in `0..min(i, k)`: the diagonal ending just before `(i, k)`.
    sums: Vec<f64>,
}

impl DiagonalSums {
    /// Euclidean distances between every frame of `a` and of `b` (rows are frames, columns
    /// features; both must have the same columns), summed along diagonals. `squared` sums squared
    /// distances instead.
    pub fn new(a: ArrayView2<'_, f64>, b: ArrayView2<'_, f64>, squared: bool) -> DiagonalSums {
        assert_eq!(a.ncols(), b.ncols(), "feature widths differ");
        let (la, lb) = (a.nrows(), b.nrows());
        let stride = lb + 1;
        let mut sums = vec![0.0; (la + 1) * stride];
        let (a, b) = (a.as_standard_layout(), b.as_standard_layout());
        let width = a.ncols();
        let a_rows = a.as_slice().expect("standard layout is contiguous");
        let b_rows = b.as_slice().expect("standard layout is contiguous");
        for i in 0..la {
            let x = &a_rows[i * width..(i + 1) * width];
            for k in 0..lb {
                let y = &b_rows[k * width..(k + 1) * width];
                let sq = squared_distance(x, y);
                let d = if squared { sq } else { sq.sqrt() };
                sums[(i + 1) * stride + k + 1] = sums[i * stride + k] + d;
            }
        }
        DiagonalSums {
            a_frames: la,
            b_frames: lb,
            sums,
        }
    }

    /// Frames of `a`.
    pub fn a_frames(&self) -> usize {
        self.a_frames
    }

    /// Frames of `b`.
    pub fn b_frames(&self) -> usize {
        self.b_frames
    }

    /// Running sum along the diagonal through `(i, k)`, counting the cells before it.
    #[inline]
    pub fn prefix(&self, i: usize, k: usize) -> f64 {
        self.sums[i * (self.b_frames + 1) + k]
    }

    /// Sum of distances matching `a[a_start..a_start+len]` to `b[b_start..b_start+len]`.
    #[inline]
    pub fn window(&self, a_start: usize, b_start: usize, len: usize) -> f64 {
        self.prefix(a_start + len, b_start + len) - self.prefix(a_start, b_start)
    }

    /// For each window `a[s..s+len]`, the mean per-frame distance to its best match anywhere in
    /// `b`. Empty when either side is shorter than `len`.
    pub fn nearest_a_windows(&self, len: usize) -> Vec<f64> {
        self.nearest_windows(len, self.a_frames, self.b_frames, |s, k| {
            self.window(s, k, len)
        })
    }

    /// For each window `b[k..k+len]`, the mean per-frame distance to its best match anywhere in
    /// `a`. Empty when either side is shorter than `len`.
    pub fn nearest_b_windows(&self, len: usize) -> Vec<f64> {
        self.nearest_windows(len, self.b_frames, self.a_frames, |k, s| {
            self.window(s, k, len)
        })
    }

    /// For each `len`-frame window of one side (`own` frames), the least `cost(own start, other
    /// start)` over the other side's windows, divided by `len`.
    fn nearest_windows(
        &self,
        len: usize,
        own: usize,
        other: usize,
        cost: impl Fn(usize, usize) -> f64,
    ) -> Vec<f64> {
        if len == 0 || own < len || other < len {
            return Vec::new();
        }
        (0..=own - len)
            .map(|i| {
                let best = (0..=other - len)
                    .map(|j| cost(i, j))
                    .fold(f64::INFINITY, f64::min);
                best / len as f64
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_data::{frame_distance as dist, random_motion as motion};

    #[test]
    fn squared_distances_match_one_running_sum() {
        for width in 0..20 {
            let x: Vec<f64> = (0..width).map(|i| (i as f64 * 0.37).sin()).collect();
            let y: Vec<f64> = (0..width).map(|i| (i as f64 * 0.91).cos()).collect();
            let naive: f64 = x.iter().zip(&y).map(|(p, q)| (p - q) * (p - q)).sum();
            let fast = squared_distance(&x, &y);
            assert!(
                (fast - naive).abs() <= 1e-14 * naive.max(1.0),
                "{width}: {fast} {naive}"
            );
        }
        assert_eq!(squared_distance(&[1.0; 9], &[1.0; 9]), 0.0);
        assert_eq!(squared_distance(&[3.0; 9], &[1.0; 9]), 36.0);
    }

    #[test]
    fn window_sums_match_direct_sums() {
        let a = motion(9, 3, 1);
        let b = motion(7, 3, 2);
        let sums = DiagonalSums::new(a.view(), b.view(), false);
        for len in 1..=7 {
            for s in 0..=9 - len {
                for k in 0..=7 - len {
                    let direct: f64 = (0..len).map(|t| dist(&a, s + t, &b, k + t)).sum();
                    assert!((sums.window(s, k, len) - direct).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn nearest_windows_of_a_copy_are_zero() {
        let a = motion(40, 4, 3);
        let sums = DiagonalSums::new(a.view(), a.view(), false);
        assert!(sums.nearest_a_windows(15).iter().all(|&d| d == 0.0));
        assert_eq!(sums.nearest_a_windows(15).len(), 26);
        assert!(sums.nearest_a_windows(41).is_empty());
    }

    #[test]
    fn nearest_b_windows_agree_with_swapped_sides() {
        let a = motion(20, 2, 4);
        let b = motion(13, 2, 5);
        let ab = DiagonalSums::new(a.view(), b.view(), false);
        let ba = DiagonalSums::new(b.view(), a.view(), false);
        let x = ab.nearest_b_windows(5);
        let y = ba.nearest_a_windows(5);
        assert_eq!(x.len(), y.len());
        for (p, q) in x.iter().zip(&y) {
            assert!((p - q).abs() < 1e-12);
        }
    }
}
