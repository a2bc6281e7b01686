//! Motion to glTF 2.0: one node per joint with its rest transform, a skin over every joint (so
//! importers build bones, not empties), and one animation per motion, in metres and +Y up.

use std::path::Path;

use serde_json::{Value, json};
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{LocalMotion, Skeleton, UpAxis, up};

use super::EXTRAS_KEY;
use super::container::{base64_encode, glb_bytes};
use crate::error::FormatError;

/// How motions are placed into glTF's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GltfWriteOptions {
    /// The up axis of the motions' own frame (glTF's is +Y; the motion is turned into it).
    pub up: UpAxis,
    /// Metres per unit of the motions' translations (glTF is in metres).
    pub metres_per_unit: f64,
    /// Add a tiny mesh (one triangle) skinned to the root, for importers that build skeletons
    /// only from skinned meshes (Unreal's).
    pub proxy_mesh: bool,
}

/// Vertex attribute data (`ARRAY_BUFFER`).
const ARRAY_BUFFER: u32 = 34962;
/// glTF's component type for unsigned bytes.
const UNSIGNED_BYTE: u32 = 5121;
/// Half the width of the proxy triangle, in metres.
const PROXY_SIZE: f32 = 0.02;

/// glTF's component type for 32-bit floats.
const FLOAT: u32 = 5126;

/// The binary buffer under construction, with one buffer view and accessor per array.
#[derive(Default)]
pub(super) struct Binary {
    pub(super) bytes: Vec<u8>,
    pub(super) views: Vec<Value>,
    pub(super) accessors: Vec<Value>,
    /// Accessors and buffer views the document holds before these (their indices start there).
    base: (usize, usize),
}

impl Binary {
    /// A buffer that continues `bytes`, in a document that already has `accessors` accessors and
    /// `views` buffer views.
    pub(super) fn after(bytes: Vec<u8>, accessors: usize, views: usize) -> Binary {
        Binary {
            bytes,
            base: (accessors, views),
            ..Binary::default()
        }
    }

    /// Appends `bytes` in a buffer view of their own (with `target`, for vertex data), 4-byte
    /// aligned; returns the view's index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bytes.len(),
            "byteLength": bytes.len(),
        });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.bytes.extend_from_slice(bytes);
        self.views.push(view);
        self.base.1 + self.views.len() - 1
    }

    /// Appends the key times of `frames` frames at `fps` (seconds from 0, with their bounds, as
    /// glTF asks of an animation's input) as an accessor; returns its index.
    pub(super) fn key_times(&mut self, frames: usize, fps: f64) -> usize {
        let times: Vec<f32> = (0..frames).map(|f| (f as f64 / fps) as f32).collect();
        self.accessor(&times, "SCALAR", 1, true)
    }

    /// Appends `values` as an accessor of `kind` (`SCALAR`, `VEC3`, `VEC4`, `MAT4`) with
    /// `width` floats per element, with its min and max when `bounds` is set; returns its index.
    pub(super) fn accessor(
        &mut self,
        values: &[f32],
        kind: &str,
        width: usize,
        bounds: bool,
    ) -> usize {
        self.float_accessor(values, kind, width, bounds, None)
    }

    /// [`Binary::accessor`] with a buffer-view target.
    fn float_accessor(
        &mut self,
        values: &[f32],
        kind: &str,
        width: usize,
        bounds: bool,
        target: Option<u32>,
    ) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": values.len() / width,
            "type": kind,
        });
        if bounds {
            let mut min = vec![f32::INFINITY; width];
            let mut max = vec![f32::NEG_INFINITY; width];
            for element in values.chunks(width) {
                for (k, &v) in element.iter().enumerate() {
                    min[k] = min[k].min(v);
                    max[k] = max[k].max(v);
                }
            }
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.accessors.push(accessor);
        self.base.0 + self.accessors.len() - 1
    }

    /// Appends `values` as a VEC4 accessor of unsigned bytes (joint indices); returns its index.
    fn joints_accessor(&mut self, values: &[u8]) -> usize {
        let view = self.view(values, Some(ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_BYTE,
            "count": values.len() / 4,
            "type": "VEC4",
        }));
        self.base.0 + self.accessors.len() - 1
    }
}

/// A one-triangle mesh bound to the root joint (`root_position`, its rest position in metres),
/// so that importers that make bones only for skinned meshes see the skeleton: the mesh's JSON.
fn proxy_mesh(binary: &mut Binary, root_position: Vec3) -> Value {
    let [x, y, z] = root_position.map(|v| v as f32);
    let positions = [
        x - PROXY_SIZE,
        y,
        z,
        x + PROXY_SIZE,
        y,
        z,
        x,
        y + PROXY_SIZE,
        z,
    ];
    let position = binary.float_accessor(&positions, "VEC3", 3, true, Some(ARRAY_BUFFER));
    // Every vertex on the root alone (joint 0, weight 1; unused slots 0 with weight 0).
    let joint_indices = [0u8; 12];
    let joints_0 = binary.joints_accessor(&joint_indices);
    let weights: Vec<f32> = (0..3).flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let weights_0 = binary.float_accessor(&weights, "VEC4", 4, false, Some(ARRAY_BUFFER));
    json!({
        "name": "proxy",
        "primitives": [{
            "attributes": {"POSITION": position, "JOINTS_0": joints_0, "WEIGHTS_0": weights_0},
            "mode": 4,
        }],
    })
}

