//! glTF 2.0 to a clip: the skeleton is the skin's joints, the motion one of the file's
//! animations, evaluated frame by frame as the glTF specification says.
//!
//! - Joint order is depth-first from the skin's root joint, so parents precede children. A joint's
//!   parent is its nearest ancestor node among the skin's joints. Nodes above the root joint (an
//!   armature object, a unit scale) are folded into the root: their rotation and translation into
//!   its transform, their uniform scale into every translation, so joints keep unit scale.
//! - The animation is sampled at its frame rate (the median spacing of its keys, snapped to a
//!   whole rate, unless one is given) from its first key, `round(duration x fps) + 1` frames.
//!   LINEAR rotations are interpolated by slerp, CUBICSPLINE values by the spec's Hermite form
//!   (rotations renormalised), STEP holds the previous key; times outside a sampler's keys hold
//!   its first or last value. Joints the animation does not move keep their rest transform.
//! - A leaf joint that never moves (Blender's and Mixamo's end bones) becomes its parent's End
//!   Site when it is the parent's only child, so no features are spent on it. Files this crate
//!   wrote keep each joint's BVH channels and End Site in node `extras`, and read back with them.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::math::{self, Mat3, Vec3};
use sinmdm::motion::{Channel, ChannelClip, Joint, LocalMotion, Skeleton, fps_from_frame_time};

use super::EXTRAS_KEY;
use super::accessor::{field_usize, read_floats};
use super::container::{Asset, read_asset};
use crate::error::{FormatError, Part};

/// Which animation of a file is the clip.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AnimationChoice {
    /// By position in the file's `animations`.
    Index(usize),
    /// By name.
    Name(String),
}

impl AnimationChoice {
    /// A number is an index, anything else a name.
    pub fn parse(text: &str) -> AnimationChoice {
        match text.parse() {
            Ok(index) => AnimationChoice::Index(index),
            Err(_) => AnimationChoice::Name(text.to_string()),
        }
    }
}

/// What a reader is asked to do beyond the defaults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GltfReadOptions {
    /// The animation to read (default: the first).
    pub animation: Option<AnimationChoice>,
    /// The frame rate to sample at (default: from the key spacing).
    pub fps: Option<f64>,
}

/// One animation of a file, as `inspect` lists them.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationInfo {
    /// Its index in the file.
    pub index: usize,
    /// Its name, if it has one.
    pub name: Option<String>,
    /// From its first key to its last, in seconds.
    pub seconds: f64,
}

/// A clip read from a glTF file, with what the file held besides.
#[derive(Debug, Clone)]
pub struct GltfClip {
    /// The clip, in the file's frame (glTF: +Y up) and units (metres).
    pub clip: ChannelClip,
    /// The animation it was read from.
    pub animation: AnimationInfo,
    /// Every animation of the file.
    pub animations: Vec<AnimationInfo>,
}

/// A rigid transform with a uniform scale: `x -> t + s R x`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Similarity {
    rotation: Mat3,
    translation: Vec3,
    scale: f64,
}

impl Similarity {
    const IDENTITY: Similarity = Similarity {
        rotation: math::IDENTITY,
        translation: [0.0; 3],
        scale: 1.0,
    };

    /// `self` after `inner`: `x -> self(inner(x))`.
    fn then(&self, inner: &Similarity) -> Similarity {
        Similarity {
            rotation: math::mat_mul(&self.rotation, &inner.rotation),
            translation: math::add(
                self.translation,
                math::scale(math::mat_vec(&self.rotation, inner.translation), self.scale),
            ),
            scale: self.scale * inner.scale,
        }
    }
}

/// A node's rest transform: translation, rotation (as a matrix) and scale.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Trs {
    translation: Vec3,
    rotation: Mat3,
    scale: Vec3,
}

/// `[x, y, z, w]` to a rotation matrix.
fn rotation_of(q: [f64; 4]) -> Mat3 {
    math::mat_from_quat_wxyz([q[3], q[0], q[1], q[2]])
}

