//! The per-frame feature vector the model learns, and the way back to a motion.
//!
//! Columns, in this order (each group may be empty):
//! 1. root: for the motion root's position channels, the two ground-plane axes as per-frame
//!    displacement (frame 0 copies frame 1) and the up axis as absolute height;
//! 2. rotations: the 6D rotation of every joint that has rotation channels, in joint order;
//! 3. positions: the non-root position channels that vary over the clip (absolute values);
//! 4. contacts: one 0/1 label per contact joint.
//!
//! Position channels that never change are static skeleton data ([`FeatureLayout::rest_translations`]),
//! and the root's first position is kept as [`RootFeatures::start_position`], so decoding
//! integrates the displacements back to world positions.
//!
//! Features live in the canonical Y-up frame ([`super::up`]): `encode` turns the clip into it
//! with the clip's detected (or given) up axis, recorded as [`FeatureLayout::up`], and `decode`
//! turns the motion back into the file's frame. So a Z-up clip and its Y-up twin have the same
//! features, and the root's axes below are canonical axes (Y = up).

use ndarray::{Array2, ArrayView2};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::clip::{ChannelClip, LocalMotion};
use super::contacts::{ContactConfig, choose_contact_joints, label_contacts};
use super::fk::{global_pose, global_poses, skeleton_height};
use super::math::{self, IDENTITY, Mat3, Vec3};
use super::resample::resample;
use super::rotation::{mat_from_6d, mat_to_6d};
use super::skeleton::{Axis, Channel, Skeleton};
use super::up::{UP, UpAxis, UpDetection, choose_up, to_canonical, to_file};

/// Errors while turning a clip into features or features into a clip.
#[derive(Debug, Error, PartialEq)]
pub enum MotionError {
    /// The clip has no frames.
    #[error("the clip has no frames")]
    NoFrames,
    /// A contact joint named in the configuration is not in the skeleton.
    #[error("contact joint '{name}' is not in the skeleton (joints: {available})")]
    UnknownContactJoint {
        /// The name that was asked for.
        name: String,
        /// The skeleton's joint names, comma-separated.
        available: String,
    },
    /// A contact threshold or ground fraction that is negative or not a number.
    #[error("contact {what} must be a finite number >= 0, got {value}")]
    BadContactSetting {
        /// Which setting.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A target frame rate that is zero, negative or not a number.
    #[error("frame rate must be a positive number, got {0}")]
    BadFrameRate(f64),
    /// A feature array whose row count does not match the layout.
    #[error("features have {got} rows but the layout describes {expected}")]
    WidthMismatch {
        /// Rows the layout expects.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// Resampling would make an absurdly long clip (a frame time of minutes, say).
    #[error(
        "resampling {frames} frames from {from_fps} fps to {to_fps} fps would give more than {limit} frames; check the clip's Frame Time"
    )]
    TooManyFrames {
        /// Frames in the clip.
        frames: usize,
        /// The clip's rate.
        from_fps: f64,
        /// The target rate.
        to_fps: f64,
        /// The largest clip accepted.
        limit: usize,
    },
    /// A clip whose skeleton is not the one the features are laid out for.
    #[error("the clip's skeleton differs from the model's: {0}")]
    SkeletonMismatch(String),
    /// A feature array holding NaN or infinity.
    #[error("features contain a non-finite value at row {row}, frame {frame}")]
    NonFinite {
        /// Feature row.
        row: usize,
        /// Frame.
        frame: usize,
    },
}