/// A rotation as glTF's unit quaternion `[x, y, z, w]`, on the same side as `previous` (so
/// interpolating consecutive keys takes the short way).
pub(super) fn quaternion_xyzw(m: &Mat3, previous: Option<[f64; 4]>) -> [f64; 4] {
    let q = math::quat_from_mat(m);
    match previous {
        Some(p) if p.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>() < 0.0 => {
            [-q[0], -q[1], -q[2], -q[3]]
        }
        _ => q,
    }
}

/// The quaternion rounded to f32 and renormalised there, as validators measure unit length.
pub(super) fn unit_f32(q: [f64; 4]) -> [f32; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let q = q.map(|v| (v / n) as f32);
    let n32 = q.iter().map(|v| v * v).sum::<f32>().sqrt();
    q.map(|v| v / n32)
}

/// The rest transform of each joint in glTF's frame: the offset in metres, and for each top
/// joint the turn from the file's frame into +Y up.
fn rest_transforms(skeleton: &Skeleton, options: &GltfWriteOptions) -> Vec<(Mat3, Vec3)> {
    let turn = options.up.canonical_from_file();
    skeleton
        .joints
        .iter()
        .map(|joint| {
            let offset = joint.offset * options.metres_per_unit;
            match joint.parent {
                None => (turn, (turn * offset)),
                Some(_) => (math::IDENTITY, offset),
            }
        })
        .collect()
}

/// The column-major inverse of each joint's global rest transform.
fn inverse_bind_matrices(skeleton: &Skeleton, rest: &[(Mat3, Vec3)]) -> Vec<f32> {
    let mut global: Vec<(Mat3, Vec3)> = Vec::with_capacity(rest.len());
    let mut out = Vec::with_capacity(rest.len() * 16);
    for (joint, (r, t)) in skeleton.joints.iter().zip(rest) {
        let g = match joint.parent {
            None => (*r, *t),
            Some(p) => {
                let (pr, pt) = global[p];
                (pr * r, pt + pr * *t)
            }
        };
        let inverse_rotation = g.0.transpose();
        let inverse_translation = (inverse_rotation * g.1) * (-1.0);
        // Column-major: the rotation's columns, then the translation, each with its fourth row.
        for column in 0..3 {
            out.extend(inverse_rotation.column(column).map(|v| v as f32));
            out.push(0.0);
        }
        out.extend(inverse_translation.map(|v| v as f32));
        out.push(1.0);
        global.push(g);
    }
    out
}

/// One glTF node per joint: its name, rest transform (the top joints turned into +Y up),
/// children, and the channels and End Site this crate records in its extras.
fn joint_nodes(
    skeleton: &Skeleton,
    rest: &[(Mat3, Vec3)],
    options: &GltfWriteOptions,
) -> Vec<Value> {
    skeleton
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let (r, t) = rest[j];
            let mut node = json!({
                "name": joint.name,
                "translation": t.map(|v| v as f32),
            });
            if joint.parent.is_none() {
                node["rotation"] = json!(unit_f32(quaternion_xyzw(&r, None)));
            }
            let children = skeleton.children(j);
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            let channels: Vec<String> = joint.channels.iter().map(|c| c.to_string()).collect();
            let mut extras = json!({ "channels": channels });
            if let Some(end) = joint.end_site {
                extras["end_site"] = json!((end * options.metres_per_unit));
            }
            node["extras"] = json!({ EXTRAS_KEY: extras });
            node
        })
        .collect()
}