fn numbers<const N: usize>(value: Option<&Value>) -> Option<[f64; N]> {
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
fn node_trs(path: &Path, nodes: &[Value], index: usize) -> Result<Trs, FormatError> {
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
        let column = |c: usize| [m[4 * c], m[4 * c + 1], m[4 * c + 2]];
        let scale = [column(0), column(1), column(2)].map(math::norm);
        if scale.iter().any(|&s| s < 1e-12) {
            return Err(FormatError::bad(
                path,
                part(),
                "'matrix' is singular".into(),
            ));
        }
        let mut rotation = math::IDENTITY;
        for c in 0..3 {
            for r in 0..3 {
                rotation[r][c] = column(c)[r] / scale[c];
            }
        }
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
        translation,
        rotation,
        scale,
    })
}

fn node_name(node: &Value) -> Option<String> {
    node.get("name").and_then(Value::as_str).map(str::to_string)
}

/// Whether every component of `scale` is 1 within a relative 1e-4.
fn unit_scale(scale: Vec3) -> bool {
    scale.iter().all(|s| (s - 1.0).abs() < 1e-4)
}

/// The uniform scale of `scale`, if its components agree within a relative 1e-4.
fn uniform(scale: Vec3) -> Option<f64> {
    let s = scale[0];
    (s > 0.0 && scale.iter().all(|v| (v - s).abs() <= 1e-4 * s)).then_some(s)
}

/// The animations of the file, for choosing and listing.
fn animation_infos(asset: &Asset) -> Vec<AnimationInfo> {
    let Some(animations) = asset.json.get("animations").and_then(Value::as_array) else {
        return Vec::new();
    };
    animations
        .iter()
        .enumerate()
        .map(|(index, animation)| {
            let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
            for sampler in animation
                .get("samplers")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
            {
                if let Some(input) = field_usize(sampler, "input") {
                    let accessor = asset.json.get("accessors").and_then(|a| a.get(input));
                    let bound = |key: &str| {
                        accessor
                            .and_then(|a| a.get(key))
                            .and_then(|v| v.get(0))
                            .and_then(Value::as_f64)
                    };
                    match (bound("min"), bound("max")) {
                        (Some(lo), Some(hi)) => {
                            first = first.min(lo);
                            last = last.max(hi);
                        }
                        _ => {
                            if let Ok(times) = read_floats(asset, input, 1) {
                                if let (Some(lo), Some(hi)) = (times.first(), times.last()) {
                                    first = first.min(f64::from(*lo));
                                    last = last.max(f64::from(*hi));
                                }
                            }
                        }
                    }
                }
            }
            AnimationInfo {
                index,
                name: node_name(animation),
                seconds: if last >= first { last - first } else { 0.0 },
            }
        })
        .collect()
}

/// The animations of a glTF file with their lengths (for `inspect`).
pub fn list_animations(path: &Path) -> Result<Vec<AnimationInfo>, FormatError> {
    Ok(animation_infos(&read_asset(path)?))
}

/// How a sampler interpolates.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Interpolation {
    Linear,
    Step,
    CubicSpline,
}

