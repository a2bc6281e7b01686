//! Replay: how long a sample copies the clip verbatim.
//!
//! Coverage and diversity cannot tell a model that recombines its clip's motifs from one that
//! plays the clip back: a replaying model covers everything and still scores some diversity
//! where it jumps between copies. This measure looks for the copies themselves. A sample
//! replays the clip over frames `s..s+L` when some clip stretch `k..k+L` matches it frame by
//! frame, each pair within [`REPLAY_TOLERANCE`]; the sample's replay is its longest such run,
//! and a model's is the mean over its samples (at most 1 s is the goal for calm clips).
//!
//! A clip that holds one pose still for a while sets a floor under the measure: a sample that
//! holds that pose as long as the clip does matches the clip's consecutive held frames, one by
//! one, so its faithful hold counts as a copy of that length. [`longest_hold`] reads that floor
//! off the clip, and the report gives it beside the samples' runs.
//!
//! A clip that looks alike both ways over a stretch (a hold, a slow passage, a move and its
//! return) sets another: motion that is plainly not the clip played back still matches it over
//! long runs there. The report scores the clip played backwards ([`longest_backwards`]) as that
//! floor: a sample's replay near it is weak evidence that the sample copies the clip, one well
//! over it strong (on the fox's slow idle the clip backwards scores 2.00 s, its samples 1.97 s).
//!
//! Frames are compared by their 6D joint rotations alone (contact labels and root motion are
//! left out), as the root-mean-square difference per 6D component: a 6D component is a unit
//! vector's coordinate, so 0.05 is about 3 degrees of rotation on every joint, a distance that
//! does not grow with the skeleton's joint count.

use ndarray::{Array2, ArrayView1, ArrayView2, ArrayView3, s};
use serde::{Deserialize, Serialize};

use sinmdm::motion::{ColumnKind, FeatureLayout};

/// Largest root-mean-square difference per 6D component at which a sample frame copies a clip
/// frame.
pub const REPLAY_TOLERANCE: f64 = 0.05;

/// The 6D rotation values of a motion: rows are frames, columns every `Rotation6d` column of
/// `layout`, from features `[F, N]` in file units.
pub fn rotation_rows(layout: &FeatureLayout, features: ArrayView2<'_, f32>) -> Array2<f64> {
    crate::frame_rows(layout, features, |column| {
        matches!(column.kind, ColumnKind::Rotation6d(_))
    })
}

/// Whether one frame copies another: within a tolerance root-mean-square per column, compared
/// as a sum of squares, so no square root per pair.
struct FrameMatch {
    /// The largest sum of squared differences that still copies.
    limit: f64,
}

impl FrameMatch {
    fn new(tolerance: f64, columns: usize) -> Self {
        FrameMatch {
            limit: tolerance * tolerance * columns.max(1) as f64,
        }
    }

    fn copies(&self, a: ArrayView1<'_, f64>, b: ArrayView1<'_, f64>) -> bool {
        let mut sq = 0.0;
        for (p, q) in a.iter().zip(b.iter()) {
            let d = p - q;
            sq += d * d;
        }
        sq <= self.limit
    }
}

/// The longest run of consecutive `sample` frames that copy consecutive `clip` frames (rows are
/// frames, both with the same columns), each pair within `tolerance` root-mean-square per
/// column. 0 when no frame is that close.
pub fn longest_replay(
    sample: ArrayView2<'_, f64>,
    clip: ArrayView2<'_, f64>,
    tolerance: f64,
) -> usize {
    assert_eq!(sample.ncols(), clip.ncols(), "feature widths differ");
    let alike = FrameMatch::new(tolerance, clip.ncols());
    let clip_frames = clip.nrows();
    // run[k + 1]: length of the copy ending at the previous sample frame and clip frame k.
    let mut previous = vec![0usize; clip_frames + 1];
    let mut current = vec![0usize; clip_frames + 1];
    let mut longest = 0;
    for a in sample.rows() {
        for (k, b) in clip.rows().into_iter().enumerate() {
            current[k + 1] = if alike.copies(a, b) {
                previous[k] + 1
            } else {
                0
            };
            longest = longest.max(current[k + 1]);
        }
        std::mem::swap(&mut previous, &mut current);
    }
    longest
}

/// The longest the clip holds one of its own poses: the most consecutive `clip` frames (rows are
/// frames) that all lie within `tolerance` root-mean-square per column of one clip frame. A
/// sample that holds that pose as long copies those frames by [`longest_replay`]'s measure, so
/// this is the verbatim run a faithful hold is counted. 0 for an empty clip.
pub fn longest_hold(clip: ArrayView2<'_, f64>, tolerance: f64) -> usize {
    let alike = FrameMatch::new(tolerance, clip.ncols());
    let mut longest = 0;
    for pose in clip.rows() {
        let mut run = 0;
        for frame in clip.rows() {
            run = if alike.copies(pose, frame) {
                run + 1
            } else {
                0
            };
            longest = longest.max(run);
        }
    }
    longest
}