/// The animation of motion `name`, its rotation and translation keys (for the joints that
/// `animated` says rotate and move) appended to `binary`; an error for a motion with no frames
/// or no valid frame rate.
fn motion_animation(
    binary: &mut Binary,
    (name, motion): (&str, &LocalMotion),
    animated: &[(bool, bool)],
    joints: usize,
    options: &GltfWriteOptions,
) -> Result<Value, String> {
    let frames = motion.frame_count();
    if frames == 0 {
        return Err(format!("motion '{name}' has no frames"));
    }
    if !(motion.fps.is_finite() && motion.fps > 0.0) {
        return Err(format!(
            "motion '{name}' has a frame rate of {}",
            motion.fps
        ));
    }
    let canonical = up::to_canonical(motion, options.up);
    let input = binary.key_times(frames, motion.fps);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (j, &(rotates, moves)) in animated.iter().enumerate() {
        if rotates {
            let mut previous = None;
            let mut values = Vec::with_capacity(frames * 4);
            for f in 0..frames {
                let q = quaternion_xyzw(&canonical.rotations[f * joints + j], previous);
                previous = Some(q);
                values.extend(unit_f32(q));
            }
            let output = binary.accessor(&values, "VEC4", 4, false);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({
                "sampler": samplers.len() - 1,
                "target": {"node": j, "path": "rotation"},
            }));
        }
        if moves {
            let values: Vec<f32> = (0..frames)
                .flat_map(|f| {
                    (canonical.translations[f * joints + j] * options.metres_per_unit)
                        .map(|v| v as f32)
                })
                .collect();
            let output = binary.accessor(&values, "VEC3", 3, false);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels.push(json!({
                "sampler": samplers.len() - 1,
                "target": {"node": j, "path": "translation"},
            }));
        }
    }
    Ok(json!({"name": name, "samplers": samplers, "channels": channels}))
}

/// The glTF document and binary buffer of `motions` (name and motion), which must share one
/// skeleton: the nodes, the skin, and one animation per motion.
pub fn gltf_document(
    motions: &[(String, &LocalMotion)],
    options: &GltfWriteOptions,
) -> Result<(Value, Vec<u8>), String> {
    let Some((_, first)) = motions.first() else {
        return Err("no motion to write".into());
    };
    let skeleton = &first.skeleton;
    if skeleton.is_empty() {
        return Err("the skeleton has no joints".into());
    }
    if let Some((name, _)) = motions.iter().find(|(_, m)| m.skeleton != *skeleton) {
        return Err(format!(
            "motion '{name}' has another skeleton than '{}'; one file holds one skeleton",
            motions[0].0
        ));
    }
    if !(options.metres_per_unit.is_finite() && options.metres_per_unit > 0.0) {
        return Err(format!(
            "the unit scale must be a positive number, got {}",
            options.metres_per_unit
        ));
    }
    let animated: Vec<(bool, bool)> = skeleton
        .joints
        .iter()
        .map(|j| (j.rotates(), !j.position_axes().is_empty()))
        .collect();
    if animated.iter().all(|&(r, t)| !r && !t) {
        return Err("no joint of the skeleton has a channel to animate".into());
    }
    let mut binary = Binary::default();
    let rest = rest_transforms(skeleton, options);
    let nodes = joint_nodes(skeleton, &rest, options);
    let roots: Vec<usize> = (0..skeleton.len())
        .filter(|&j| skeleton.joints[j].parent.is_none())
        .collect();
    let ibm = binary.accessor(&inverse_bind_matrices(skeleton, &rest), "MAT4", 16, false);
    let joints = skeleton.len();
    let mut animations = Vec::with_capacity(motions.len());
    for (name, motion) in motions {
        animations.push(motion_animation(
            &mut binary,
            (name.as_str(), *motion),
            &animated,
            joints,
            options,
        )?);
    }
    let mut nodes = nodes;
    let mut scene_nodes = roots.clone();
    let mut meshes = Vec::new();
    if options.proxy_mesh {
        let (_, root_translation) = rest[roots[0]];
        meshes.push(proxy_mesh(&mut binary, root_translation));
        nodes.push(json!({"name": "proxy_mesh", "mesh": 0, "skin": 0}));
        scene_nodes.push(nodes.len() - 1);
    }
    let mut document = json!({
        "asset": {"version": "2.0", "generator": concat!("sinmdm-rs ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": scene_nodes}],
        "nodes": nodes,
        "skins": [{"joints": (0..joints).collect::<Vec<_>>(), "inverseBindMatrices": ibm, "skeleton": roots[0]}],
        "animations": animations,
        "accessors": binary.accessors,
        "bufferViews": binary.views,
        "buffers": [{"byteLength": binary.bytes.len()}],
    });
    if !meshes.is_empty() {
        document["meshes"] = json!(meshes);
    }
    Ok((document, binary.bytes))
}

/// Writes `motions` (name and motion, one skeleton) to `path`: a `.glb`, or a `.gltf` with its
/// buffer embedded as base64. The file appears complete or not at all.
pub fn write_gltf(
    path: &Path,
    motions: &[(String, &LocalMotion)],
    options: &GltfWriteOptions,
) -> Result<(), FormatError> {
    let (mut document, bin) =
        gltf_document(motions, options).map_err(|message| FormatError::Write {
            path: path.to_path_buf(),
            message,
        })?;
    let binary_file = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let bytes = if binary_file {
        glb_bytes(&document, &bin)
    } else {
        document["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64_encode(&bin)
        ));
        serde_json::to_vec_pretty(&document).expect("a JSON value serialises")
    };
    sinmdm::files::write_atomically(path, &bytes).map_err(|reason| FormatError::Io {
        path: path.to_path_buf(),
        reason,
    })
}