/// The root's share of the features.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RootFeatures {
    /// The joint that carries the clip's travel (the BVH root, or its only child when the root is
    /// a static container such as Bandai-Namco's `joint_Root`).
    pub joint: usize,
    /// Its position axes in the canonical frame, in X, Y, Z order: X and Z (the ground plane)
    /// become displacements, Y (up) stays absolute.
    pub axes: Vec<Axis>,
    /// Its local translation at frame 0 (canonical frame), where decoding starts integrating.
    pub start_position: Vec3,
    /// The rotation from the joint's parent frame to the canonical frame, when the joint hangs
    /// below a static container whose frame is turned (a Z-up rig whose `root` container holds
    /// the pelvis): its translation and rotation features are taken in the canonical frame, so
    /// height is height whatever the container's axes. Identity (and not written) otherwise.
    #[serde(default = "identity", skip_serializing_if = "is_identity")]
    pub frame: Mat3,
}

fn identity() -> Mat3 {
    IDENTITY
}

fn is_identity(m: &Mat3) -> bool {
    *m == IDENTITY
}

impl RootFeatures {
    /// Whether the features need the [`RootFeatures::frame`] turn.
    fn turned(&self) -> bool {
        !is_identity(&self.frame)
    }
}

/// What one feature column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ColumnKind {
    /// Root displacement per frame along X or Z.
    RootDisplacement(Axis),
    /// Root height (absolute Y).
    RootHeight,
    /// Component 0..6 of a joint's 6D rotation (`R00 R01 R02 R10 R11 R12`).
    Rotation6d(u8),
    /// A varying non-root position channel (absolute value).
    Position(Axis),
    /// A contact label.
    Contact,
}

/// One feature column: which joint and what.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Column {
    /// Joint index in the skeleton.
    pub joint: usize,
    /// What the column holds.
    pub kind: ColumnKind,
}

/// Which feature column is which, plus the static data needed to decode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureLayout {
    /// The skeleton the features belong to.
    pub skeleton: Skeleton,
    /// Frame rate of the feature sequence.
    pub fps: f64,
    /// Root features, absent when the motion root has no position channels.
    pub root: Option<RootFeatures>,
    /// Joints with a 6D rotation, in column order.
    pub rotation_joints: Vec<usize>,
    /// Varying non-root position channels, in column order.
    pub position_channels: Vec<(usize, Axis)>,
    /// Contact joints, in column order.
    pub contact_joints: Vec<usize>,
    /// Per joint: the OFFSET with constant position channels applied (the translation used when
    /// no feature animates it).
    pub rest_translations: Vec<Vec3>,
    /// Contact threshold in skeleton heights per second.
    pub contact_speed_threshold: f64,
    /// The skeleton height the thresholds are relative to (file units).
    pub skeleton_height: f64,
    /// The file's up axis: features are in the canonical Y-up frame, and decoding turns them
    /// back into this one. Model files written before the field existed are Y-up.
    #[serde(default)]
    pub up: UpAxis,
}

impl FeatureLayout {
    /// Number of feature columns (F).
    pub fn width(&self) -> usize {
        self.root.as_ref().map_or(0, |r| r.axes.len())
            + 6 * self.rotation_joints.len()
            + self.position_channels.len()
            + self.contact_joints.len()
    }

    /// Every column in order.
    pub fn columns(&self) -> Vec<Column> {
        let mut out = Vec::with_capacity(self.width());
        if let Some(root) = &self.root {
            for &axis in &root.axes {
                let kind = if axis.index() == UP {
                    ColumnKind::RootHeight
                } else {
                    ColumnKind::RootDisplacement(axis)
                };
                out.push(Column {
                    joint: root.joint,
                    kind,
                });
            }
        }
        for &joint in &self.rotation_joints {
            out.extend((0..6).map(|c| Column {
                joint,
                kind: ColumnKind::Rotation6d(c),
            }));
        }
        for &(joint, axis) in &self.position_channels {
            out.push(Column {
                joint,
                kind: ColumnKind::Position(axis),
            });
        }
        for &joint in &self.contact_joints {
            out.push(Column {
                joint,
                kind: ColumnKind::Contact,
            });
        }
        out
    }

    /// Column indices that belong to `joint` (its rotation, varying positions, root channels and
    /// contact label).
    pub fn joint_columns(&self, joint: usize) -> Vec<usize> {
        self.columns()
            .iter()
            .enumerate()
            .filter(|(_, c)| c.joint == joint)
            .map(|(i, _)| i)
            .collect()
    }

