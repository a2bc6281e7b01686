//! Features back to a motion in the file's frame.

use ndarray::ArrayView2;

use super::error::MotionError;
use super::heading::{integrate, yaw};
use super::layout::FeatureLayout;
use crate::motion::clip::LocalMotion;
use crate::motion::math::{IDENTITY, Mat3, Vec3};
use crate::motion::rotation::mat_from_6d;
use crate::motion::up::{UP, to_file};

/// Where a heading-relative root starts integrating: its canonical position (the up component
/// is ignored: height is a feature) and facing in frame 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootStart {
    /// The root joint's position, canonical frame.
    pub position: Vec3,
    /// The facing, radians about up from +Z toward +X.
    pub heading: f64,
}

impl RootStart {
    /// Where a layout's heading-relative root starts: its training clip's first position and
    /// facing; `None` for another root layout.
    pub fn of(layout: &FeatureLayout) -> Option<RootStart> {
        let root = layout.root.as_ref()?;
        Some(RootStart {
            position: root.start_position,
            heading: root.heading.as_ref()?.start,
        })
    }
}

/// Turns features `[F, N]` back into local joint transforms in the file's frame (its up axis,
/// [`FeatureLayout::up`]). Contact labels are not needed to rebuild the pose and are ignored.
pub fn decode(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
) -> Result<LocalMotion, MotionError> {
    decode_from(layout, features, None)
}

/// The heading-relative root's canonical position and facing in every frame of `features`,
/// integrated from `start` (the layout's start when `None`); `None` for another root layout.
pub fn root_track(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
    start: Option<RootStart>,
) -> Option<(Vec<Vec3>, Vec<f64>)> {
    let first = RootStart::of(layout)?;
    let start = start.unwrap_or(first);
    // Filled by a plain loop: collecting a mapped row iterator has memcheck report a branch on
    // the iterator's uninitialised size hint (a false report, but one that hides real ones).
    let column = |r: usize| -> Vec<f64> {
        let mut values = Vec::with_capacity(features.ncols());
        for &v in features.row(r) {
            values.push(f64::from(v));
        }
        values
    };
    Some(integrate(
        &column(0),
        &column(1),
        &column(2),
        &column(3),
        start.position,
        start.heading,
    ))
}

/// [`decode`], with a heading-relative root starting from `start` instead of the layout's
/// start (a stream continues its last block's course this way). `start` is ignored for a
/// world-layout root.
pub fn decode_from(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
    start: Option<RootStart>,
) -> Result<LocalMotion, MotionError> {
    let (width, frames) = features.dim();
    if width != layout.width() {
        return Err(MotionError::WidthMismatch {
            expected: layout.width(),
            got: width,
        });
    }
    if let Some(((row, frame), _)) = features.indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(MotionError::NonFinite { row, frame });
    }
    let joints = layout.skeleton.len();
    // A top joint without rotation channels keeps the file's orientation once turned back.
    let mut rest_rotations = vec![IDENTITY; joints];
    for (j, joint) in layout.skeleton.joints.iter().enumerate() {
        if joint.parent.is_none() && !joint.rotates() {
            rest_rotations[j] = layout.up.canonical_from_file();
        }
    }
    let mut rotations: Vec<Mat3> = (0..frames)
        .flat_map(|_| rest_rotations.iter().copied())
        .collect();
    let mut translations: Vec<Vec3> = (0..frames)
        .flat_map(|_| layout.rest_translations.iter().copied())
        .collect();
    if let Some(root) = layout.root.as_ref().filter(|r| r.turned()) {
        for f in 0..frames {
            let t = &mut translations[f * joints + root.joint];
            *t = root.frame * *t;
        }
    }
    let mut row = 0;
    // The facing per frame under the heading layout, to turn the root's rotation back by.
    let mut facing: Option<(usize, Vec<f64>)> = None;
    if let Some(root) = &layout.root
        && let Some((positions, headings)) = root_track(layout, features, start)
    {
        for (f, p) in positions.into_iter().enumerate() {
            translations[f * joints + root.joint] = p;
        }
        facing = Some((root.joint, headings));
        row += root.width();
    } else if let Some(root) = &layout.root {
        for &axis in &root.axes {
            let a = axis.index();
            let mut value = root.start_position[a];
            for f in 0..frames {
                let feature = f64::from(features[[row, f]]);
                if a == UP {
                    value = feature;
                } else if f > 0 {
                    value += feature;
                }
                translations[f * joints + root.joint][a] = value;
            }
            row += 1;
        }
    }
    let mut six = [0.0f64; 6];
    for &joint in &layout.rotation_joints {
        for f in 0..frames {
            for (c, value) in six.iter_mut().enumerate() {
                *value = f64::from(features[[row + c, f]]);
            }
            rotations[f * joints + joint] = mat_from_6d(&six);
        }
        row += 6;
    }
    if let Some((joint, headings)) = &facing {
        turn_back_to_facing(layout, *joint, headings, &mut rotations);
    }
    for &(joint, axis) in &layout.position_channels {
        for f in 0..frames {
            translations[f * joints + joint][axis.index()] = f64::from(features[[row, f]]);
        }
        row += 1;
    }
    if let Some(root) = layout.root.as_ref().filter(|r| r.turned()) {
        let back = root.frame.transpose();
        for f in 0..frames {
            let k = f * joints + root.joint;
            translations[k] = back * translations[k];
            rotations[k] = back * rotations[k];
        }
    }
    let canonical = LocalMotion {
        skeleton: layout.skeleton.clone(),
        fps: layout.fps,
        rotations,
        translations,
    };
    Ok(to_file(&canonical, layout.up))
}

/// Turns the motion root's rotation by its facing per frame, and the rotating joints above it
/// by the first facing (they were taken relative to it).
fn turn_back_to_facing(
    layout: &FeatureLayout,
    joint: usize,
    headings: &[f64],
    rotations: &mut [Mat3],
) {
    let joints = layout.skeleton.len();
    let frames = headings.len();
    for (f, &h) in headings.iter().enumerate() {
        let k = f * joints + joint;
        rotations[k] = yaw(h) * rotations[k];
    }
    // The joints above the motion root were taken relative to the first facing.
    let first = layout
        .root
        .as_ref()
        .and_then(|r| r.heading.as_ref())
        .map_or(0.0, |h| h.start);
    for above in layout.skeleton.ancestors(joint) {
        if layout.rotation_joints.contains(&above) {
            for f in 0..frames {
                let k = f * joints + above;
                rotations[k] = yaw(first) * rotations[k];
            }
        }
    }
}