/// [`longest_replay`] with the clip played backwards as the sample, against the clip, in
/// frames: what motion that is not a copy scores on the measure, from the stretch of the clip
/// that looks most alike both ways. 0 for an empty clip; 1 for a clip whose frames all differ
/// (each frame meets only itself, never two in a row); a slow clip, many.
pub fn longest_backwards(clip: ArrayView2<'_, f64>, tolerance: f64) -> usize {
    longest_replay(clip.slice(s![..;-1, ..]), clip, tolerance)
}

/// The replay of a set of samples against their clip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReplayReport {
    /// The per-frame tolerance used ([`REPLAY_TOLERANCE`] unless asked otherwise).
    pub tolerance: f64,
    /// Frames per second of the motion, to turn frames into seconds.
    pub fps: f64,
    /// Each sample's longest verbatim run, in frames.
    pub longest_frames: Vec<usize>,
    /// Mean over the samples of their longest run, in seconds (the figure the goal is set on).
    pub mean_seconds: f64,
    /// The longest run of any sample, in seconds.
    pub max_seconds: f64,
    /// The longest the clip holds one pose ([`longest_hold`]), in frames: a sample that holds
    /// it as long is counted a copy this long (0 in reports written before this field).
    #[serde(default)]
    pub clip_hold_frames: usize,
    /// The same, in seconds.
    #[serde(default)]
    pub clip_hold_seconds: f64,
    /// [`longest_backwards`] of the clip, in frames: the replay that the clip played backwards,
    /// not a copy, scores (0 in reports written before this field).
    #[serde(default)]
    pub clip_backwards_frames: usize,
    /// The same, in seconds.
    #[serde(default)]
    pub clip_backwards_seconds: f64,
}

impl ReplayReport {
    /// Measures samples `[B, F, N]` against `clip` `[F, N]`, both raw features in `layout`.
    pub fn of_features(
        layout: &FeatureLayout,
        clip: ArrayView2<'_, f32>,
        samples: ArrayView3<'_, f32>,
        tolerance: f64,
    ) -> Self {
        let clip = rotation_rows(layout, clip);
        let samples: Vec<Array2<f64>> = samples
            .outer_iter()
            .map(|sample| rotation_rows(layout, sample))
            .collect();
        Self::measure(clip.view(), &samples, layout.fps, tolerance)
    }

