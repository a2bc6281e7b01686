//! Soft borders: the weight of each frame of a kept span, easing in from its gaps (SPEC
//! section 5). Shared by the tasks, streams and steering, and depending on nothing.

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