/// One animated property of one joint.
struct Track {
    joint: usize,
    property: Property,
    times: Vec<f32>,
    /// `width` values per key; CUBICSPLINE keeps in-tangent, value, out-tangent per key.
    values: Vec<f32>,
    interpolation: Interpolation,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Property {
    Translation,
    Rotation,
    Scale,
}

impl Property {
    fn width(self) -> usize {
        match self {
            Property::Rotation => 4,
            _ => 3,
        }
    }
}

impl Track {
    /// The property's value at time `t`: a translation or scale `[x, y, z, _]`, or a rotation
    /// `[x, y, z, w]` (unit).
    fn sample(&self, t: f64) -> [f64; 4] {
        let width = self.property.width();
        let keys = self.times.len();
        let value = |key: usize| -> [f64; 4] {
            let base = match self.interpolation {
                Interpolation::CubicSpline => (3 * key + 1) * width,
                _ => key * width,
            };
            let mut out = [0.0; 4];
            for k in 0..width {
                out[k] = f64::from(self.values[base + k]);
            }
            out
        };
        let result = if t <= f64::from(self.times[0]) {
            value(0)
        } else if t >= f64::from(self.times[keys - 1]) {
            value(keys - 1)
        } else {
            // The last key at or before t.
            let k = self.times.partition_point(|&key| f64::from(key) <= t) - 1;
            let (t0, t1) = (f64::from(self.times[k]), f64::from(self.times[k + 1]));
            let dt = t1 - t0;
            let u = if dt > 0.0 { (t - t0) / dt } else { 0.0 };
            match self.interpolation {
                Interpolation::Step => value(k),
                Interpolation::Linear if self.property == Property::Rotation => {
                    let (a, b) = (value(k), value(k + 1));
                    let q = math::slerp([a[3], a[0], a[1], a[2]], [b[3], b[0], b[1], b[2]], u);
                    [q[1], q[2], q[3], q[0]]
                }
                Interpolation::Linear => {
                    let (a, b) = (value(k), value(k + 1));
                    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * u)
                }
                Interpolation::CubicSpline => {
                    let tangent = |key: usize, slot: usize| -> [f64; 4] {
                        let base = (3 * key + slot) * width;
                        std::array::from_fn(|i| {
                            if i < width {
                                f64::from(self.values[base + i])
                            } else {
                                0.0
                            }
                        })
                    };
                    let (p0, m0) = (value(k), tangent(k, 2));
                    let (p1, m1) = (value(k + 1), tangent(k + 1, 0));
                    let (u2, u3) = (u * u, u * u * u);
                    let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
                    let h10 = u3 - 2.0 * u2 + u;
                    let h01 = -2.0 * u3 + 3.0 * u2;
                    let h11 = u3 - u2;
                    std::array::from_fn(|i| {
                        h00 * p0[i] + h10 * dt * m0[i] + h01 * p1[i] + h11 * dt * m1[i]
                    })
                }
            }
        };
        if self.property == Property::Rotation {
            let n = result.iter().map(|v| v * v).sum::<f64>().sqrt();
            if n > 1e-12 {
                return result.map(|v| v / n);
            }
            return [0.0, 0.0, 0.0, 1.0];
        }
        result
    }
}

