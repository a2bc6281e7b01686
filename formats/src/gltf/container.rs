//! The two ways a glTF asset is stored: a binary `.glb` (a JSON chunk and a binary chunk in one
//! file) and a `.gltf` JSON file whose buffers are data URIs or side-car files.

use std::path::Path;

use crate::error::{FormatError, Part};
use crate::files::{FileAccess, GLTF_BUFFER_LIMIT, GLTF_LIMIT, read_file, side_car_path};
use sinmdm::files::{read_regular_file, regular_file_size};

/// `glTF` in little-endian ASCII.
const GLB_MAGIC: u32 = 0x4654_6C67;
/// The GLB container version this reads and writes.
const GLB_VERSION: u32 = 2;
/// Chunk type of the JSON chunk (`JSON`).
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
const CHUNK_BIN: u32 = 0x004E_4942;
/// The prefix of an embedded base64 buffer.
const DATA_URI_PREFIXES: [&str; 2] = [
    "data:application/octet-stream;base64,",
    "data:application/gltf-buffer;base64,",
];

/// A glTF asset in memory: its JSON document and its buffers' bytes, in buffer order.
#[derive(Debug, Clone)]
pub struct Asset {
    /// The JSON document.
    pub json: serde_json::Value,
    /// The bytes of each buffer.
    pub buffers: Vec<Vec<u8>>,
    /// The bytes read to make it: the file, and a `.gltf`'s decoded buffers.
    pub bytes_read: usize,
}

/// A GLB file of `json` (serialised compactly) and one binary chunk `bin`.
pub fn glb_bytes(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(json).expect("a JSON value serialises");
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let mut bin_bytes = bin.to_vec();
    while !bin_bytes.len().is_multiple_of(4) {
        bin_bytes.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin_bytes.len();
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, GLB_VERSION, total as u32] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    out.extend_from_slice(&bin_bytes);
    out
}

/// Reads a `.glb` or `.gltf` file (chosen by its first bytes, not its name); `access` says
/// whether a `.gltf` file's side-car buffers may lie outside its folder.
pub fn read_asset(path: &Path, access: FileAccess) -> Result<Asset, FormatError> {
    let bytes = read_file(path, GLTF_LIMIT)?;
    if is_glb(&bytes) {
        parse_glb(path, &bytes)
    } else {
        let json: serde_json::Value = serde_json::from_slice(&bytes)
            .map_err(|e| FormatError::bad(path, Part::Json, format!("is not JSON: {e}")))?;
        let buffers = load_buffers(path, &json, None, access)?;
        let bytes_read = bytes.len() + buffers.iter().map(Vec::len).sum::<usize>();
        Ok(Asset {
            json,
            buffers,
            bytes_read,
        })
    }
}

/// Whether `bytes` start as a GLB container does (`glTF`).
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.len() >= 4 && bytes[..4] == GLB_MAGIC.to_le_bytes()
}

/// Parses a GLB container.
pub fn parse_glb(path: &Path, bytes: &[u8]) -> Result<Asset, FormatError> {
    let bad = |message: String| FormatError::bad(path, Part::Container, message);
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if bytes.len() < 20 {
        return Err(bad(format!(
            "has {} bytes, too few for a GLB header",
            bytes.len()
        )));
    }
    let version = word(4).unwrap_or(0);
    if version != GLB_VERSION {
        return Err(bad(format!(
            "is GLB version {version}; only version 2 is read"
        )));
    }
    let length = word(8).unwrap_or(0) as usize;
    if length > bytes.len() {
        return Err(bad(format!(
            "says it is {length} bytes long but has {} (truncated?)",
            bytes.len()
        )));
    }
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at + 8 <= length {
        let size = word(at).unwrap_or(0) as usize;
        let kind = word(at + 4).unwrap_or(0);
        let start = at + 8;
        let end = start
            .checked_add(size)
            .filter(|&e| e <= length)
            .ok_or_else(|| {
                bad(format!(
                    "has a chunk at byte {at} of {size} bytes that runs past the file's end"
                ))
            })?;
        match kind {
            CHUNK_JSON if json.is_none() => json = Some(&bytes[start..end]),
            CHUNK_BIN if bin.is_none() => bin = Some(bytes[start..end].to_vec()),
            _ => {}
        }
        at = end + (4 - end % 4) % 4;
    }
    let json = json.ok_or_else(|| bad("has no JSON chunk".into()))?;
    let json: serde_json::Value = serde_json::from_slice(json)
        .map_err(|e| FormatError::bad(path, Part::Json, format!("JSON chunk: {e}")))?;
    // A GLB's buffers are its binary chunk and data URIs; side-car files are for `.gltf`.
    let buffers = load_buffers(path, &json, bin, FileAccess::default())?;
    Ok(Asset {
        json,
        buffers,
        bytes_read: bytes.len(),
    })
}