    /// Measures every sample (rows are frames) against `clip`, at `fps` frames per second.
    pub fn measure(
        clip: ArrayView2<'_, f64>,
        samples: &[Array2<f64>],
        fps: f64,
        tolerance: f64,
    ) -> Self {
        let longest_frames: Vec<usize> = samples
            .iter()
            .map(|s| longest_replay(s.view(), clip, tolerance))
            .collect();
        let seconds = |frames: usize| frames as f64 / fps;
        let mean_seconds = if longest_frames.is_empty() {
            0.0
        } else {
            longest_frames.iter().map(|&f| seconds(f)).sum::<f64>() / longest_frames.len() as f64
        };
        let max_seconds = longest_frames.iter().copied().max().map_or(0.0, seconds);
        let clip_hold_frames = longest_hold(clip, tolerance);
        let clip_backwards_frames = longest_backwards(clip, tolerance);
        ReplayReport {
            tolerance,
            fps,
            longest_frames,
            mean_seconds,
            max_seconds,
            clip_hold_frames,
            clip_hold_seconds: seconds(clip_hold_frames),
            clip_backwards_frames,
            clip_backwards_seconds: seconds(clip_backwards_frames),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    /// A clip of pseudo-random values in [-1, 1]: any two of its frames differ by far more
    /// than the tolerance (about 0.8 root-mean-square).
    fn distinct_clip(frames: usize, width: usize) -> Array2<f64> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        Array2::from_shape_fn((frames, width), |_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
    }

    #[test]
    fn a_copied_stretch_is_found_with_its_length() {
        let clip = distinct_clip(60, 12);
        // Frames 0-9 unlike anything, then clip frames 20..45 with a small error, then others.
        let mut sample = Array2::from_elem((50, 12), 3.0);
        let copy = clip.slice(s![20..45, ..]).mapv(|v| v + 0.03);
        sample.slice_mut(s![10..35, ..]).assign(&copy);
        assert_eq!(longest_replay(sample.view(), clip.view(), 0.05), 25);
        // An error of 0.06 on every column is over the tolerance: no copy at all.
        let far = clip.slice(s![20..45, ..]).mapv(|v| v + 0.06);
        sample.slice_mut(s![10..35, ..]).assign(&far);
        assert_eq!(longest_replay(sample.view(), clip.view(), 0.05), 0);
    }

    #[test]
    fn the_tolerance_is_a_root_mean_square_per_column() {
        // One column off by 0.2 among 16: RMS 0.05, just at the tolerance.
        let clip = distinct_clip(10, 16);
        let mut sample = clip.clone();
        sample.column_mut(3).mapv_inplace(|v| v + 0.2);
        assert_eq!(longest_replay(sample.view(), clip.view(), 0.0501), 10);
        assert_eq!(longest_replay(sample.view(), clip.view(), 0.0499), 0);
    }

    #[test]
    fn a_run_must_follow_the_clip_in_order() {
        // The clip played backwards copies single frames, never two in a row.
        let clip = distinct_clip(40, 8);
        let reversed = clip.slice(s![..;-1, ..]).to_owned();
        assert_eq!(longest_replay(reversed.view(), clip.view(), 0.05), 1);
        // Two copies of 15 frames from different places: the longer run counts, not the sum.
        let mut sample = Array2::from_elem((40, 8), 5.0);
        sample
            .slice_mut(s![0..15, ..])
            .assign(&clip.slice(s![0..15, ..]));
        sample
            .slice_mut(s![15..35, ..])
            .assign(&clip.slice(s![5..25, ..]));
        assert_eq!(longest_replay(sample.view(), clip.view(), 0.05), 20);
    }

    #[test]
    fn a_held_pose_is_the_longest_run_of_frames_near_one_of_them() {
        // Frames 10..40 hold frame 10's pose, every other one off it by 0.04 on every column
        // (within 0.05 of it, and of each other).
        let mut clip = distinct_clip(60, 6);
        let pose = clip.row(10).to_owned();
        for (i, frame) in (10..40).enumerate() {
            let wobble = if i % 2 == 0 { 0.0 } else { 0.04 };
            clip.row_mut(frame).assign(&pose.mapv(|v| v + wobble));
        }
        assert_eq!(longest_hold(clip.view(), 0.05), 30);
        // A sample that holds the pose 30 frames copies the held frames one by one.
        let held = Array2::from_shape_fn((30, 6), |(_, c)| pose[c]);
        assert_eq!(longest_replay(held.view(), clip.view(), 0.05), 30);
        // Under a tighter tolerance no two consecutive frames are alike: the hold is one frame.
        assert_eq!(longest_hold(clip.view(), 0.03), 1);
        assert_eq!(longest_hold(clip.slice(s![..0, ..]), 0.05), 0);
    }

    #[test]
    fn the_report_gives_seconds() {
        let clip = distinct_clip(60, 6);
        let copy = |len: usize| {
            let mut s = Array2::from_elem((60, 6), 9.0);
            s.slice_mut(s![0..len, ..])
                .assign(&clip.slice(s![0..len, ..]));
            s
        };
        let report = ReplayReport::measure(clip.view(), &[copy(30), copy(60)], 30.0, 0.05);
        assert_eq!(report.longest_frames, vec![30, 60]);
        assert!((report.mean_seconds - 1.5).abs() < 1e-12);
        assert!((report.max_seconds - 2.0).abs() < 1e-12);
        assert_eq!(
            report.clip_hold_frames, 1,
            "no two frames of the clip alike"
        );
        assert!((report.clip_hold_seconds - 1.0 / 30.0).abs() < 1e-12);
        assert_eq!(
            report.clip_backwards_frames, 1,
            "backwards, each frame meets only itself"
        );
        assert!((report.clip_backwards_seconds - 1.0 / 30.0).abs() < 1e-12);
    }

    #[test]
    fn a_slow_clip_played_backwards_matches_itself_for_a_long_run() {
        // A clip whose first 20 frames drift 0.011 a frame on every column, the rest far apart.
        // Backwards, clip frame a meets clip frame b when both lie in the drift within 4 frames
        // of each other (0.044; 5 frames is 0.055). Along a run a falls by one a frame and b
        // rises by one, so a - b steps by 2: through 4, 2, 0, -2, -4 at the longest, 5 frames.
        let mut clip = distinct_clip(50, 4);
        for f in 0..20 {
            clip.row_mut(f).fill(0.011 * f as f64);
        }
        assert_eq!(longest_backwards(clip.view(), 0.05), 5);
        // Without the drift, backwards meets itself at single frames only.
        assert_eq!(longest_backwards(distinct_clip(50, 4).view(), 0.05), 1);
    }
}
