//! Features back to a motion in the file's frame.

use ndarray::ArrayView2;

use super::error::MotionError;
use super::heading::{integrate, yaw};
use super::layout::FeatureLayout;
use crate::motion::clip::LocalMotion;
use crate::motion::math::{IDENTITY, Mat3, Vec3};
use crate::motion::rotation::mat_from_6d;
use crate::motion::up::{UP, to_file};

/// Turns features `[F, N]` back into local joint transforms in the file's frame (its up axis,
/// [`FeatureLayout::up`]). Contact labels are not needed to rebuild the pose and are ignored.
pub fn decode(
    layout: &FeatureLayout,
    features: ArrayView2<'_, f32>,
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
        && let Some(heading) = &root.heading
    {
        let column = |r: usize| -> Vec<f64> {
            features
                .row(row + r)
                .iter()
                .map(|&v| f64::from(v))
                .collect()
        };
        let (positions, headings) = integrate(
            &column(0),
            &column(1),
            &column(2),
            &column(3),
            root.start_position,
            heading.start,
        );
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
        for above in layout.skeleton.ancestors(*joint) {
            if layout.rotation_joints.contains(&above) {
                for f in 0..frames {
                    let k = f * joints + above;
                    rotations[k] = yaw(first) * rotations[k];
                }
            }
        }
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
