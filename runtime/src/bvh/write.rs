//! Our BVH writer: the input's joint names, exact offsets, units and per-joint channel lists,
//! motion values with six decimals, and the right Frame Time.

use std::fmt::Write as _;
use std::path::Path;

use super::error::{BvhError, BvhErrorKind};
use crate::files::write_atomically;
use crate::motion::clip::ChannelClip;
use crate::motion::skeleton::Skeleton;

/// Formats a number with six decimals, writing negative zero as zero.
fn num(out: &mut String, value: f64) {
    let value = if value == 0.0 { 0.0 } else { value };
    let _ = write!(out, "{value:.6}");
    if out.ends_with("-0.000000") {
        out.truncate(out.len() - "-0.000000".len());
        out.push_str("0.000000");
    }
}

/// Formats an offset: six decimals when that is exact, otherwise the shortest text that reads
/// back to the same number, so the skeleton is never altered.
fn exact_num(out: &mut String, value: f64) {
    let start = out.len();
    num(out, value);
    if out[start..].parse::<f64>().ok() != Some(value) {
        out.truncate(start);
        let _ = write!(out, "{value}");
    }
}

fn hierarchy(out: &mut String, skeleton: &Skeleton, joint: usize, depth: usize) {
    let j = &skeleton.joints[joint];
    let indent = "\t".repeat(depth);
    let keyword = if j.parent.is_none() { "ROOT" } else { "JOINT" };
    let _ = writeln!(out, "{indent}{keyword} {}", j.name);
    let _ = writeln!(out, "{indent}{{");
    out.push_str(&indent);
    out.push_str("\tOFFSET");
    for v in j.offset {
        out.push(' ');
        exact_num(out, v);
    }
    out.push('\n');
    let _ = write!(out, "{indent}\tCHANNELS {}", j.channels.len());
    for c in &j.channels {
        let _ = write!(out, " {}", c.bvh_name());
    }
    out.push('\n');
    for child in skeleton.children(joint) {
        hierarchy(out, skeleton, child, depth + 1);
    }
    if let Some(end) = j.end_site {
        let _ = writeln!(out, "{indent}\tEnd Site");
        let _ = writeln!(out, "{indent}\t{{");
        let _ = write!(out, "{indent}\t\tOFFSET");
        for v in end {
            out.push(' ');
            exact_num(out, v);
        }
        out.push('\n');
        let _ = writeln!(out, "{indent}\t}}");
    }
    let _ = writeln!(out, "{indent}}}");
}

/// The HIERARCHY and the MOTION block's header (frame count and frame time) of a file.
pub(crate) fn header_text(skeleton: &Skeleton, fps: f64, frames: usize) -> String {
    let mut out = String::from("HIERARCHY\n");
    if !skeleton.is_empty() {
        hierarchy(&mut out, skeleton, 0, 0);
    }
    out.push_str("MOTION\n");
    let _ = writeln!(out, "Frames: {frames}");
    let _ = writeln!(out, "Frame Time: {:.8}", 1.0 / fps);
    out
}

/// Appends one MOTION line.
pub(crate) fn push_row(out: &mut String, values: &[f64]) {
    for (i, &v) in values.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        num(out, v);
    }
    out.push('\n');
}

/// The clip as BVH text (LF line ends).
pub fn to_bvh_string(clip: &ChannelClip) -> String {
    let mut out = header_text(&clip.skeleton, clip.fps, clip.frame_count());
    out.reserve(clip.values.len() * 11);
    for f in 0..clip.frame_count() {
        push_row(&mut out, clip.frame(f));
    }
    out
}

/// Writes the clip to `path` atomically: the file appears complete or not at all.
pub fn write_bvh(path: impl AsRef<Path>, clip: &ChannelClip) -> Result<(), BvhError> {
    let path = path.as_ref();
    write_atomically(path, to_bvh_string(clip).as_bytes()).map_err(|e| BvhError {
        file: path.display().to_string(),
        line: None,
        kind: BvhErrorKind::Io(e),
    })
}
