//! A click track: the song (mono) with a short tone burst on every beat, to hear whether the
//! beats are right.

use std::path::Path;

use crate::{Audio, BeatsError};

/// Frequency of the click's tone.
pub const CLICK_HZ: f64 = 1760.0;
/// Length of a click, in seconds.
pub const CLICK_SECONDS: f64 = 0.03;

/// The song with a click at each of `beats` (seconds), the song at half level so the clicks
/// stand out, limited to -1..1.
pub fn with_clicks(song: &Audio, beats: &[f64]) -> Audio {
    let rate = song.rate as f64;
    let mut samples: Vec<f32> = song.samples.iter().map(|s| 0.5 * s).collect();
    let length = (CLICK_SECONDS * rate).round() as usize;
    for &beat in beats {
        let start = (beat * rate).round();
        if start.is_nan() || start < 0.0 {
            continue;
        }
        let start = start as usize;
        for i in 0..length {
            let Some(slot) = samples.get_mut(start + i) else {
                break;
            };
            let t = i as f64 / rate;
            let decay = (-t / (CLICK_SECONDS / 4.0)).exp();
            *slot += (0.6 * decay * (2.0 * std::f64::consts::PI * CLICK_HZ * t).sin()) as f32;
        }
    }
    for s in &mut samples {
        *s = s.clamp(-1.0, 1.0);
    }
    Audio {
        samples,
        rate: song.rate,
    }
}

/// Writes `song` with clicks at `beats` as 16-bit mono WAV to `path`, through a temporary file
/// beside it, so a failed write leaves no half-written file.
pub fn write_click_track(path: &Path, song: &Audio, beats: &[f64]) -> Result<(), BeatsError> {
    write_wav(path, &with_clicks(song, beats))
}

/// Writes mono audio as 16-bit WAV, through a temporary file beside `path`.
pub fn write_wav(path: &Path, audio: &Audio) -> Result<(), BeatsError> {
    let io = |source: std::io::Error| BeatsError::Io {
        path: path.to_path_buf(),
        reason: source,
    };
    let partial = path.with_extension("wav.partial");
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: audio.rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let result = (|| -> Result<(), hound::Error> {
        let mut writer = hound::WavWriter::create(&partial, spec)?;
        for &s in &audio.samples {
            writer.write_sample((s.clamp(-1.0, 1.0) * 32767.0).round() as i16)?;
        }
        writer.finalize()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&partial);
        return Err(match e {
            hound::Error::IoError(source) => io(source),
            other => BeatsError::Decode {
                path: path.to_path_buf(),
                reason: other.to_string(),
            },
        });
    }
    std::fs::rename(&partial, path).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read_audio;

    #[test]
    fn clicks_land_at_the_beats_and_the_file_reads_back() {
        let song = Audio {
            samples: vec![0.0; 8000],
            rate: 8000,
        };
        let clicked = with_clicks(&song, &[0.25, 0.5]);
        let loud: Vec<usize> = clicked
            .samples
            .iter()
            .enumerate()
            .filter(|(_, s)| s.abs() > 0.2)
            .map(|(i, _)| i)
            .collect();
        assert!(
            loud.iter()
                .all(|&i| (2000..2240).contains(&i) || (4000..4240).contains(&i))
        );
        assert!(loud.iter().any(|&i| i < 2240) && loud.iter().any(|&i| i >= 4000));
        let dir = std::env::temp_dir().join(format!("sinmdm-beats-click-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("click.wav");
        write_click_track(&path, &song, &[0.25, 0.5]).unwrap();
        let back = read_audio(&path).unwrap();
        assert_eq!(back.samples.len(), 8000);
        for (a, b) in back.samples.iter().zip(&clicked.samples) {
            assert!((a - b).abs() < 1.0 / 16000.0);
        }
        assert!(!path.with_extension("wav.partial").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
