//! The library read back: each clip's state (done, running, failed, stale, pending) and one
//! table of every model's evaluation and training time (Markdown and JSON), and a contact sheet
//! (a row of frames of each model's sample).

use std::path::Path;

use serde::Serialize;

use crate::error::LibraryError;
use crate::fingerprint::{DEFAULT_CONFIG, fingerprint};
use crate::manifest::{ClipEntry, Manifest};
use crate::status::{State, TaskStatus};
use crate::task::TaskFolder;

/// Where a clip stands, as the report sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Standing {
    /// Never started.
    Pending,
    /// Running now (or killed while running).
    Running,
    /// Failed (the error is in the row).
    Failed,
    /// Done, and current.
    Done,
    /// Done, but the clip, its settings, its configuration or the code changed since.
    Stale,
}

impl Standing {
    /// The word for it, as in the JSON report.
    pub fn name(self) -> &'static str {
        match self {
            Standing::Pending => "pending",
            Standing::Running => "running",
            Standing::Failed => "failed",
            Standing::Done => "done",
            Standing::Stale => "stale",
        }
    }
}

/// One clip's line of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The clip's task name.
    pub name: String,
    /// Where it stands.
    pub standing: Standing,
    /// The task's error, when it failed.
    pub error: Option<String>,
    /// Training seconds of the model.
    pub training_seconds: Option<f64>,
    /// Training steps.
    pub steps: Option<u64>,
    /// Coverage in percent of the planted samples.
    pub coverage: Option<f64>,
    /// Global diversity.
    pub global_diversity: Option<f64>,
    /// Local diversity.
    pub local_diversity: Option<f64>,
    /// Harmonic mean of the normalised scores.
    pub harmonic_mean: Option<f64>,
    /// Mean longest verbatim copy of the clip, in seconds.
    pub replay_seconds: Option<f64>,
    /// Share (percent) of the planted samples' frames that are nearly still.
    pub still_percent: Option<f64>,
    /// The same share of the clip's frames.
    pub clip_still_percent: Option<f64>,
    /// The planted samples' median speed over the clip's.
    pub speed_p50_ratio: Option<f64>,
}

/// The largest clip file a manifest may name, as the clip readers' own limits (1 GiB).
const CLIP_LIMIT: sinmdm::files::FileLimit = sinmdm::files::FileLimit {
    bytes: sinmdm::bvh::MAX_BVH_BYTES,
    name: "MAX_BVH_BYTES",
    what: "a clip file",
};

/// The text of the configuration `entry` trains with.
pub fn config_text(manifest: &Manifest, entry: &ClipEntry) -> Result<String, LibraryError> {
    match entry.config.as_ref().or(manifest.config.as_ref()) {
        Some(path) => sinmdm::files::read_text_file(path, "a training configuration")
            .map_err(|e| LibraryError::io(path, e)),
        None => Ok(DEFAULT_CONFIG.to_string()),
    }
}

/// The fingerprint clip `entry` of `manifest` would train under now.
pub fn current_fingerprint(manifest: &Manifest, entry: &ClipEntry) -> Result<String, LibraryError> {
    let bytes = sinmdm::files::read_regular_file(&entry.clip, CLIP_LIMIT, None)
        .map_err(|e| LibraryError::io(&entry.clip, e))?;
    Ok(fingerprint(&bytes, entry, &config_text(manifest, entry)?))
}

fn number(value: &serde_json::Value, path: &[&str]) -> Option<f64> {
    path.iter().try_fold(value, |v, key| v.get(key))?.as_f64()
}

/// Every clip's row, in manifest order.
pub fn rows(manifest: &Manifest) -> Result<Vec<Row>, LibraryError> {
    manifest
        .clips
        .iter()
        .map(|entry| {
            let folder = TaskFolder::new(manifest.folder(entry));
            let status = TaskStatus::read(&folder.status())?;
            // A clip that cannot be read now (deleted, unreadable) is judged by its status only.
            let current = current_fingerprint(manifest, entry).ok();
            let standing = match &status {
                None => Standing::Pending,
                Some(s) if s.state == State::Running => Standing::Running,
                Some(s) if s.state == State::Failed => Standing::Failed,
                Some(s)
                    if current.as_deref() != Some(s.fingerprint.as_str())
                        || !folder.is_current(&s.fingerprint) =>
                {
                    Standing::Stale
                }
                Some(_) => Standing::Done,
            };
            let eval: Option<serde_json::Value> = std::fs::read_to_string(folder.eval())
                .ok()
                .and_then(|t| serde_json::from_str(&t).ok());
            let eval = eval.as_ref();
            let report = |key: &[&str]| {
                eval.and_then(|e| {
                    number(e, &[&["planted_report"], key].concat())
                        .or_else(|| number(e, &[&["report"], key].concat()))
                })
            };
            Ok(Row {
                name: Manifest::name(entry).to_string(),
                standing,
                error: status.as_ref().and_then(|s| s.error.clone()),
                training_seconds: status.as_ref().and_then(|s| s.training_seconds),
                steps: status.as_ref().and_then(|s| s.steps),
                coverage: report(&["coverage", "mean"]),
                global_diversity: report(&["global_diversity", "mean"]),
                local_diversity: report(&["local_diversity", "mean"]),
                harmonic_mean: report(&["harmonic_mean"]),
                replay_seconds: eval.and_then(|e| number(e, &["replay", "mean_seconds"])),
                still_percent: eval
                    .and_then(|e| number(e, &["kinematics", "planted", "still_share"]))
                    .map(|s| 100.0 * s),
                clip_still_percent: eval
                    .and_then(|e| number(e, &["kinematics", "clip", "still_share"]))
                    .map(|s| 100.0 * s),
                speed_p50_ratio: eval.and_then(|e| {
                    e.pointer("/kinematics/planted/speed_ratios/1")
                        .and_then(serde_json::Value::as_f64)
                }),
            })
        })
        .collect()
}

