//! How well a steered motion did what it was asked: its distance from the path, how far along
//! the path it got, its speed and turn rate against velocity commands, and its facing against
//! facing commands.

use ndarray::ArrayView2;

use crate::model_file::ModelMetadata;
use crate::motion::FeatureLayout;
use crate::motion::features::heading::wrap;
use crate::motion::math::Vec3;
use crate::motion::root_track;
use crate::motion::up::UP;

use super::{FACING_CATCH_UP_SECONDS, STEER_REACH_SECONDS, SteerFrame, facing_of_direction};

/// How far from a frame's own path point its nearest point is sought, seconds.
pub const PROGRESS_WINDOW_SECONDS: f64 = 2.0;

/// A motion's root against a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathFollowing {
    /// Mean distance on the ground from the root to the path (to the nearest point of the
    /// path's polyline near the frame's own point), in skeleton heights.
    pub mean_distance: f64,
    /// The largest such distance, in skeleton heights.
    pub max_distance: f64,
    /// How far along the path the root's nearest point got by the last frame, as a share of
    /// the path's length: about 1 when it kept up. The nearest point of each frame is sought
    /// within [`PROGRESS_WINDOW_SECONDS`] of the path's point for that frame, so a path that
    /// comes back over itself (a figure eight) is not read short.
    pub progress: f64,
}

/// The root's canonical ground positions of heading-layout `features` (raw, `[F, N]`) from
/// the layout's start; `None` for another layout.
pub fn root_positions(layout: &FeatureLayout, features: ArrayView2<'_, f32>) -> Option<Vec<Vec3>> {
    let (positions, _) = root_track(layout, features, None)?;
    Some(
        positions
            .into_iter()
            .map(|mut p| {
                p[UP] = 0.0;
                p
            })
            .collect(),
    )
}

