//! Where each contact point should be: contact spans grown over the frames where the point is
//! low and slow, an anchor per span, and per frame a target that eases from the generated path
//! to the anchor and back.

use std::ops::Range;

use super::chain::LegChain;
use super::options::{Anchor, Kept, PlantOptions};
use super::spans::span_weights;
use crate::motion::math::Vec3;
use crate::motion::up::UP;

/// Spans grown on both sides over the frames where `low` holds, merged where they meet.
pub(super) fn grow_spans(
    spans: Vec<Range<usize>>,
    frames: usize,
    low: impl Fn(usize) -> bool,
) -> Vec<Range<usize>> {
    let mut grown: Vec<Range<usize>> = Vec::with_capacity(spans.len());
    for mut span in spans {
        while span.start > 0 && low(span.start - 1) {
            span.start -= 1;
        }
        while span.end < frames && low(span.end) {
            span.end += 1;
        }
        match grown.last_mut() {
            Some(last) if last.end >= span.start => last.end = last.end.max(span.end),
            _ => grown.push(span),
        }
    }
    grown
}

/// Spans with the frames where `fast` holds taken out, each piece kept if it is at least
/// `min_frames` long: a foot the network moves fast within a labelled span is stepping, not
/// standing.
pub(super) fn split_spans(
    spans: Vec<Range<usize>>,
    min_frames: usize,
    fast: impl Fn(usize) -> bool,
) -> Vec<Range<usize>> {
    let mut pieces = Vec::with_capacity(spans.len());
    for span in spans {
        let mut start = span.start;
        for f in span.clone() {
            if fast(f) {
                if f - start >= min_frames.max(1) {
                    pieces.push(start..f);
                }
                start = f + 1;
            }
        }
        if span.end.saturating_sub(start) >= min_frames.max(1) {
            pieces.push(start..span.end);
        }
    }
    pieces
}

/// The point a span holds its contact point at, on or above the ground.
fn anchor(points: &[Vec3], span: Range<usize>, kind: Anchor, ground: f64) -> Vec3 {
    let mut at = match kind {
        Anchor::Landing => points[span.start],
        Anchor::Mean => {
            let n = span.len() as f64;
            let sum = points[span].iter().fold(Vec3::ZERO, |a, &p| a + p);
            sum * (1.0 / n)
        }
    };
    at[UP] = at[UP].max(ground);
    at
}

/// What one chain's targets are computed from.
pub(super) struct ChainTrack<'a> {
    /// The chain.
    pub(super) chain: &'a LegChain,
    /// Its contact point, frame by frame.
    pub(super) points: &'a [Vec3],
    /// Its contact spans.
    pub(super) spans: &'a [Range<usize>],
}

/// Per frame, where the chain's contact point should be (`None`: leave it), and how many frames
/// hold it fully still. Inside a span it is the span's anchor; over `blend` frames on each side
/// it is the generated path carrying a fading share of the anchor's offset from the span's
/// nearest end (a fixed offset that fades, so the point never chases a foot that swings away);
/// a pull is never longer than `max_hold` heights; outside spans, only a point below the ground
/// gets a target (on it). Frames where a task kept any joint of the chain get none.
pub(super) fn chain_targets(
    track: &ChainTrack<'_>,
    kept: &Kept,
    options: &PlantOptions,
    (ground, height, blend): (f64, f64, usize),
) -> (Vec<Option<Vec3>>, usize) {
    let ChainTrack {
        chain,
        points,
        spans,
    } = track;
    let frames = points.len();
    let anchors: Vec<Vec3> = spans
        .iter()
        .map(|s| anchor(points, s.clone(), options.anchor, ground))
        .collect();
    let weights = span_weights(spans, frames, blend);
    let mut planted = 0;
    let targets = (0..frames)
        .map(|f| {
            if chain.joints.iter().any(|&j| kept.joint(f, j)) {
                return None;
            }
            let mut target = points[f];
            if let Some((span, w)) = weights[f] {
                let s = &spans[span];
                let edge = if f < s.start { s.start } else { s.end - 1 };
                let offset = anchors[span] - points[edge];
                let pull = if s.contains(&f) {
                    anchors[span] - points[f]
                } else {
                    offset * w
                };
                let length = pull.norm();
                let most = options.max_hold * height;
                target = points[f] + (pull * (if length > most { most / length } else { 1.0 }));
                if w >= 1.0 {
                    planted += 1;
                }
            } else if target[UP] >= ground {
                return None;
            }
            target[UP] = target[UP].max(ground);
            Some(target)
        })
        .collect();
    (targets, planted)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_grow_over_low_frames_and_merge() {
        let low = |f: usize| (3..=6).contains(&f) || f == 9;
        let grown = grow_spans(vec![4..5, 6..7, 10..12], 14, low);
        assert_eq!(grown, vec![3..7, 9..12]);
    }

    #[test]
    fn fast_frames_split_a_span_and_short_pieces_go() {
        let fast = |f: usize| [5, 6, 12, 20, 29].contains(&f);
        // 2..10: frames 5 and 6 go, 2..5 (3 frames) and 7..10 (3) stay at a minimum of 3.
        // 12..16: its fast first frame goes, 13..16 stays. 18..21: 18..20 (2 frames) and
        // nothing after the fast 20 are under 3. 25..30: its fast last frame goes, 25..29 stays.
        // 31..34 has no fast frame and stays whole.
        let spans = vec![2..10, 12..16, 18..21, 25..30, 31..34];
        assert_eq!(
            split_spans(spans.clone(), 3, fast),
            vec![2..5, 7..10, 13..16, 25..29, 31..34]
        );
        // At a minimum of 2 the piece 18..20 stays too.
        assert_eq!(
            split_spans(spans, 2, fast),
            vec![2..5, 7..10, 13..16, 18..20, 25..29, 31..34]
        );
        // A span ending at the clip's last frame (here 40) splits the same way.
        assert_eq!(
            split_spans(vec![30..33, 35..40], 1, |f| f == 39),
            vec![30..33, 35..39]
        );
    }

    #[test]
    fn an_anchor_never_goes_below_the_ground() {
        let points = [[0.0, -1.0, 0.0], [2.0, 1.0, 0.0], [4.0, -3.0, 0.0]].map(Vec3);
        assert_eq!(
            anchor(&points, 0..3, Anchor::Mean, 0.0),
            Vec3([2.0, 0.0, 0.0])
        );
        assert_eq!(
            anchor(&points, 1..3, Anchor::Landing, 0.0),
            Vec3([2.0, 1.0, 0.0])
        );
    }
}