/// Reads the clip of one animation of a `.glb` or `.gltf` file.
pub fn read_gltf(path: &Path, options: &GltfReadOptions) -> Result<GltfClip, FormatError> {
    let asset = read_asset(path)?;
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    let nodes: &[Value] = asset
        .json
        .get("nodes")
        .and_then(Value::as_array)
        .map(Vec::as_slice)
        .unwrap_or(&[]);

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

    // The skin: the one with the most joints.
    let skins = asset.json.get("skins").and_then(Value::as_array);
    let (skin_index, skin) = skins
        .into_iter()
        .flatten()
        .enumerate()
        .max_by_key(|(_, s)| s.get("joints").and_then(Value::as_array).map_or(0, Vec::len))
        .ok_or_else(|| {
            bad(
                Part::Json,
                "has no skin, so no skeleton: export the armature with its skin (a skinned mesh or the armature's bones)".into(),
            )
        })?;
    let joint_nodes: Vec<usize> = skin
        .get("joints")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|j| j.as_u64().map(|j| j as usize).filter(|&j| j < nodes.len()))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| {
            bad(
                Part::Skin(skin_index),
                "names a joint that is not a node".into(),
            )
        })?;
    if joint_nodes.is_empty() {
        return Err(bad(Part::Skin(skin_index), "has no joints".into()));
    }
    let is_joint = |n: usize| joint_nodes.contains(&n);
    let joint_parent = |n: usize| -> Option<usize> {
        let mut at = parent[n];
        while let Some(p) = at {
            if is_joint(p) {
                return Some(p);
            }
            at = parent[p];
        }
        None
    };
    let roots: Vec<usize> = joint_nodes
        .iter()
        .copied()
        .filter(|&n| joint_parent(n).is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<String> = roots
            .iter()
            .map(|&n| node_name(&nodes[n]).unwrap_or_else(|| format!("node {n}")))
            .collect();
        return Err(bad(
            Part::Skin(skin_index),
            format!(
                "has {} root joints ({}); a skeleton needs exactly one",
                roots.len(),
                names.join(", ")
            ),
        ));
    }
    // Depth-first order from the root, children in file order.
    let mut order = Vec::with_capacity(joint_nodes.len());
    let mut stack = vec![roots[0]];
    while let Some(n) = stack.pop() {
        if is_joint(n) {
            order.push(n);
        }
        let children: Vec<usize> = nodes[n]
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|c| c.as_u64().map(|c| c as usize))
            .collect();
        stack.extend(children.into_iter().rev());
    }
    let position_of = |n: usize| order.iter().position(|&o| o == n);

    // Rest transforms, with non-joint nodes above each joint folded in.
    let rest: Vec<Trs> = (0..nodes.len())
        .map(|n| node_trs(path, nodes, n))
        .collect::<Result<_, _>>()?;
    let mut pre: Vec<Similarity> = Vec::with_capacity(order.len());
    for &n in &order {
        let stop = joint_parent(n);
        let mut fold = Similarity::IDENTITY;
        let mut at = parent[n];
        while at.is_some() && at != stop {
            let p = at.expect("checked");
            let trs = rest[p];
            let scale = uniform(trs.scale).ok_or_else(|| {
                bad(
                    Part::Node(p, node_name(&nodes[p])),
                    format!("has a non-uniform scale {:?} above a joint", trs.scale),
                )
            })?;
            if stop.is_some() && (scale - 1.0).abs() > 1e-4 {
                return Err(bad(
                    Part::Node(p, node_name(&nodes[p])),
                    format!(
                        "scales by {scale} between two joints; only nodes above the root may scale"
                    ),
                ));
            }
            fold = Similarity {
                rotation: trs.rotation,
                translation: trs.translation,
                scale,
            }
            .then(&fold);
            at = parent[p];
        }
        pre.push(fold);
    }
    // The scale of the nodes above the root multiplies every translation below it.
    let unit = pre[0].scale;

    // The animation.
    let animations = animation_infos(&asset);
    if animations.is_empty() {
        return Err(bad(Part::Json, "has no animation".into()));
    }
    let chosen = match &options.animation {
        None => 0,
        Some(AnimationChoice::Index(i)) if *i < animations.len() => *i,
        Some(AnimationChoice::Index(i)) => {
            return Err(bad(
                Part::Json,
                format!(
                    "has {} animations; there is no animation {i}",
                    animations.len()
                ),
            ));
        }
        Some(AnimationChoice::Name(name)) => animations
            .iter()
            .position(|a| a.name.as_deref() == Some(name.as_str()))
            .ok_or_else(|| {
                let names: Vec<String> = animations
                    .iter()
                    .map(|a| a.name.clone().unwrap_or_else(|| format!("#{}", a.index)))
                    .collect();
                bad(
                    Part::Json,
                    format!(
                        "has no animation named '{name}' (it has: {})",
                        names.join(", ")
                    ),
                )
            })?,
    };
    let animation = &asset.json["animations"][chosen];
    let animation_part = Part::Animation(chosen, node_name(animation));
    let samplers = animation
        .get("samplers")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut tracks = Vec::new();
    for (c, channel) in animation
        .get("channels")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
    {
        let target = channel.get("target");
        let Some(node) = target.and_then(|t| field_usize(t, "node")) else {
            continue;
        };
        let Some(joint) = position_of(node) else {
            continue;
        };
        let property = match target.and_then(|t| t.get("path")).and_then(Value::as_str) {
            Some("translation") => Property::Translation,
            Some("rotation") => Property::Rotation,
            Some("scale") => Property::Scale,
            _ => continue,
        };
        let s = field_usize(channel, "sampler").unwrap_or(usize::MAX);
        let sampler = samplers.get(s).ok_or_else(|| {
            bad(
                Part::Channel(chosen, c),
                format!("names sampler {s}, which does not exist"),
            )
        })?;
        let interpolation = match sampler
            .get("interpolation")
            .and_then(Value::as_str)
            .unwrap_or("LINEAR")
        {
            "LINEAR" => Interpolation::Linear,
            "STEP" => Interpolation::Step,
            "CUBICSPLINE" => Interpolation::CubicSpline,
            other => {
                return Err(bad(
                    Part::Sampler(chosen, s),
                    format!("has interpolation '{other}'"),
                ));
            }
        };
        let sampler_error = |(part, message): (Part, String)| {
            bad(Part::Sampler(chosen, s), format!("{part}: {message}"))
        };
        let times = read_floats(
            &asset,
            field_usize(sampler, "input").unwrap_or(usize::MAX),
            1,
        )
        .map_err(sampler_error)?;
        let width = property.width();
        let values = read_floats(
            &asset,
            field_usize(sampler, "output").unwrap_or(usize::MAX),
            width,
        )
        .map_err(sampler_error)?;
        if times.is_empty() {
            return Err(bad(Part::Sampler(chosen, s), "has no keys".into()));
        }
        if times.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad(
                Part::Sampler(chosen, s),
                "has key times that do not increase".into(),
            ));
        }
        let per_key = if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        if values.len() != times.len() * width * per_key {
            return Err(bad(
                Part::Sampler(chosen, s),
                format!(
                    "has {} keys but {} output values ({} expected for {} {:?})",
                    times.len(),
                    values.len() / width,
                    times.len() * per_key,
                    if per_key == 3 {
                        "CUBICSPLINE"
                    } else {
                        "keys of"
                    },
                    property
                ),
            ));
        }
        tracks.push(Track {
            joint,
            property,
            times,
            values,
            interpolation,
        });
    }
    if tracks.is_empty() {
        return Err(bad(animation_part, "moves no joint of the skin".into()));
    }

    // Frame rate and frame count.
    let first = tracks
        .iter()
        .map(|t| f64::from(t.times[0]))
        .fold(f64::INFINITY, f64::min);
    let last = tracks
        .iter()
        .map(|t| f64::from(*t.times.last().expect("keys")))
        .fold(f64::NEG_INFINITY, f64::max);
    let fps = match options.fps {
        Some(fps) => fps,
        None => {
            let mut gaps: Vec<f64> = tracks
                .iter()
                .flat_map(|t| {
                    t.times
                        .windows(2)
                        .map(|w| f64::from(w[1]) - f64::from(w[0]))
                })
                .collect();
            if gaps.is_empty() {
                return Err(bad(
                    animation_part,
                    "has a single key, so no frame rate; give one (--fps)".into(),
                ));
            }
            gaps.sort_by(f64::total_cmp);
            fps_from_frame_time(gaps[gaps.len() / 2])
        }
    };
    if !(fps.is_finite() && fps > 0.0) {
        return Err(bad(animation_part, format!("gives a frame rate of {fps}")));
    }
    let frames = ((last - first) * fps).round() as usize + 1;

    // Each joint's local transform, frame by frame.
    let joints = order.len();
    let mut rotations = Vec::with_capacity(frames * joints);
    let mut translations = Vec::with_capacity(frames * joints);
    for f in 0..frames {
        let t = first + f as f64 / fps;
        for (j, &n) in order.iter().enumerate() {
            let mut translation = rest[n].translation;
            let mut rotation = rest[n].rotation;
            let mut scale = rest[n].scale;
            for track in tracks.iter().filter(|track| track.joint == j) {
                let v = track.sample(t);
                match track.property {
                    Property::Translation => translation = [v[0], v[1], v[2]],
                    Property::Rotation => rotation = rotation_of(v),
                    Property::Scale => scale = [v[0], v[1], v[2]],
                }
            }
            if !unit_scale(scale) {
                return Err(bad(
                    Part::Node(n, node_name(&nodes[n])),
                    format!(
                        "is a joint with scale {scale:?} at {t:.3} s; joints must keep unit scale (fold a unit scale into a node above the root)"
                    ),
                ));
            }
            let local = pre[j].then(&Similarity {
                rotation,
                translation,
                scale: 1.0,
            });
            // Below the root, the nodes above it scale every translation.
            let factor = if j == 0 { 1.0 } else { unit };
            rotations.push(local.rotation);
            translations.push(math::scale(local.translation, factor));
        }
    }

    // Names, unique and non-empty.
    let mut names: Vec<String> = Vec::with_capacity(joints);
    for &n in &order {
        let base = node_name(&nodes[n])
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.split_whitespace().collect::<Vec<_>>().join("_"))
            .unwrap_or_else(|| format!("joint_{n}"));
        let mut name = base.clone();
        let mut k = 2;
        while names.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        names.push(name);
    }

    let skeleton_joints = build_joints(
        &order,
        nodes,
        &names,
        &rotations,
        &translations,
        frames,
        unit,
    );
    let (skeleton, rotations, translations) = drop_static_leaves(
        skeleton_joints,
        rotations,
        translations,
        frames,
        nodes,
        &order,
    );
    let motion = LocalMotion {
        skeleton,
        fps,
        rotations,
        translations,
    };
    Ok(GltfClip {
        clip: motion.to_channels(),
        animation: animations[chosen].clone(),
        animations,
    })
}

