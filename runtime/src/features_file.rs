//! Raw feature arrays as JSON: what `sinmdm encode` and `--features-json` write, and what the
//! Python reference reads and writes, so both sides can be compared value for value.
//!
//! ```json
//! {"format": "sinmdm-features", "version": 1, "fps": 30.0,
//!  "columns": ["Hips.dX", ...], "samples": [[[f32; N]; F]; B]}
//! ```
//! Values are unnormalised (file units, 6D rotations, 0/1 contacts); f32 printed in shortest
//! round-trip form, so reading gives back the same bits.

use std::path::{Path, PathBuf};

use ndarray::{Array3, ArrayView3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::files::write_atomically;
use crate::motion::FeatureLayout;

/// The `format` field.
pub const FORMAT: &str = "sinmdm-features";
/// The `version` field this crate writes and reads.
pub const VERSION: u32 = 1;

/// A features file that could not be read or written.
#[derive(Debug, Error)]
pub enum FeaturesFileError {
    /// Reading or writing failed. The reason is said in the message and not chained as a
    /// source, so a printer of causes (`{:#}`) says it once.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said, or the limit the file broke.
        reason: std::io::Error,
    },
    /// Not a features file of this version, or ragged arrays.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// The largest features file read (1 GiB): a long clip's features as text stay far below it.
pub const MAX_FEATURES_FILE_BYTES: u64 = 1 << 30;

/// The size limit of features files.
const FEATURES_FILE_LIMIT: crate::files::FileLimit = crate::files::FileLimit {
    bytes: MAX_FEATURES_FILE_BYTES,
    name: "MAX_FEATURES_FILE_BYTES",
    what: "a features file",
};

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FeaturesJson {
    format: String,
    version: u32,
    fps: f64,
    columns: Vec<String>,
    samples: Vec<Vec<Vec<f32>>>,
}

/// Writes `features` `[B, F, N]` with the layout's column names and frame rate.
pub fn write_features(
    path: &Path,
    layout: &FeatureLayout,
    features: ArrayView3<'_, f32>,
) -> Result<(), FeaturesFileError> {
    let doc = FeaturesJson {
        format: FORMAT.into(),
        version: VERSION,
        fps: layout.fps,
        columns: layout
            .columns()
            .iter()
            .map(|c| layout.column_name(c))
            .collect(),
        samples: features
            .outer_iter()
            .map(|s| s.outer_iter().map(|row| row.to_vec()).collect())
            .collect(),
    };
    let text = serde_json::to_string(&doc).map_err(|e| FeaturesFileError::Format {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomically(path, text.as_bytes()).map_err(|source| FeaturesFileError::Io {
        path: path.to_path_buf(),
        reason: source,
    })
}

/// Reads a features file: the array `[B, F, N]` and the frame rate.
pub fn read_features(path: &Path) -> Result<(Array3<f32>, f64), FeaturesFileError> {
    let bad = |message: String| FeaturesFileError::Format {
        path: path.to_path_buf(),
        message,
    };
    let text = crate::files::read_regular_text(path, FEATURES_FILE_LIMIT).map_err(|source| {
        FeaturesFileError::Io {
            path: path.to_path_buf(),
            reason: source,
        }
    })?;
    let doc: FeaturesJson = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    if doc.format != FORMAT || doc.version != VERSION {
        return Err(bad(format!(
            "format '{}' version {}, expected '{FORMAT}' version {VERSION}",
            doc.format, doc.version
        )));
    }
    let b = doc.samples.len();
    let f = doc.samples.first().map_or(0, Vec::len);
    let n = doc
        .samples
        .first()
        .and_then(|s| s.first())
        .map_or(0, Vec::len);
    let mut out = Array3::<f32>::zeros((b, f, n));
    for (i, sample) in doc.samples.iter().enumerate() {
        if sample.len() != f || sample.iter().any(|r| r.len() != n) {
            return Err(bad(format!("sample {i} is not {f} rows of {n} frames")));
        }
        for (r, row) in sample.iter().enumerate() {
            for (k, &v) in row.iter().enumerate() {
                out[[i, r, k]] = v;
            }
        }
    }
    if f != doc.columns.len() {
        return Err(bad(format!(
            "{} column names for {f} feature rows",
            doc.columns.len()
        )));
    }
    Ok((out, doc.fps))
}

#[cfg(all(test, feature = "bvh"))]
mod tests {
    use super::*;
    use crate::motion::{EncodeOptions, encode};

    #[test]
    fn written_features_read_back_exactly() {
        let clip = crate::bvh::parse_bvh(
            "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT Leg\n {\n  OFFSET 0 -1 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 -1 0\n  }\n }\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n0 2 0 0 0 0 10 0 0\n0.5 2 0 5 0 0 20 0 0\n1 2.1 0 10 0 0 30 0 0\n",
            "clip.bvh",
        )
        .unwrap();
        let encoded = encode(&clip, &EncodeOptions::default()).unwrap();
        let batch = encoded.features.clone().insert_axis(ndarray::Axis(0));
        let path =
            std::env::temp_dir().join(format!("sinmdm-features-{}.json", std::process::id()));
        write_features(&path, &encoded.layout, batch.view()).unwrap();
        let (back, fps) = read_features(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back, batch);
        assert_eq!(fps, encoded.layout.fps);
    }
}
