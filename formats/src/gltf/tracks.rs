//! An animation's channels that move the skeleton's joints, read as tracks and sampled as the
//! glTF specification says, and the frame rate their keys give.

use std::path::Path;

use serde_json::Value;
use sinmdm::motion::fps_from_frame_time;
use sinmdm::motion::math;

use super::accessor::{field_usize, read_floats};
use super::container::Asset;
use super::nodes::node_name;
pub(crate) use crate::animation::MAX_CLIP_FRAMES;
use crate::error::{FormatError, Part};

/// How a sampler interpolates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Interpolation {
    Linear,
    Step,
    CubicSpline,
}

/// One animated property of one joint.
pub(super) struct Track {
    pub(super) joint: usize,
    pub(super) property: Property,
    pub(super) times: Vec<f32>,
    /// `width` values per key; CUBICSPLINE keeps in-tangent, value, out-tangent per key.
    values: Vec<f32>,
    interpolation: Interpolation,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Property {
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
    /// `[x, y, z, w]` (unit). A key within `snap` seconds of `t` is taken as it is: key times
    /// are f32, so the key of frame `f` may sit an ulp away from `f / fps`, and interpolating
    /// across that ulp would blend in a sliver of the neighbouring frame.
    pub(super) fn sample(&self, t: f64, snap: f64) -> [f64; 4] {
        let width = self.property.width();
        let keys = self.times.len();
        let value = |key: usize| -> [f64; 4] {
            let base = match self.interpolation {
                Interpolation::CubicSpline => (3 * key + 1) * width,
                _ => key * width,
            };
            let mut out = [0.0; 4];
            for (o, v) in out.iter_mut().zip(&self.values[base..base + width]) {
                *o = f64::from(*v);
            }
            out
        };
        let nearest = self.times.partition_point(|&key| f64::from(key) <= t);
        let close = [nearest.checked_sub(1), (nearest < keys).then_some(nearest)]
            .into_iter()
            .flatten()
            .find(|&k| (f64::from(self.times[k]) - t).abs() <= snap);
        let result = if let Some(k) = close {
            value(k)
        } else if t <= f64::from(self.times[0]) {
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

/// The tracks of animation `chosen` that move joints (`joint_of` gives a node's joint index),
/// each checked: a sampler that exists, increasing key times, as many values as keys.
pub(super) fn read_tracks(
    path: &Path,
    asset: &Asset,
    chosen: usize,
    joint_of: impl Fn(usize) -> Option<usize>,
) -> Result<Vec<Track>, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
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
        let Some(joint) = joint_of(node) else {
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
        tracks.push(sampler_track(
            path,
            asset,
            (chosen, s),
            sampler,
            (joint, property),
        )?);
    }
    if tracks.is_empty() {
        return Err(bad(animation_part, "moves no joint of the skin".into()));
    }

    Ok(tracks)
}

/// The track of sampler `s` of animation `chosen` for `joint`'s `property`, checked: a known
/// interpolation, readable accessors, increasing key times, as many values as keys.
fn sampler_track(
    path: &Path,
    asset: &Asset,
    (chosen, s): (usize, usize),
    sampler: &Value,
    (joint, property): (usize, Property),
) -> Result<Track, FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
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
        asset,
        field_usize(sampler, "input").unwrap_or(usize::MAX),
        1,
    )
    .map_err(sampler_error)?;
    let width = property.width();
    let values = read_floats(
        asset,
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
    Ok(Track {
        joint,
        property,
        times,
        values,
        interpolation,
    })
}

/// The first key time, the frame rate (`asked`, or the median key spacing snapped to a whole
/// rate) and the frame count of `tracks`, from animation `part`.
pub(super) fn frame_rate(
    path: &Path,
    part: Part,
    tracks: &[Track],
    asked: Option<f64>,
) -> Result<(f64, f64, usize), FormatError> {
    let bad = |part: Part, message: String| FormatError::bad(path, part, message);
    let animation_part = part;
    // Frame rate and frame count.
    let first = tracks
        .iter()
        .map(|t| f64::from(t.times[0]))
        .fold(f64::INFINITY, f64::min);
    let last = tracks
        .iter()
        .map(|t| f64::from(*t.times.last().expect("keys")))
        .fold(f64::NEG_INFINITY, f64::max);
    let fps = match asked {
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
    let span = ((last - first) * fps).round();
    if span >= MAX_CLIP_FRAMES as f64 {
        return Err(bad(
            animation_part,
            format!(
                "lasts {:.1} s, {span} frames at {fps} fps, more than the {MAX_CLIP_FRAMES} a clip may have; is the frame rate right (--fps)?",
                last - first
            ),
        ));
    }
    Ok((first, fps, span as usize + 1))
}
