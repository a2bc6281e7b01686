//! Beats a person gives: a file of beat times, or a tempo and the time of the first beat; and
//! the arithmetic shared by everything that reads beats (the fitted tempo, the F-measure).

use std::path::Path;

use crate::BeatsError;

/// Most beats a grid or file may hold (a beat every 50 ms for a day is far less).
pub const MAX_BEATS: usize = 2_000_000;

/// Reads beat times in seconds, one per line. Blank lines and lines starting with `#` are
/// skipped; on a line with commas, tabs or spaces the first field is the time (so a CSV whose
/// first column is the time reads as it is, after an optional header line that is not a
/// number). Times must increase.
pub fn read_beat_file(path: &Path) -> Result<Vec<f64>, BeatsError> {
    let text =
        sinmdm::files::read_text_file(path, "a beat list").map_err(|source| BeatsError::Io {
            path: path.to_path_buf(),
            reason: source,
        })?;
    let mut times: Vec<f64> = Vec::new();
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut seen_data = false;
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let field = line
            .split([',', '\t', ' ', ';'])
            .find(|f| !f.is_empty())
            .unwrap_or("");
        let bad = |reason: String| BeatsError::BeatFile {
            path: path.to_path_buf(),
            line: i + 1,
            reason,
        };
        let first_line = !seen_data;
        seen_data = true;
        let time: f64 = match field.parse() {
            Ok(t) => t,
            // A header: the first line that is not a comment, with no digit in it.
            Err(_) if first_line && !line.chars().any(|c| c.is_ascii_digit()) => continue,
            Err(_) => return Err(bad(format!("'{field}' is not a time in seconds"))),
        };
        if !time.is_finite() || time < 0.0 {
            return Err(bad(format!(
                "{field} is not a time in seconds (at least 0)"
            )));
        }
        if let Some(&before) = times.last()
            && time <= before
        {
            return Err(bad(format!(
                "{time} s comes after {before} s: beat times must increase"
            )));
        }
        if times.len() == MAX_BEATS {
            return Err(bad(format!("more than {MAX_BEATS} beats")));
        }
        times.push(time);
    }
    if times.len() < 2 {
        return Err(BeatsError::BeatFile {
            path: path.to_path_buf(),
            line: text.lines().count().max(1),
            reason: format!("{} beat(s) in the file; at least 2 are needed", times.len()),
        });
    }
    Ok(times)
}

/// Beats every `60 / bpm` seconds from `offset` up to `seconds`.
pub fn beat_grid(bpm: f64, offset: f64, seconds: f64) -> Result<Vec<f64>, BeatsError> {
    if !(bpm.is_finite() && (10.0..=1000.0).contains(&bpm)) {
        return Err(BeatsError::Grid(format!(
            "a tempo of {bpm} BPM is not usable: give 10 to 1000 beats per minute"
        )));
    }
    if !(offset.is_finite() && offset >= 0.0) {
        return Err(BeatsError::Grid(format!(
            "an offset of {offset} s is not usable: give the first beat's time, at least 0"
        )));
    }
    let interval = 60.0 / bpm;
    let count = ((seconds - offset) / interval).floor();
    if !(count.is_finite() && count >= 1.0) {
        return Err(BeatsError::Grid(format!(
            "no two beats at {bpm} BPM from {offset} s fit in {seconds:.2} s"
        )));
    }
    if count >= MAX_BEATS as f64 {
        return Err(BeatsError::Grid(format!(
            "more than {MAX_BEATS} beats at {bpm} BPM in {seconds:.0} s"
        )));
    }
    Ok((0..=count as usize)
        .map(|k| offset + k as f64 * interval)
        .collect())
}

/// The least-squares slope of beat time against beat number: the beat interval in seconds.
pub fn fitted_interval(times: &[f64]) -> f64 {
    let n = times.len() as f64;
    if times.len() < 2 {
        return f64::NAN;
    }
    let mean_k = (n - 1.0) / 2.0;
    let mean_t = times.iter().sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for (k, t) in times.iter().enumerate() {
        num += (k as f64 - mean_k) * (t - mean_t);
        den += (k as f64 - mean_k).powi(2);
    }
    num / den
}

/// Beat F-measure of `estimated` against `reference` (both increasing, seconds): each reference
/// beat matches at most one estimated beat within `tolerance` seconds (greedy, in time order).
pub fn f_measure(reference: &[f64], estimated: &[f64], tolerance: f64) -> f64 {
    if reference.is_empty() || estimated.is_empty() {
        return 0.0;
    }
    let mut used = vec![false; estimated.len()];
    let mut hits = 0usize;
    for &r in reference {
        let best = estimated
            .iter()
            .enumerate()
            .filter(|(i, e)| !used[*i] && (*e - r).abs() <= tolerance)
            .min_by(|a, b| (a.1 - r).abs().total_cmp(&(b.1 - r).abs()));
        if let Some((i, _)) = best {
            used[i] = true;
            hits += 1;
        }
    }
    let precision = hits as f64 / estimated.len() as f64;
    let recall = hits as f64 / reference.len() as f64;
    if hits == 0 {
        0.0
    } else {
        2.0 * precision * recall / (precision + recall)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_has_the_asked_tempo_and_offset() {
        let g = beat_grid(120.0, 0.25, 3.0).unwrap();
        assert_eq!(g, vec![0.25, 0.75, 1.25, 1.75, 2.25, 2.75]);
        assert!((fitted_interval(&g) - 0.5).abs() < 1e-12);
        assert!(beat_grid(0.0, 0.0, 10.0).is_err());
        assert!(beat_grid(120.0, -1.0, 10.0).is_err());
        assert!(beat_grid(120.0, 9.9, 10.0).is_err());
    }

    #[test]
    fn f_measure_counts_each_beat_once() {
        let reference = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(f_measure(&reference, &reference, 0.07), 1.0);
        // Half tempo: precision 1, recall 0.5.
        assert!((f_measure(&reference, &[1.0, 3.0], 0.07) - 2.0 / 3.0).abs() < 1e-12);
        // Off-beat: nothing within 70 ms.
        assert_eq!(f_measure(&reference, &[1.5, 2.5, 3.5], 0.07), 0.0);
        // Two estimates near one beat: one counts.
        assert!((f_measure(&[1.0], &[0.98, 1.02], 0.07) - 2.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_beat_file_reads_times_and_names_its_bad_line() {
        let dir = std::env::temp_dir().join(format!("sinmdm-beats-grid-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("beats.csv");
        std::fs::write(
            &good,
            "time,strength\n# a comment\n0.5,1\n1.0,0.3\n\n1.5,0.9\n",
        )
        .unwrap();
        assert_eq!(read_beat_file(&good).unwrap(), vec![0.5, 1.0, 1.5]);
        let bad = dir.join("bad.txt");
        std::fs::write(&bad, "0.5\n1.0\n0.8\n").unwrap();
        let e = read_beat_file(&bad).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("increase"), "{e}");
        std::fs::write(&bad, "0.5\nsoon\n").unwrap();
        let e = read_beat_file(&bad).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("soon"), "{e}");
        // A byte-order mark is not a header; a first time with a typo is an error, not skipped.
        std::fs::write(&bad, "\u{feff}0.5\n1.0\n1.5\n").unwrap();
        assert_eq!(read_beat_file(&bad).unwrap(), vec![0.5, 1.0, 1.5]);
        std::fs::write(&bad, "# tapped\n0.5s\n1.0\n").unwrap();
        let e = read_beat_file(&bad).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("0.5s"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