/// The root of `features` against the path of `commands` (their positions, file frame);
/// `None` for a layout without a heading-relative root or fewer than two points.
pub fn path_following(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
    commands: &[SteerFrame],
) -> Option<PathFollowing> {
    let to_canonical = layout.up.canonical_from_file();
    // The path's points with the frames they are for (frames without a position are left out).
    let (frames_of, path): (Vec<usize>, Vec<Vec3>) = commands
        .iter()
        .enumerate()
        .filter_map(|(f, c)| {
            let mut q = to_canonical * c.position()?;
            q[UP] = 0.0;
            Some((f, q))
        })
        .unzip();
    if path.len() < 2 {
        return None;
    }
    let positions = root_positions(layout, features)?;
    let mut along = vec![0.0; path.len()];
    for i in 1..path.len() {
        along[i] = along[i - 1] + (path[i] - path[i - 1]).norm();
    }
    let length = along[path.len() - 1].max(1e-12);
    // Nearest point of the polyline among the segments whose points are for frames near
    // `frame`: (distance, arc length there).
    let reach = (PROGRESS_WINDOW_SECONDS * layout.fps).ceil() as usize;
    let nearest = |frame: usize, p: Vec3| -> (f64, f64) {
        let mut best = (f64::INFINITY, 0.0);
        for i in 1..path.len() {
            if frames_of[i] + reach < frame || frames_of[i - 1] > frame + reach {
                continue;
            }
            let (a, b) = (path[i - 1], path[i]);
            let ab = b - a;
            let len2 = ab.dot(ab);
            let t = if len2 > 0.0 {
                ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (p - (a + ab * t)).norm();
            if d < best.0 {
                best = (d, along[i - 1] + t * len2.sqrt());
            }
        }
        best
    };
    // The frames the path covers.
    let (first, last) = (
        frames_of[0],
        frames_of[path.len() - 1].min(positions.len() - 1),
    );
    let distances: Vec<(f64, f64)> = (first..=last)
        .map(|f| nearest(f, positions[f]))
        .filter(|d| d.0.is_finite())
        .collect();
    if distances.is_empty() {
        return None;
    }
    let n = distances.len();
    let height = layout.skeleton_height;
    Some(PathFollowing {
        mean_distance: distances.iter().map(|d| d.0).sum::<f64>() / n as f64 / height,
        max_distance: distances.iter().map(|d| d.0).fold(0.0, f64::max) / height,
        progress: distances.last().map_or(0.0, |d| d.1) / length,
    })
}

/// A motion's forward speed and turn rate against velocity commands, averaged over windows.
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityFollowing {
    /// Per window: (commanded, achieved) mean forward speed, file units per second.
    pub forward: Vec<(f64, f64)>,
    /// Per window: (commanded, achieved) mean turn rate, radians per second.
    pub turn: Vec<(f64, f64)>,
}

/// Means over consecutive windows of `window` frames of the commanded and achieved forward
/// speed and turn rate (raw heading-layout `features`); windows without a velocity command
/// throughout are left out. `None` for another layout.
pub fn velocity_following(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
    commands: &[SteerFrame],
    window: usize,
) -> Option<VelocityFollowing> {
    layout.root.as_ref()?.heading.as_ref()?;
    let fps = layout.fps;
    let frames = features.ncols().min(commands.len());
    let mut out = VelocityFollowing {
        forward: Vec::new(),
        turn: Vec::new(),
    };
    let window = window.max(1);
    for start in (1..frames).step_by(window) {
        let end = (start + window).min(frames);
        let asked: Option<Vec<(f64, f64)>> = (start..end)
            .map(|f| match commands[f] {
                SteerFrame::Velocity { forward, turn } => Some((forward, turn)),
                _ => None,
            })
            .collect();
        let Some(asked) = asked else { continue };
        let count = (end - start) as f64;
        let mean = |values: Vec<f64>| values.iter().sum::<f64>() / count;
        out.forward.push((
            mean(asked.iter().map(|a| a.0).collect()),
            mean(
                (start..end)
                    .map(|f| f64::from(features[[0, f]]) * fps)
                    .collect(),
            ),
        ));
        out.turn.push((
            mean(asked.iter().map(|a| a.1).collect()),
            mean(
                (start..end)
                    .map(|f| f64::from(features[[2, f]]) * fps)
                    .collect(),
            ),
        ));
    }
    Some(out)
}

/// A motion's facing against facing commands, in degrees, over the frames that command a
/// facing, less the first [`FACING_SETTLE_SECONDS`] of each span of them (the time it is given
/// to turn there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacingFollowing {
    /// Frames measured.
    pub frames: usize,
    /// Median angle between the root's facing and the commanded one.
    pub median: f64,
    /// The 90th percentile of that angle.
    pub p90: f64,
}

/// How long a span of facing commands is given to turn the character before it is measured,
/// seconds: the catch-up plus the steering low-pass's reach.
pub const FACING_SETTLE_SECONDS: f64 = FACING_CATCH_UP_SECONDS + STEER_REACH_SECONDS;

/// The root's facing of `features` (raw, `[F, N]`, of `metadata`'s heading-relative model)
/// against the facings `commands` ask for; `None` for another layout or when no frame is
/// measured.
pub fn facing_following(
    metadata: &ModelMetadata,
    features: ArrayView2<'_, f32>,
    commands: &[SteerFrame],
) -> Option<FacingFollowing> {
    let (_, headings) = root_track(&metadata.layout, features, None)?;
    let settle = (FACING_SETTLE_SECONDS * metadata.layout.fps).round() as usize;
    let mut since_start = 0;
    let mut angles = Vec::new();
    for (f, c) in commands.iter().enumerate().take(headings.len()) {
        let Some(wanted) = c.facing().and_then(|d| facing_of_direction(metadata, d)) else {
            since_start = 0;
            continue;
        };
        since_start += 1;
        if since_start > settle {
            angles.push(wrap(headings[f] - wanted).abs().to_degrees());
        }
    }
    if angles.is_empty() {
        return None;
    }
    angles.sort_by(f64::total_cmp);
    let at = |q: f64| angles[((angles.len() - 1) as f64 * q).round() as usize];
    Some(FacingFollowing {
        frames: angles.len(),
        median: at(0.5),
        p90: at(0.9),
    })
}