/// The channels this crate's writer recorded for node `n`, and its End Site.
fn recorded(node: &Value, unit: f64) -> (Option<Vec<Channel>>, Option<Vec3>) {
    let extras = node.get("extras").and_then(|e| e.get(EXTRAS_KEY));
    let channels = extras
        .and_then(|e| e.get("channels"))
        .and_then(Value::as_array)
        .and_then(|list| {
            list.iter()
                .map(|c| c.as_str().and_then(Channel::parse))
                .collect::<Option<Vec<_>>>()
        });
    let end = numbers::<3>(extras.and_then(|e| e.get("end_site"))).map(|e| math::scale(e, unit));
    (channels, end)
}

/// Largest change of joint `j`'s local rotation and translation over the frames.
fn joint_motion(
    rotations: &[Mat3],
    translations: &[Vec3],
    joints: usize,
    frames: usize,
    j: usize,
) -> (f64, f64) {
    let (r0, t0) = (rotations[j], translations[j]);
    let mut worst = (0.0f64, 0.0f64);
    for f in 1..frames {
        let k = f * joints + j;
        worst.0 = worst.0.max(math::mat_max_abs_diff(&rotations[k], &r0));
        worst.1 = worst.1.max(math::norm(math::sub(translations[k], t0)));
    }
    worst
}