/// The bytes of every buffer of `json`: the GLB's binary chunk for a buffer without a URI,
/// embedded base64 data, or a regular file in `path`'s folder (elsewhere when `access` allows
/// it), of which no more than its `byteLength` is read.
fn load_buffers(
    path: &Path,
    json: &serde_json::Value,
    mut bin: Option<Vec<u8>>,
    access: FileAccess,
) -> Result<Vec<Vec<u8>>, FormatError> {
    let Some(buffers) = json.get("buffers") else {
        return Ok(Vec::new());
    };
    let buffers = buffers
        .as_array()
        .ok_or_else(|| FormatError::bad(path, Part::Json, "'buffers' is not an array".into()))?;
    let mut out = Vec::with_capacity(buffers.len());
    let mut declared = 0u64;
    for (index, buffer) in buffers.iter().enumerate() {
        let part = Part::Buffer(index);
        let length = buffer
            .get("byteLength")
            .and_then(serde_json::Value::as_u64)
            .ok_or_else(|| FormatError::bad(path, part.clone(), "has no byteLength".into()))?;
        declared = declared.saturating_add(length);
        if declared > GLTF_BUFFER_LIMIT.bytes {
            let total = if declared > length {
                format!(", {declared} bytes with the buffers before it")
            } else {
                String::new()
            };
            return Err(FormatError::bad(
                path,
                part,
                format!(
                    "declares a byteLength of {length}{total}, more than the {} {} may have ({})",
                    GLTF_BUFFER_LIMIT.bytes, GLTF_BUFFER_LIMIT.what, GLTF_BUFFER_LIMIT.name
                ),
            ));
        }
        let length = length as usize;
        let bytes = match buffer.get("uri").and_then(serde_json::Value::as_str) {
            None => bin.take().ok_or_else(|| {
                FormatError::bad(
                    path,
                    part.clone(),
                    "has no uri and the file has no binary chunk".into(),
                )
            })?,
            Some(uri) => {
                if let Some(data) = DATA_URI_PREFIXES.iter().find_map(|p| uri.strip_prefix(p)) {
                    base64_decode(data).ok_or_else(|| {
                        FormatError::bad(path, part.clone(), "holds malformed base64 data".into())
                    })?
                } else if uri.starts_with("data:") {
                    return Err(FormatError::bad(
                        path,
                        part,
                        "holds a data URI that is not base64 binary data".into(),
                    ));
                } else {
                    let side = side_car_path(path, uri, access)
                        .map_err(|message| FormatError::bad(path, part.clone(), message))?;
                    let io = |reason| FormatError::Io {
                        path: side.clone(),
                        reason,
                    };
                    let size = regular_file_size(&side, GLTF_BUFFER_LIMIT).map_err(io)?;
                    if size < length as u64 {
                        return Err(FormatError::bad(
                            path,
                            part,
                            format!(
                                "says it has {length} bytes but its file {} has {size} (truncated?)",
                                side.display()
                            ),
                        ));
                    }
                    read_regular_file(&side, GLTF_BUFFER_LIMIT, Some(length as u64)).map_err(io)?
                }
            }
        };
        if bytes.len() < length {
            return Err(FormatError::bad(
                path,
                part,
                format!(
                    "has {} bytes but says it has {length} (truncated?)",
                    bytes.len()
                ),
            ));
        }
        out.push(bytes);
    }
    Ok(out)
}

const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 with padding.
pub fn base64_encode(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(BASE64[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Decodes standard base64 (padding optional); `None` for a character outside the alphabet.
pub fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for c in text.bytes() {
        if c == b'=' {
            break;
        }
        let v = BASE64.iter().position(|&b| b == c)? as u32;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_and_matches_known_text() {
        assert_eq!(base64_encode(b"glTF"), "Z2xURg==");
        assert_eq!(
            base64_encode(b"any carnal pleas"),
            "YW55IGNhcm5hbCBwbGVhcw=="
        );
        for n in 0..40 {
            let bytes: Vec<u8> = (0..n).map(|i| (i * 37 + 11) as u8).collect();
            assert_eq!(base64_decode(&base64_encode(&bytes)).unwrap(), bytes);
        }
        assert_eq!(base64_decode("Z2x!"), None);
    }

    #[test]
    fn a_glb_round_trips_and_a_truncated_one_is_refused() {
        let json = serde_json::json!({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 5}]});
        let bytes = glb_bytes(&json, &[1, 2, 3, 4, 5]);
        assert_eq!(bytes.len() % 4, 0);
        let asset = parse_glb(Path::new("t.glb"), &bytes).unwrap();
        assert_eq!(asset.json, json);
        assert_eq!(&asset.buffers[0][..5], &[1, 2, 3, 4, 5]);
        let err = parse_glb(Path::new("t.glb"), &bytes[..bytes.len() - 8]).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
    }
}
