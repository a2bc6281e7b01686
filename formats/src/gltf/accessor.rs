//! Reading accessors: the typed arrays a glTF file keeps in its buffers, checked against the
//! buffer they point into.

use serde_json::Value;

use super::container::Asset;
use crate::error::Part;

/// The float values of accessor `index` (`width` per element, which its `type` must give),
/// converted from any component type the spec allows for animation data (normalised integers
/// included). `Err` names what is wrong.
pub fn read_floats(asset: &Asset, index: usize, width: usize) -> Result<Vec<f32>, (Part, String)> {
    let part = Part::Accessor(index);
    let bad = |message: String| (part.clone(), message);
    let accessor = asset
        .json
        .get("accessors")
        .and_then(|a| a.get(index))
        .ok_or_else(|| bad("does not exist".into()))?;
    let count = field_usize(accessor, "count").ok_or_else(|| bad("has no count".into()))?;
    let kind = accessor.get("type").and_then(Value::as_str).unwrap_or("");
    let kind_width = match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT4" => 16,
        _ => return Err(bad(format!("has type '{kind}'"))),
    };
    if kind_width != width {
        return Err(bad(format!(
            "is {kind}, where {width} values per element are needed"
        )));
    }
    let component = field_usize(accessor, "componentType").unwrap_or(0);
    let (size, convert) = component_reader(component).map_err(bad)?;
    if component != 5126 && accessor.get("normalized").and_then(Value::as_bool) != Some(true) {
        return Err(bad("holds integers that are not normalized".into()));
    }
    if accessor.get("sparse").is_some() {
        return Err(bad("is sparse, which this reader does not take".into()));
    }
    let values = count
        .checked_mul(width)
        .ok_or_else(|| bad(format!("count {count} is too large")))?;
    let Some(view_index) = field_usize(accessor, "bufferView") else {
        // No buffer view: all zeros, as the spec says.
        return Ok(vec![0.0; values]);
    };
    let BufferView {
        view,
        buffer,
        offset: view_offset,
        end: view_end,
    } = buffer_view(asset, view_index)?;
    let element = width * size;
    let stride = field_usize(view, "byteStride")
        .unwrap_or(element)
        .max(element);
    let offset = field_usize(accessor, "byteOffset").unwrap_or(0);
    let needed = if count == 0 {
        0
    } else {
        (count - 1)
            .checked_mul(stride)
            .and_then(|v| v.checked_add(element))
            .and_then(|v| v.checked_add(offset))
            .ok_or_else(|| bad(format!("count {count} is too large")))?
    };
    if needed > view_end - view_offset {
        return Err(bad(format!(
            "needs {needed} bytes but its bufferView {view_index} has {}",
            view_end - view_offset
        )));
    }
    let data = &buffer[view_offset + offset..view_end];
    let mut out = Vec::with_capacity(values);
    for e in 0..count {
        let at = e * stride;
        for k in 0..width {
            out.push(convert(&data[at + k * size..at + (k + 1) * size]));
        }
    }
    if let Some(i) = out.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("value {i} is {}", out[i])));
    }
    Ok(out)
}

/// Converts one value's little-endian bytes to `f32`.
type Convert = fn(&[u8]) -> f32;

/// The byte size and the converter to `f32` of one value of accessor component type
/// `component`, or why that type is not taken.
fn component_reader(component: usize) -> Result<(usize, Convert), String> {
    Ok(match component {
        5126 => (4, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        5120 => (1, |b| (f32::from(b[0] as i8) / 127.0).max(-1.0)),
        5121 => (1, |b| f32::from(b[0]) / 255.0),
        5122 => (2, |b| {
            (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }),
        5123 => (2, |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0),
        _ => {
            return Err(format!(
                "has componentType {component}, not a float or a normalised integer"
            ));
        }
    })
}

/// A buffer view: its JSON, the buffer it points into, and its byte range there.
struct BufferView<'a> {
    view: &'a Value,
    buffer: &'a [u8],
    offset: usize,
    end: usize,
}

/// Buffer view `view_index`, checked to lie within its buffer.
fn buffer_view(asset: &Asset, view_index: usize) -> Result<BufferView<'_>, (Part, String)> {
    let view_part = Part::BufferView(view_index);
    let view = asset
        .json
        .get("bufferViews")
        .and_then(|v| v.get(view_index))
        .ok_or_else(|| (view_part.clone(), "does not exist".into()))?;
    let buffer_index = field_usize(view, "buffer").unwrap_or(usize::MAX);
    let buffer = asset.buffers.get(buffer_index).ok_or_else(|| {
        (
            view_part.clone(),
            format!("names buffer {buffer_index}, which does not exist"),
        )
    })?;
    let view_offset = field_usize(view, "byteOffset").unwrap_or(0);
    let view_length = field_usize(view, "byteLength").unwrap_or(0);
    let view_end = view_offset
        .checked_add(view_length)
        .filter(|&e| e <= buffer.len())
        .ok_or_else(|| {
            (
                view_part.clone(),
                format!(
                    "bytes {view_offset}..+{view_length} run past buffer {buffer_index}'s {} bytes",
                    buffer.len()
                ),
            )
        })?;
    Ok(BufferView {
        view,
        buffer,
        offset: view_offset,
        end: view_end,
    })
}

/// A non-negative integer field of a JSON object.
pub fn field_usize(object: &Value, key: &str) -> Option<usize> {
    object
        .get(key)
        .and_then(Value::as_u64)
        .and_then(|v| usize::try_from(v).ok())
}