/// The skeleton's joints: offsets from the first frame's translations where no position
/// channel moves them, and channels as recorded, or rotations (and positions where they move).
fn build_joints(
    order: &[usize],
    nodes: &[Value],
    names: &[String],
    rotations: &[Mat3],
    translations: &[Vec3],
    frames: usize,
    unit: f64,
) -> Vec<Joint> {
    let joints = order.len();
    let parent_of = |j: usize| -> Option<usize> {
        // The joint's parent is the nearest earlier joint that lists it beneath: recomputed
        // from the node tree in read_gltf's order (parents precede children).
        (0..j)
            .rev()
            .find(|&p| is_ancestor(nodes, order[p], order[j]))
    };
    (0..joints)
        .map(|j| {
            let (recorded_channels, end_site) = recorded(&nodes[order[j]], unit);
            let (turns, moves) = joint_motion(rotations, translations, joints, frames, j);
            let parent = parent_of(j);
            let default_channels = || {
                let mut channels = Vec::new();
                if parent.is_none() || moves > 1e-9 {
                    channels.extend(
                        ["Xposition", "Yposition", "Zposition"]
                            .map(|c| Channel::parse(c).expect("channel")),
                    );
                }
                channels.extend(
                    ["Zrotation", "Xrotation", "Yrotation"]
                        .map(|c| Channel::parse(c).expect("channel")),
                );
                channels
            };
            // Recorded channels are kept only when they can carry the motion: no rotation
            // channel means the identity, no position channel a fixed offset.
            let channels = match recorded_channels {
                Some(channels) => {
                    let rotates = channels.iter().any(|c| matches!(c, Channel::Rotation(_)));
                    let positions = channels.iter().any(|c| matches!(c, Channel::Position(_)));
                    let identity = math::mat_max_abs_diff(&rotations[j], &math::IDENTITY) < 1e-6;
                    if (rotates || (turns < 1e-6 && identity)) && (positions || moves < 1e-9) {
                        channels
                    } else {
                        default_channels()
                    }
                }
                None => default_channels(),
            };
            Joint {
                name: names[j].clone(),
                parent,
                offset: translations[j],
                channels,
                end_site,
            }
        })
        .collect()
}

