//! The feature layout: which column holds what, and the skeleton facts to decode them.

use serde::{Deserialize, Serialize};

use super::heading::{Heading, RootLayout};
use crate::motion::ground::Body;
use crate::motion::math::{IDENTITY, Mat3, Vec3};
use crate::motion::skeleton::{Axis, Skeleton};
use crate::motion::up::{UP, UpAxis};

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
    /// The heading-relative root's facts ([`super::heading`]); absent for the world layout,
    /// which every model file written before it existed has.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heading: Option<Heading>,
}

fn identity() -> Mat3 {
    IDENTITY
}

fn is_identity(m: &Mat3) -> bool {
    *m == IDENTITY
}

impl RootFeatures {
    /// Whether the features need the [`RootFeatures::frame`] turn.
    pub(crate) fn turned(&self) -> bool {
        !is_identity(&self.frame)
    }

    /// Which root description the features use.
    pub fn layout(&self) -> RootLayout {
        match self.heading {
            Some(_) => RootLayout::Heading,
            None => RootLayout::World,
        }
    }

    /// The root's feature rows: one per position axis for the world layout, four (forward,
    /// leftward, turn, height) for the heading layout.
    pub fn width(&self) -> usize {
        match self.heading {
            Some(_) => HEADING_ROOT_KINDS.len(),
            None => self.axes.len(),
        }
    }

    /// What each of the root's rows holds, in order.
    pub fn kinds(&self) -> Vec<ColumnKind> {
        match self.heading {
            Some(_) => HEADING_ROOT_KINDS.to_vec(),
            None => self
                .axes
                .iter()
                .map(|&axis| {
                    if axis.index() == UP {
                        ColumnKind::RootHeight
                    } else {
                        ColumnKind::RootDisplacement(axis)
                    }
                })
                .collect(),
        }
    }
}

/// The heading layout's root rows, in order.
pub const HEADING_ROOT_KINDS: [ColumnKind; 4] = [
    ColumnKind::RootForward,
    ColumnKind::RootLeftward,
    ColumnKind::RootTurn,
    ColumnKind::RootHeight,
];

/// What one feature column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ColumnKind {
    /// Root displacement per frame along X or Z.
    RootDisplacement(Axis),
    /// Root height (absolute Y).
    RootHeight,
    /// Heading layout: the root's ground displacement per frame along its facing.
    RootForward,
    /// Heading layout: the root's ground displacement per frame across its facing, to its left.
    RootLeftward,
    /// Heading layout: the facing's turn per frame about up, radians (toward +X from +Z is
    /// positive).
    RootTurn,
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
    /// The clip's ground level: a canonical-frame height in file units, where its contact
    /// points rest ([`crate::motion::ground::ground_level`]). Model files written before the
    /// field existed lack it; foot planting then reads the ground from the motion it plants.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground: Option<f64>,
}

impl FeatureLayout {
    /// The joint that carries the motion: the root's joint, or the top joint for a layout
    /// without root features.
    pub fn carrier(&self) -> usize {
        self.root.as_ref().map_or_else(
            || {
                self.skeleton
                    .joints
                    .iter()
                    .position(|j| j.parent.is_none())
                    .unwrap_or(0)
            },
            |r| r.joint,
        )
    }

    /// The skeleton's body: every joint but the static containers above the [`carrier`](Self::carrier).
    pub fn body(&self) -> Body {
        Body::carried_by(&self.skeleton, self.carrier())
    }

    /// Number of feature columns (F).
    pub fn width(&self) -> usize {
        self.root.as_ref().map_or(0, RootFeatures::width)
            + 6 * self.rotation_joints.len()
            + self.position_channels.len()
            + self.contact_joints.len()
    }

    /// Every column in order.
    pub fn columns(&self) -> Vec<Column> {
        let mut out = Vec::with_capacity(self.width());
        if let Some(root) = &self.root {
            out.extend(root.kinds().into_iter().map(|kind| Column {
                joint: root.joint,
                kind,
            }));
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

    /// Rows of the contact labels, one per contact joint in [`FeatureLayout::contact_joints`]
    /// order.
    pub fn contact_rows(&self) -> Vec<usize> {
        self.columns()
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == ColumnKind::Contact)
            .map(|(i, _)| i)
            .collect()
    }

    /// The contact labels of a feature table (`[F, frames]`, as the network makes it), one
    /// series per contact joint in [`FeatureLayout::contact_joints`] order: what planting reads.
    pub fn contact_labels(&self, features: ndarray::ArrayView2<'_, f32>) -> Vec<Vec<f32>> {
        self.contact_rows()
            .into_iter()
            .map(|row| features.row(row).to_vec())
            .collect()
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
            ColumnKind::RootForward => format!("{joint}.forward"),
            ColumnKind::RootLeftward => format!("{joint}.leftward"),
            ColumnKind::RootTurn => format!("{joint}.turn"),
            ColumnKind::Rotation6d(c) => format!("{joint}.rot6d[{c}]"),
            ColumnKind::Position(axis) => format!("{joint}.{axis}position"),
            ColumnKind::Contact => format!("{joint}.contact"),
        }
    }
}
