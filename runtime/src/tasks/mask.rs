//! Frame spans and the masks built from them (SPEC section 5).

use std::fmt;

/// A half-open range of frames `start..end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Span {
    /// First frame.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
}

impl Span {
    /// The span `start..end`.
    pub fn new(start: usize, end: usize) -> Span {
        Span { start, end }
    }

    /// Frames in the span.
    pub fn len(&self) -> usize {
        self.end.saturating_sub(self.start)
    }

    /// Whether the span holds no frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl fmt::Display for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.start, self.end)
    }
}

/// Which frames of `n` lie in some span.
pub fn covered(n: usize, spans: &[Span]) -> Vec<bool> {
    let mut inside = vec![false; n];
    for span in spans {
        for slot in &mut inside[span.start.min(n)..span.end.min(n)] {
            *slot = true;
        }
    }
    inside
}

/// A soft 0..1 weight per frame: 0 outside `keep`, and inside it `min(d, ramp) / ramp`, where `d`
/// is the distance in frames to the nearest frame outside (1 for a frame next to a gap). Frames
/// `ramp` or more frames from any gap weigh exactly 1; a frame with no gap anywhere weighs 1.
/// `ramp` 0 or 1 gives a hard mask.
pub fn soft_mask(keep: &[bool], ramp: usize) -> Vec<f32> {
    let n = keep.len();
    let far = usize::MAX / 2;
    let mut distance = vec![far; n];
    let mut last_gap: Option<usize> = None;
    for i in 0..n {
        if !keep[i] {
            last_gap = Some(i);
            distance[i] = 0;
        } else if let Some(g) = last_gap {
            distance[i] = i - g;
        }
    }
    let mut next_gap: Option<usize> = None;
    for i in (0..n).rev() {
        if !keep[i] {
            next_gap = Some(i);
        } else if let Some(g) = next_gap {
            distance[i] = distance[i].min(g - i);
        }
    }
    let ramp = ramp.max(1);
    distance
        .into_iter()
        .map(|d| d.min(ramp) as f32 / ramp as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn soft_mask_ramps_on_the_kept_side_only() {
        let keep = covered(12, &[Span::new(0, 5), Span::new(8, 12)]);
        let m = soft_mask(&keep, 3);
        let third = 1.0 / 3.0f32;
        let expected = [
            1.0,
            1.0,
            1.0,
            2.0 * third,
            third,
            0.0,
            0.0,
            0.0,
            third,
            2.0 * third,
            1.0,
            1.0,
        ];
        for (i, (a, b)) in m.iter().zip(expected).enumerate() {
            assert!((a - b).abs() < 1e-6, "frame {i}: {a} vs {b}");
        }
    }

    #[test]
    fn everything_kept_is_all_ones_and_nothing_kept_all_zeros() {
        assert!(soft_mask(&[true; 7], 10).iter().all(|&v| v == 1.0));
        assert!(soft_mask(&[false; 7], 10).iter().all(|&v| v == 0.0));
    }
}
