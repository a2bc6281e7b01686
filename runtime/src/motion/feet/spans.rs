//! Contact spans from predicted contact labels, and the weights that blend a planted point in
//! and out around them.

use std::ops::Range;

/// A label at or above this starts a contact ...
pub const CONTACT_ON: f32 = 0.6;
/// ... and one below this ends it (hysteresis: a label wobbling around 0.5 does not flicker).
pub const CONTACT_OFF: f32 = 0.4;

/// The frame spans in which `labels` say "in contact": entered at [`CONTACT_ON`], left below
/// [`CONTACT_OFF`], and at least `min_frames` long (shorter ones are flickers and dropped).
pub fn contact_spans(labels: &[f32], min_frames: usize) -> Vec<Range<usize>> {
    let mut spans = Vec::new();
    let mut start: Option<usize> = None;
    for (f, &label) in labels.iter().enumerate() {
        match start {
            None if label >= CONTACT_ON => start = Some(f),
            Some(s) if label < CONTACT_OFF || label.is_nan() => {
                spans.push(s..f);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push(s..labels.len());
    }
    spans.retain(|s| s.len() >= min_frames.max(1));
    spans
}

/// How strongly frame `f` is held to a span's anchor, and which span: 1 inside a span; outside,
/// a smoothstep falling to 0 over `blend` frames on each side (the nearest span wins); `None`
/// when no span is within reach.
pub fn span_weights(
    spans: &[Range<usize>],
    frames: usize,
    blend: usize,
) -> Vec<Option<(usize, f64)>> {
    (0..frames)
        .map(|f| {
            spans
                .iter()
                .enumerate()
                .filter_map(|(k, s)| {
                    let distance = if f < s.start {
                        s.start - f
                    } else if f >= s.end {
                        f + 1 - s.end
                    } else {
                        0
                    };
                    (distance <= blend).then(|| (k, blend_weight(distance, blend)))
                })
                .max_by(|a, b| a.1.total_cmp(&b.1))
        })
        .collect()
}

/// The weight `distance` frames outside a span with a border of `blend` frames: 1 at the span,
/// easing (smoothstep, so no step in speed) to 0 just past the border.
pub fn blend_weight(distance: usize, blend: usize) -> f64 {
    let x = 1.0 - distance as f64 / (blend + 1) as f64;
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hysteresis_and_minimum_length() {
        let labels = [
            0.0, 0.7, 0.5, 0.45, 0.3, 0.0, 0.9, 0.0, 0.0, 0.65, 0.55, 0.6, 0.5, 0.41, 0.39, 1.0,
        ];
        // 1..4 (0.5 and 0.45 stay in), the one-frame flicker at 6 is dropped, 9..14, and the last
        // frame alone is dropped too.
        assert_eq!(contact_spans(&labels, 2), vec![1..4, 9..14]);
        assert_eq!(contact_spans(&labels, 1), vec![1..4, 6..7, 9..14, 15..16]);
    }

    #[test]
    fn weights_ease_out_on_both_sides() {
        let span = 5..8;
        let w = span_weights(std::slice::from_ref(&span), 14, 3);
        let values: Vec<f64> = w.iter().map(|x| x.map_or(0.0, |(_, w)| w)).collect();
        assert_eq!(&values[5..8], &[1.0, 1.0, 1.0]);
        assert!(w[0].is_none() && w[1].is_none() && w[12].is_none());
        assert!(values[4] > values[3] && values[3] > values[2] && values[2] > 0.0);
        assert!((values[4] - values[8]).abs() < 1e-12 && (values[2] - values[10]).abs() < 1e-12);
        assert_eq!(values[11], 0.0);
        // smoothstep at 3/4, 1/2, 1/4
        assert!((values[4] - 0.84375).abs() < 1e-12);
    }
}