    /// A short human-readable name of a column, such as `LeftFoot.rot6d[2]`.
    pub fn column_name(&self, column: &Column) -> String {
        let joint = &self.skeleton.joints[column.joint].name;
        match column.kind {
            ColumnKind::RootDisplacement(axis) => format!("{joint}.d{axis}"),
            ColumnKind::RootHeight => format!("{joint}.Y"),
            ColumnKind::Rotation6d(c) => format!("{joint}.rot6d[{c}]"),
            ColumnKind::Position(axis) => format!("{joint}.{axis}position"),
            ColumnKind::Contact => format!("{joint}.contact"),
        }
    }
}

/// How a clip becomes features.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodeOptions {
    /// Target frame rate; `None` keeps the clip's own.
    pub fps: Option<f64>,
    /// Contact joints and threshold.
    pub contacts: ContactConfig,
    /// The clip's up axis; `None` detects it from the motion ([`super::up::detect_up`]).
    pub up: Option<UpAxis>,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            fps: Some(30.0),
            contacts: ContactConfig::default(),
            up: None,
        }
    }
}

/// A clip turned into features.
#[derive(Debug, Clone)]
pub struct EncodedClip {
    /// The column description (with the skeleton and static data).
    pub layout: FeatureLayout,
    /// Unnormalised features `[F, N]`.
    pub features: Array2<f32>,
    /// Share of frames in contact for each contact joint.
    pub contact_share: Vec<f64>,
    /// The up-axis detection and its evidence (`None` when the axis was given).
    pub up_detection: Option<UpDetection>,
    /// The clip is an in-place cycle (its root does not travel) and its contacts were labelled
    /// relative to the treadmill.
    pub in_place: bool,
}

/// The longest feature sequence `encode` makes (over nine hours at 30 fps).
pub const MAX_FRAMES: usize = 1_000_000;

/// Relative change under which a channel counts as constant.
const CONSTANT_TOLERANCE: f64 = 1e-9;

/// Whether each channel of the clip (in channel order) changes over the clip.
fn varying_channels(clip: &ChannelClip) -> Vec<bool> {
    let width = clip.skeleton.channel_count();
    let first = clip.frame(0);
    let mut varies = vec![false; width];
    for f in 1..clip.frame_count() {
        for (c, (&v, &v0)) in clip.frame(f).iter().zip(first).enumerate() {
            if (v - v0).abs() > CONSTANT_TOLERANCE * (1.0 + v0.abs()) {
                varies[c] = true;
            }
        }
    }
    varies
}

/// The joint that carries the clip's travel: the root, or, while a joint has no varying position
/// channel and exactly one child that has one, that child.
fn motion_root(skeleton: &Skeleton, varying_position: &[bool]) -> usize {
    let mut joint = 0;
    loop {
        if varying_position[joint] {
            return joint;
        }
        match skeleton.children(joint).as_slice() {
            [only] if varying_position[*only] => joint = *only,
            _ => return joint,
        }
    }
}

/// Refuses a resampling to `fps` that would make more than [`MAX_FRAMES`] frames.
fn check_resampled_length(clip: &ChannelClip, fps: f64) -> Result<(), MotionError> {
    let resampled = (clip.frame_count() as f64 - 1.0) * fps / clip.fps + 1.0;
    if resampled.is_nan() || resampled > MAX_FRAMES as f64 {
        return Err(MotionError::TooManyFrames {
            frames: clip.frame_count(),
            from_fps: clip.fps,
            to_fps: fps,
            limit: MAX_FRAMES,
        });
    }
    Ok(())
}

