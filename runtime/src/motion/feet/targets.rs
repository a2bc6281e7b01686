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
        let fast = |f: usize| f == 5 || f == 6 || f == 12;
        // 2..12: 2..5 kept (3 frames), 7..12 kept; 10..14: 10..12 is 2 frames, dropped at 3,
        // and 13..14 too; 20..22, shorter than 3 frames, goes too, and stays whole at 2.
        assert_eq!(
            split_spans(vec![2..12, 10..14, 20..22], 3, fast),
            vec![2..5, 7..12]
        );
        assert_eq!(
            split_spans(vec![2..12, 10..14, 20..22], 2, fast),
            vec![2..5, 7..12, 10..12, 20..22]
        );
        assert_eq!(
            split_spans(vec![0..4, 6..9], 1, |_| false),
            vec![0..4, 6..9]
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
