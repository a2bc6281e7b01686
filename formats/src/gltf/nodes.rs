//! The node tree of a glTF file: each node's rest transform and parent.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::math::{self, Mat3, Vec3};

use crate::error::{FormatError, Part};

/// A rigid transform with a uniform scale: `x -> t + s R x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Similarity {
    pub(super) rotation: Mat3,
    pub(super) translation: Vec3,
    pub(super) scale: f64,
}

impl Similarity {
    pub(super) const IDENTITY: Similarity = Similarity {
        rotation: math::IDENTITY,
        translation: Vec3([0.0; 3]),
        scale: 1.0,
    };

    /// `self` after `inner`: `x -> self(inner(x))`.
    pub(super) fn then(&self, inner: &Similarity) -> Similarity {
        Similarity {
            rotation: (self.rotation * inner.rotation),
            translation: (self.translation + ((self.rotation * inner.translation) * self.scale)),
            scale: self.scale * inner.scale,
        }
    }
}

/// A node's rest transform: translation, rotation (as a matrix) and scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Trs {
    pub(super) translation: Vec3,
    pub(super) rotation: Mat3,
    pub(super) scale: Vec3,
}

/// `[x, y, z, w]` to a rotation matrix.
pub(super) fn rotation_of(q: [f64; 4]) -> Mat3 {
    math::mat_from_quat(q)
}

pub(super) fn numbers<const N: usize>(value: Option<&Value>) -> Option<[f64; N]> {
    let array = value?.as_array()?;
    if array.len() != N {
        return None;
    }
    let mut out = [0.0; N];
    for (o, v) in out.iter_mut().zip(array) {
        *o = v.as_f64().filter(|x| x.is_finite())?;
    }
    Some(out)
}

/// The rest transform of node `index`, from its TRS properties or its matrix.
pub(super) fn node_trs(path: &Path, nodes: &[Value], index: usize) -> Result<Trs, FormatError> {
    let node = &nodes[index];
    let part = || Part::Node(index, node_name(node));
    let invalid = |key: &str| -> Result<(), FormatError> {
        match node.get(key) {
            None => Ok(()),
            Some(v) => Err(FormatError::bad(
                path,
                part(),
                format!("'{key}' is not valid: {v}"),
            )),
        }
    };
    if let Some(m) = node.get("matrix") {
        let m = numbers::<16>(Some(m))
            .ok_or_else(|| FormatError::bad(path, part(), "'matrix' is not 16 numbers".into()))?;
        // Column-major: column c is m[4c..4c+4].
        let column = |c: usize| Vec3::new(m[4 * c], m[4 * c + 1], m[4 * c + 2]);
        let scale = Vec3::from_fn(|c| column(c).norm());
        if scale.iter().any(|&s| s < 1e-12) {
            return Err(FormatError::bad(
                path,
                part(),
                "'matrix' is singular".into(),
            ));
        }
        let rotation = Mat3::from_fn(|r, c| column(c)[r] / scale[c]);
        return Ok(Trs {
            translation: column(3),
            rotation,
            scale,
        });
    }
    let translation = match numbers::<3>(node.get("translation")) {
        Some(t) => t,
        None => invalid("translation").map(|()| [0.0; 3])?,
    };
    let rotation = match numbers::<4>(node.get("rotation")) {
        Some(q) => rotation_of(q),
        None => invalid("rotation").map(|()| math::IDENTITY)?,
    };
    let scale = match numbers::<3>(node.get("scale")) {
        Some(s) => s,
        None => invalid("scale").map(|()| [1.0; 3])?,
    };
    Ok(Trs {
        translation: sinmdm::motion::math::Vec3(translation),
        rotation,
        scale: sinmdm::motion::math::Vec3(scale),
    })
}

pub(super) fn node_name(node: &Value) -> Option<String> {
    node.get("name").and_then(Value::as_str).map(str::to_string)
}

/// Whether every component of `scale` is 1 within a relative 1e-4.
pub(super) fn unit_scale(scale: Vec3) -> bool {
    scale.iter().all(|s| (s - 1.0).abs() < 1e-4)
}

/// The uniform scale of `scale`, if its components agree within a relative 1e-4.
pub(super) fn uniform(scale: Vec3) -> Option<f64> {
    let s = scale[0];
    (s > 0.0 && scale.iter().all(|v| (v - s).abs() <= 1e-4 * s)).then_some(s)
}

/// Every node's parent, checked: children in range, no node the child of two, no cycle.
pub(super) fn parents(path: &Path, nodes: &[Value]) -> Result<Vec<Option<usize>>, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    // The node tree: every node's parent, checked to be a forest.
    let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
    for (index, node) in nodes.iter().enumerate() {
        for child in node
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let c = child
                .as_u64()
                .map(|c| c as usize)
                .filter(|&c| c < nodes.len() && c != index)
                .ok_or_else(|| {
                    bad(
                        Part::Node(index, node_name(node)),
                        format!("has a bad child {child}"),
                    )
                })?;
            if parent[c].is_some() {
                return Err(bad(
                    Part::Node(c, node_name(&nodes[c])),
                    "is the child of two nodes".into(),
                ));
            }
            parent[c] = Some(index);
        }
    }
    for start in 0..nodes.len() {
        let mut at = start;
        for _ in 0..=nodes.len() {
            match parent[at] {
                Some(p) => at = p,
                None => break,
            }
            if at == start {
                return Err(bad(
                    Part::Node(start, node_name(&nodes[start])),
                    "is its own ancestor".into(),
                ));
            }
        }
    }

    Ok(parent)
}