/// Turns a clip into features: resampled to `options.fps`, root displacement and height, 6D
/// rotations, varying positions and contact labels.
pub fn encode(clip: &ChannelClip, options: &EncodeOptions) -> Result<EncodedClip, MotionError> {
    if clip.frame_count() == 0 {
        return Err(MotionError::NoFrames);
    }
    let fps = options.fps.unwrap_or(clip.fps);
    if !(fps.is_finite() && fps > 0.0) {
        return Err(MotionError::BadFrameRate(fps));
    }
    for (what, value) in [
        ("speed threshold", options.contacts.speed_threshold),
        ("ground fraction", options.contacts.ground_fraction),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(MotionError::BadContactSetting { what, value });
        }
    }
    check_resampled_length(clip, fps)?;
    let skeleton = &clip.skeleton;
    let varies = varying_channels(clip);
    let starts = skeleton.channel_starts();
    let position_varies = |j: usize, axis: Axis| {
        skeleton.joints[j]
            .channels
            .iter()
            .position(|c| *c == Channel::Position(axis))
            .is_some_and(|c| varies[starts[j] + c])
    };
    let any_position_varies: Vec<bool> = (0..skeleton.len())
        .map(|j| {
            [Axis::X, Axis::Y, Axis::Z]
                .iter()
                .any(|&a| position_varies(j, a))
        })
        .collect();
    let root_joint = motion_root(skeleton, &any_position_varies);

    let file_local = clip.to_local();
    let (up, up_detection) = choose_up(&file_local, options.up);
    let canonical_from_file = up.canonical_from_file();
    let local = to_canonical(&resample(&file_local, fps), up);
    let joints = skeleton.len();

    let first = clip.frame(0);
    let rest_translations: Vec<Vec3> = skeleton
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let mut translation = joint.offset;
            for (c, channel) in joint.channels.iter().enumerate() {
                if let Channel::Position(axis) = channel {
                    translation[axis.index()] = first[starts[j] + c];
                }
            }
            if joint.parent.is_none() {
                translation = math::mat_vec(&canonical_from_file, translation);
            }
            translation
        })
        .collect();
    // A motion root below the top joint sits in its container's frame; take that frame (at
    // frame 0: the container is static) to the canonical one.
    // Entries within 1e-9 of 0 or +-1 are snapped, so a container turned by a quarter turn
    // written as text (cos 90 = 6e-17) gives an exact axis permutation.
    let frame = match skeleton.joints[root_joint].parent {
        Some(parent) => global_pose(&local, 0).rotations[parent].map(|row| {
            row.map(|v| {
                if (v - v.round()).abs() < 1e-9 {
                    v.round() + 0.0
                } else {
                    v
                }
            })
        }),
        None => IDENTITY,
    };
    let to_canonical_axes = if root_joint == 0 {
        canonical_from_file
    } else {
        frame
    };
    let mut root_axes: Vec<usize> = skeleton.joints[root_joint]
        .position_axes()
        .iter()
        .map(|a| {
            let column = [0, 1, 2].map(|i| to_canonical_axes[i][a.index()].abs());
            (0..3)
                .max_by(|&x, &y| column[x].total_cmp(&column[y]))
                .unwrap_or(a.index())
        })
        .collect();
    root_axes.sort_unstable();
    root_axes.dedup();
    let root = (!root_axes.is_empty()).then(|| RootFeatures {
        joint: root_joint,
        axes: root_axes.into_iter().map(Axis::from_index).collect(),
        start_position: math::mat_vec(&frame, local.translations[root_joint]),
        frame,
    });
    let rotation_joints: Vec<usize> = (0..joints)
        .filter(|&j| skeleton.joints[j].rotates())
        .collect();
    let position_channels: Vec<(usize, Axis)> = (0..joints)
        .filter(|&j| j != root_joint || root.is_none())
        .flat_map(|j| {
            [Axis::X, Axis::Y, Axis::Z]
                .into_iter()
                .filter(move |&a| position_varies(j, a))
                .map(move |a| (j, a))
        })
        .collect();

    let poses = global_poses(&local);
    let height = skeleton_height(&poses);
    let contact_joints = match &options.contacts.joints {
        Some(names) => names
            .iter()
            .map(|name| {
                skeleton
                    .find(name)
                    .ok_or_else(|| MotionError::UnknownContactJoint {
                        name: name.clone(),
                        available: skeleton
                            .joints
                            .iter()
                            .map(|j| j.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", "),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?,
        None => choose_contact_joints(skeleton, &poses, height, options.contacts.ground_fraction),
    };

    let layout = FeatureLayout {
        skeleton: skeleton.clone(),
        fps,
        root,
        rotation_joints,
        position_channels,
        contact_joints,
        rest_translations,
        contact_speed_threshold: options.contacts.speed_threshold,
        skeleton_height: height,
        up,
    };

    let filled = fill_features(&layout, &local, &poses);
    Ok(EncodedClip {
        layout,
        features: filled.features,
        contact_share: filled.contact_share,
        up_detection,
        in_place: filled.in_place,
    })
}

/// What [`fill_features`] makes.
struct Filled {
    features: Array2<f32>,
    contact_share: Vec<f64>,
    in_place: bool,
}

/// Writes the columns of `layout` for `local` (canonical frame, already at the layout's frame
/// rate, `poses` its global poses), with each contact joint's share of frames in contact.
fn fill_features(
    layout: &FeatureLayout,
    local: &LocalMotion,
    poses: &[super::fk::GlobalPose],
) -> Filled {
    let frames = local.frame_count();
    let joints = layout.skeleton.len();
    let fps = layout.fps;
    let height = layout.skeleton_height;
    let mut features = Array2::<f32>::zeros((layout.width(), frames));
    let mut row = 0;
    if let Some(root) = &layout.root {
        for &axis in &root.axes {
            let a = axis.index();
            let at = |f: usize| {
                let t = local.translations[f * joints + root.joint];
                if root.turned() {
                    math::mat_vec(&root.frame, t)[a]
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
    let root_turn = layout
        .root
        .as_ref()
        .filter(|r| r.turned())
        .map(|r| (r.joint, r.frame));
    for &joint in &layout.rotation_joints {
        for f in 0..frames {
            let rotation = &local.rotations[f * joints + joint];
            let six = match root_turn {
                Some((j, frame)) if j == joint => mat_to_6d(&math::mat_mul(&frame, rotation)),
                _ => mat_to_6d(rotation),
            };
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

/// Encodes a clip of the same skeleton in an existing layout (a model's): resampled to the
/// layout's frame rate, read with the layout's up axis, with the layout's columns, contact joints
/// and contact threshold, so the result lines up with the features the model was trained on.
pub fn encode_for(clip: &ChannelClip, layout: &FeatureLayout) -> Result<Array2<f32>, MotionError> {
    if clip.frame_count() == 0 {
        return Err(MotionError::NoFrames);
    }
    if let Some(problem) = layout.skeleton.difference(&clip.skeleton) {
        return Err(MotionError::SkeletonMismatch(problem));
    }
    check_resampled_length(clip, layout.fps)?;
    let local = to_canonical(&resample(&clip.to_local(), layout.fps), layout.up);
    let poses = global_poses(&local);
    Ok(fill_features(layout, &local, &poses).features)
}

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
            *t = math::mat_vec(&root.frame, *t);
        }
    }
    let mut row = 0;
    if let Some(root) = &layout.root {
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
    for &(joint, axis) in &layout.position_channels {
        for f in 0..frames {
            translations[f * joints + joint][axis.index()] = f64::from(features[[row, f]]);
        }
        row += 1;
    }
    if let Some(root) = layout.root.as_ref().filter(|r| r.turned()) {
        let back = math::transpose(&root.frame);
        for f in 0..frames {
            let k = f * joints + root.joint;
            translations[k] = math::mat_vec(&back, translations[k]);
            rotations[k] = math::mat_mul(&back, &rotations[k]);
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