fn cell(value: Option<f64>, digits: usize) -> String {
    value.map_or("".into(), |v| format!("{v:.digits$}"))
}

/// The state of every clip, one line each (`sinmdm library status`).
pub fn status_text(rows: &[Row]) -> String {
    let mut out = String::new();
    for row in rows {
        out.push_str(&format!("{:<24} {}", row.name, row.standing.name()));
        if let Some(error) = &row.error {
            out.push_str(&format!(": {}", error.lines().next().unwrap_or("")));
        }
        out.push('\n');
    }
    let count = |s: Standing| rows.iter().filter(|r| r.standing == s).count();
    out.push_str(&format!(
        "{} clips: {} done, {} running, {} failed, {} stale, {} pending\n",
        rows.len(),
        count(Standing::Done),
        count(Standing::Running),
        count(Standing::Failed),
        count(Standing::Stale),
        count(Standing::Pending)
    ));
    out
}

/// The table of every model (Markdown).
pub fn markdown(rows: &[Row]) -> String {
    let mut out = String::from(
        "| clip | state | coverage (%) | global div. | local div. | harmonic mean | replay (s) | still (%), clip's | speed p50 (x clip's) | steps | training (min) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.name,
            r.standing.name(),
            cell(r.coverage, 1),
            cell(r.global_diversity, 3),
            cell(r.local_diversity, 3),
            cell(r.harmonic_mean, 3),
            cell(r.replay_seconds, 2),
            match (r.still_percent, r.clip_still_percent) {
                (Some(s), Some(c)) => format!("{s:.1} ({c:.1})"),
                _ => String::new(),
            },
            cell(r.speed_p50_ratio, 2),
            r.steps.map_or(String::new(), |s| s.to_string()),
            cell(r.training_seconds.map(|s| s / 60.0), 1),
        ));
    }
    out
}

/// A contact sheet: for each clip with a sample, a row of `frames` evenly spaced frames of it,
/// labelled with the clip's name; `None` when no clip has a sample yet.
pub fn contact_sheet(manifest: &Manifest, frames: usize) -> Result<Option<Vec<u8>>, LibraryError> {
    use sinmdm_render::figure::{Figure, RenderOptions, contact_sheet};
    let mut figures = Vec::new();
    for entry in &manifest.clips {
        let folder = TaskFolder::new(manifest.folder(entry));
        let path = folder.sample();
        if !path.is_file() {
            continue;
        }
        let clip = sinmdm::bvh::read_bvh(&path).map_err(|e| LibraryError::Status {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let motion = clip.to_local();
        let up = sinmdm::motion::up_detect::detect_up(&motion).axis;
        figures.push(Figure::new(&motion, up, Manifest::name(entry), 1.0));
    }
    if figures.is_empty() {
        return Ok(None);
    }
    let options = RenderOptions::default();
    Ok(Some(contact_sheet(&figures, frames, &options).to_png()))
}

/// Writes `report.md`, `report.json` and `contact_sheet.png` (when any sample exists) into
/// `dir`, each whole or not at all; returns the files written.
pub fn write_report(
    manifest: &Manifest,
    dir: &Path,
) -> Result<Vec<std::path::PathBuf>, LibraryError> {
    std::fs::create_dir_all(dir).map_err(|e| LibraryError::io(dir, e))?;
    let rows = rows(manifest)?;
    let mut written = Vec::new();
    let md = dir.join("report.md");
    sinmdm::files::write_atomically(&md, markdown(&rows).as_bytes())
        .map_err(|e| LibraryError::io(&md, e))?;
    written.push(md);
    let json = dir.join("report.json");
    let text = serde_json::to_string_pretty(&rows).expect("rows serialise");
    sinmdm::files::write_atomically(&json, text.as_bytes())
        .map_err(|e| LibraryError::io(&json, e))?;
    written.push(json);
    if let Some(png) = contact_sheet(manifest, 4)? {
        let path = dir.join("contact_sheet.png");
        sinmdm::files::write_atomically(&path, &png).map_err(|e| LibraryError::io(&path, e))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::Standing;

    #[test]
    fn the_words_are_the_json_reports() {
        for s in [
            Standing::Pending,
            Standing::Running,
            Standing::Failed,
            Standing::Done,
            Standing::Stale,
        ] {
            assert_eq!(serde_json::to_value(s).unwrap(), s.name());
        }
    }
}
