//! The static part of a clip: joints, their parents, offsets and per-joint channel lists.

use serde::{Deserialize, Serialize};
use std::fmt;

use super::math::Vec3;

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Axis {
    /// X.
    X,
    /// Y (up in the canonical frame, see [`super::up`]).
    Y,
    /// Z.
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// The axis with index 0, 1 or 2.
    pub fn from_index(index: usize) -> Axis {
        match index {
            0 => Axis::X,
            1 => Axis::Y,
            _ => Axis::Z,
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Axis::X => "X",
            Axis::Y => "Y",
            Axis::Z => "Z",
        })
    }
}

/// One animated channel of a joint, as named in a BVH `CHANNELS` line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Channel {
    /// A translation along an axis (file units).
    Position(Axis),
    /// A rotation about an axis (degrees in BVH files).
    Rotation(Axis),
}

impl Channel {
    /// Parses a BVH channel name such as `Xposition` or `Zrotation` (case-insensitive).
    pub fn parse(name: &str) -> Option<Channel> {
        let lower = name.to_ascii_lowercase();
        let axis = match lower.as_bytes().first()? {
            b'x' => Axis::X,
            b'y' => Axis::Y,
            b'z' => Axis::Z,
            _ => return None,
        };
        match &lower[1..] {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }

    /// The canonical BVH name (`Xposition`, `Zrotation`, ...).
    pub fn bvh_name(self) -> &'static str {
        match self {
            Channel::Position(Axis::X) => "Xposition",
            Channel::Position(Axis::Y) => "Yposition",
            Channel::Position(Axis::Z) => "Zposition",
            Channel::Rotation(Axis::X) => "Xrotation",
            Channel::Rotation(Axis::Y) => "Yrotation",
            Channel::Rotation(Axis::Z) => "Zrotation",
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.bvh_name())
    }
}

/// One joint of a skeleton.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Joint {
    /// The joint's name, unique within its skeleton.
    pub name: String,
    /// Index of the parent joint; `None` for the root. Parents always come before their children.
    pub parent: Option<usize>,
    /// Translation from the parent joint in the rest pose (file units).
    pub offset: Vec3,
    /// The joint's animated channels in file order (3 or 6 in practice, any order).
    pub channels: Vec<Channel>,
    /// The End Site offset, if the joint ends a chain with one.
    pub end_site: Option<Vec3>,
}

impl Joint {
    /// The rotation axes in the order the file lists them: `[Z, X, Y]` means `R = Rz * Rx * Ry`.
    pub fn rotation_order(&self) -> Vec<Axis> {
        self.axes_of(|c| match c {
            Channel::Rotation(a) => Some(a),
            Channel::Position(_) => None,
        })
    }

    /// The position axes the joint animates, in file order.
    pub fn position_axes(&self) -> Vec<Axis> {
        self.axes_of(|c| match c {
            Channel::Position(a) => Some(a),
            Channel::Rotation(_) => None,
        })
    }

    fn axes_of(&self, pick: impl Fn(Channel) -> Option<Axis>) -> Vec<Axis> {
        self.channels.iter().filter_map(|&c| pick(c)).collect()
    }

    /// Whether the joint has at least one rotation channel.
    pub fn rotates(&self) -> bool {
        self.channels
            .iter()
            .any(|c| matches!(c, Channel::Rotation(_)))
    }
}

/// A joint hierarchy. Joints are stored in file (depth-first) order, so every parent precedes
/// its children and index 0 is the root.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skeleton {
    /// The joints, root first.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Number of joints (End Sites are not joints).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether the skeleton has no joints.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Total number of channels over all joints (values per motion frame).
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// Index of the first channel of each joint within a motion frame.
    pub fn channel_starts(&self) -> Vec<usize> {
        let mut start = 0;
        self.joints
            .iter()
            .map(|j| {
                let s = start;
                start += j.channels.len();
                s
            })
            .collect()
    }

    /// Index of the joint with this name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the direct children of `joint`.
    pub fn children(&self, joint: usize) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&j| self.joints[j].parent == Some(joint))
            .collect()
    }

    /// The joints above `joint`, its parent first and the top joint last.
    pub fn ancestors(&self, joint: usize) -> Vec<usize> {
        let mut out = Vec::new();
        let mut j = joint;
        while let Some(p) = self.joints.get(j).and_then(|j| j.parent) {
            out.push(p);
            j = p;
        }
        out
    }

    /// Joints that have no child joints (the ends of chains: feet, hands, head, tail tips).
    pub fn leaves(&self) -> Vec<usize> {
        let mut has_child = vec![false; self.joints.len()];
        for joint in &self.joints {
            if let Some(p) = joint.parent {
                has_child[p] = true;
            }
        }
        (0..self.joints.len()).filter(|&j| !has_child[j]).collect()
    }

    /// The first structural difference between `self` (the expected skeleton) and `other`, in
    /// words: joint count, a joint's name, parent or channel list. Offsets may differ.
    pub fn difference(&self, other: &Skeleton) -> Option<String> {
        if self.joints.len() != other.joints.len() {
            return Some(format!(
                "it has {} joints where {} are expected",
                other.joints.len(),
                self.joints.len()
            ));
        }
        let parent_name = |s: &Skeleton, p: Option<usize>| {
            p.map_or("none (root)".to_string(), |p| {
                format!("'{}'", s.joints[p].name)
            })
        };
        for (i, (a, b)) in self.joints.iter().zip(&other.joints).enumerate() {
            if a.name != b.name {
                return Some(format!(
                    "joint {i} is '{}' where '{}' is expected",
                    b.name, a.name
                ));
            }
            if a.parent != b.parent {
                return Some(format!(
                    "joint '{}' has parent {} where {} is expected",
                    a.name,
                    parent_name(other, b.parent),
                    parent_name(self, a.parent)
                ));
            }
            if a.channels != b.channels {
                let list =
                    |c: &[Channel]| c.iter().map(|c| c.bvh_name()).collect::<Vec<_>>().join(" ");
                return Some(format!(
                    "joint '{}' has channels [{}] where [{}] are expected",
                    a.name,
                    list(&b.channels),
                    list(&a.channels)
                ));
            }
        }
        None
    }
}