/// Whether node `a` is an ancestor of node `b`.
fn is_ancestor(nodes: &[Value], a: usize, b: usize) -> bool {
    let mut stack = vec![a];
    while let Some(n) = stack.pop() {
        for c in nodes[n]
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let Some(c) = c.as_u64().map(|c| c as usize) {
                if c == b {
                    return true;
                }
                if c < nodes.len() {
                    stack.push(c);
                }
            }
        }
    }
    false
}

/// Leaf joints that never move and are their parent's only child become the parent's End Site
/// (files this crate wrote keep their End Sites in extras and have no such joints).
fn drop_static_leaves(
    mut joints: Vec<Joint>,
    rotations: Vec<Mat3>,
    translations: Vec<Vec3>,
    frames: usize,
    nodes: &[Value],
    order: &[usize],
) -> (Skeleton, Vec<Mat3>, Vec<Vec3>) {
    let count = joints.len();
    let mut keep = vec![true; count];
    for j in 1..count {
        let written_by_us = nodes[order[j]]
            .get("extras")
            .and_then(|e| e.get(EXTRAS_KEY))
            .is_some();
        let Some(p) = joints[j].parent else { continue };
        let leaf = !joints.iter().any(|o| o.parent == Some(j));
        let only_child = joints.iter().filter(|o| o.parent == Some(p)).count() == 1;
        let (turns, moves) = joint_motion(&rotations, &translations, count, frames, j);
        if !written_by_us
            && leaf
            && only_child
            && turns < 1e-6
            && moves < 1e-9
            && joints[p].end_site.is_none()
        {
            joints[p].end_site = Some(translations[j]);
            keep[j] = false;
        }
    }
    if keep.iter().all(|&k| k) {
        return (Skeleton { joints }, rotations, translations);
    }
    let new_index: Vec<Option<usize>> = keep
        .iter()
        .scan(0, |next, &k| {
            let index = k.then_some(*next);
            *next += usize::from(k);
            Some(index)
        })
        .collect();
    let kept: Vec<Joint> = joints
        .into_iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(mut joint, _)| {
            joint.parent = joint.parent.and_then(|p| new_index[p]);
            joint
        })
        .collect();
    (
        Skeleton { joints: kept },
        kept_joints(rotations, &keep),
        kept_joints(translations, &keep),
    )
}

/// The `[frames][joints]` values of the joints marked in `keep`.
fn kept_joints<T>(values: Vec<T>, keep: &[bool]) -> Vec<T> {
    values
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep[i % keep.len()])
        .map(|(_, v)| v)
        .collect()
}
