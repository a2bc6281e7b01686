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

pub use crate::soft_border::soft_mask;

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
