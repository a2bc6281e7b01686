//! The feature matrix of a clip whose layout is chosen: the root's columns, 6D rotations,
//! varying positions and contact labels, frame by frame.

use ndarray::Array2;

use super::heading::{facing_angles, root_columns, yaw};
use super::layout::{FeatureLayout, RootFeatures};
use crate::motion::clip::LocalMotion;
use crate::motion::contacts::label_contacts;
use crate::motion::math::Vec3;
use crate::motion::rotation::mat_to_6d;
use crate::motion::up::UP;

/// The root joint's position per frame in the canonical frame.
pub(super) fn root_positions(root: &RootFeatures, local: &LocalMotion) -> Vec<Vec3> {
    let joints = local.skeleton.len();
    (0..local.frame_count())
        .map(|f| {
            let t = local.translations[f * joints + root.joint];
            if root.turned() { root.frame * t } else { t }
        })
        .collect()
}

/// What [`fill_features`] makes.
pub(super) struct Filled {
    pub(super) features: Array2<f32>,
    pub(super) contact_share: Vec<f64>,
    pub(super) in_place: bool,
}

/// Writes the columns of `layout` for `local` (canonical frame, already at the layout's frame
/// rate, `poses` its global poses), with each contact joint's share of frames in contact.
pub(super) fn fill_features(
    layout: &FeatureLayout,
    local: &LocalMotion,
    poses: &[crate::motion::fk::GlobalPose],
) -> Filled {
    let frames = local.frame_count();
    let joints = layout.skeleton.len();
    let fps = layout.fps;
    let height = layout.skeleton_height;
    let mut features = Array2::<f32>::zeros((layout.width(), frames));
    let mut row = 0;
    // The facing per frame under the heading layout: the root's rotation is taken relative to it.
    let mut facing: Option<Vec<f64>> = None;
    if let Some(root) = &layout.root
        && let Some(heading) = &root.heading
    {
        let headings = facing_angles(poses, heading.left, heading.right, heading.smoothing * fps);
        let columns = root_columns(&root_positions(root, local), &headings);
        for values in columns {
            for (f, v) in values.into_iter().enumerate() {
                features[[row, f]] = v as f32;
            }
            row += 1;
        }
        facing = Some(headings);
    } else if let Some(root) = &layout.root {
        for &axis in &root.axes {
            let a = axis.index();
            let at = |f: usize| {
                let t = local.translations[f * joints + root.joint];
                if root.turned() {
                    (root.frame * t)[a]
                } else {
                    t[a]
                }
            };
            for f in 0..frames {
                features[[row, f]] = if a == UP {
                    at(f) as f32
                } else if frames < 2 {
                    0.0
                } else {
                    let g = f.max(1);
                    (at(g) - at(g - 1)) as f32
                };
            }
            row += 1;
        }
    }
    let root_joint = layout.root.as_ref().map(|r| r.joint);
    let root_turn = layout.root.as_ref().filter(|r| r.turned()).map(|r| r.frame);
    // Under the heading layout, the joints above the motion root (a static container) are
    // taken relative to the first facing, so a clip turned about up keeps its features.
    let above_root = root_joint.map_or_else(Vec::new, |r| layout.skeleton.ancestors(r));
    for &joint in &layout.rotation_joints {
        for f in 0..frames {
            let mut rotation = local.rotations[f * joints + joint];
            if root_joint == Some(joint) {
                if let Some(frame) = root_turn {
                    rotation = frame * rotation;
                }
                if let Some(headings) = &facing {
                    rotation = yaw(headings[f]).transpose() * rotation;
                }
            } else if let Some(headings) = &facing
                && above_root.contains(&joint)
            {
                rotation = yaw(headings[0]).transpose() * rotation;
            }
            let six = mat_to_6d(&rotation);
            for (c, value) in six.iter().enumerate() {
                features[[row + c, f]] = *value as f32;
            }
        }
        row += 6;
    }
    for &(joint, axis) in &layout.position_channels {
        for f in 0..frames {
            features[[row, f]] = local.translations[f * joints + joint][axis.index()] as f32;
        }
        row += 1;
    }
    let mut contact_share = Vec::with_capacity(layout.contact_joints.len());
    let labelled = label_contacts(
        poses,
        layout.root.as_ref().map_or(0, |r| r.joint),
        &layout.contact_joints,
        fps,
        height,
        layout.contact_speed_threshold,
    );
    for labels in labelled.labels {
        contact_share.push(labels.iter().map(|&l| f64::from(l)).sum::<f64>() / frames as f64);
        for (f, label) in labels.into_iter().enumerate() {
            features[[row, f]] = label;
        }
        row += 1;
    }
    debug_assert_eq!(row, layout.width());
    Filled {
        features,
        contact_share,
        in_place: labelled.in_place,
    }
}
