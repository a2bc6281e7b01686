//! Audio in: a mono mix of a WAV file (or, with the `compressed` feature, MP3, OGG Vorbis and
//! FLAC), as floats in -1..1.

use std::path::Path;

use sinmdm::files::{FileLimit, regular_file_size};

use crate::BeatsError;

/// The largest audio file read (1 GiB): hours of uncompressed CD audio.
pub const MAX_AUDIO_BYTES: u64 = 1 << 30;
/// The most mono samples a piece of music may have once decoded (2^26: 23 minutes at 48 kHz,
/// 256 MiB of floats): beyond any dance a model makes, and a bound on what a compressed file
/// (or a WAV header) can make the reader allocate.
pub const MAX_AUDIO_SAMPLES: usize = 1 << 26;
/// The size limit of audio files.
const AUDIO_LIMIT: FileLimit = FileLimit {
    bytes: MAX_AUDIO_BYTES,
    name: "MAX_AUDIO_BYTES",
    what: "an audio file",
};

/// Mono audio: samples in -1..1 at `rate` samples per second.
#[derive(Debug, Clone, PartialEq)]
pub struct Audio {
    /// The samples (the mean of the file's channels).
    pub samples: Vec<f32>,
    /// Samples per second.
    pub rate: u32,
}

impl Audio {
    /// Length in seconds.
    pub fn seconds(&self) -> f64 {
        self.samples.len() as f64 / self.rate.max(1) as f64
    }
}

/// Reads an audio file as mono: WAV always, MP3/OGG/FLAC with the `compressed` feature. Only a
/// regular file of at most [`MAX_AUDIO_BYTES`] is opened (a FIFO would block the reader), and
/// decoding stops with an error past [`MAX_AUDIO_SAMPLES`].
pub fn read_audio(path: &Path) -> Result<Audio, BeatsError> {
    regular_file_size(path, AUDIO_LIMIT).map_err(|source| BeatsError::Io {
        path: path.to_path_buf(),
        reason: source,
    })?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match extension.as_str() {
        "wav" | "wave" => read_wav(path),
        _ => read_compressed(path),
    }
}

fn read_wav(path: &Path) -> Result<Audio, BeatsError> {
    let decode = |e: hound::Error| match e {
        hound::Error::IoError(source) => BeatsError::Io {
            path: path.to_path_buf(),
            reason: source,
        },
        other => BeatsError::Decode {
            path: path.to_path_buf(),
            reason: other.to_string(),
        },
    };
    let reader = hound::WavReader::open(path).map_err(decode)?;
    let spec = reader.spec();
    if spec.sample_rate == 0 {
        return Err(BeatsError::Decode {
            path: path.to_path_buf(),
            reason: "the header's sample rate is 0".into(),
        });
    }
    // The header's own count first, so a long file is refused before it is decoded.
    too_long(path, reader.duration() as usize)?;
    let channels = usize::from(spec.channels.max(1));
    // The header is trusted for the reservation only as far as the file's size backs it.
    let backed = std::fs::metadata(path).map_or(0, |m| m.len()) as usize
        / (channels * usize::from(spec.bits_per_sample.div_ceil(8)).max(1));
    let mut samples = Vec::with_capacity((reader.duration() as usize).min(backed));
    let mut frame = Vec::with_capacity(channels);
    let mut push = |value: f32| -> Result<(), BeatsError> {
        frame.push(value);
        if frame.len() == channels {
            samples.push(frame.iter().sum::<f32>() / channels as f32);
            frame.clear();
            too_long(path, samples.len())?;
        }
        Ok(())
    };
    match spec.sample_format {
        hound::SampleFormat::Float => {
            for value in reader.into_samples::<f32>() {
                push(value.map_err(decode)?)?;
            }
        }
        hound::SampleFormat::Int => {
            let scale = 1.0 / (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f32;
            for value in reader.into_samples::<i32>() {
                push(value.map_err(decode)? as f32 * scale)?;
            }
        }
    }
    Ok(Audio {
        samples,
        rate: spec.sample_rate,
    })
}

/// Refuses a piece of music of more than [`MAX_AUDIO_SAMPLES`] mono samples.
fn too_long(path: &Path, samples: usize) -> Result<(), BeatsError> {
    if samples > MAX_AUDIO_SAMPLES {
        return Err(BeatsError::Decode {
            path: path.to_path_buf(),
            reason: format!(
                "more than {MAX_AUDIO_SAMPLES} samples (MAX_AUDIO_SAMPLES, 23 minutes at 48 kHz); \
                 cut the music to the part to dance to"
            ),
        });
    }
    Ok(())
}

/// The mean of each frame's `channels` interleaved samples.
pub fn mono(interleaved: &[f32], channels: usize) -> Vec<f32> {
    let channels = channels.max(1);
    interleaved
        .chunks_exact(channels)
        .map(|frame| frame.iter().sum::<f32>() / channels as f32)
        .collect()
}

#[cfg(not(feature = "compressed"))]
fn read_compressed(path: &Path) -> Result<Audio, BeatsError> {
    Err(BeatsError::Unsupported {
        path: path.to_path_buf(),
    })
}

#[cfg(feature = "compressed")]
fn read_compressed(path: &Path) -> Result<Audio, BeatsError> {
    use symphonia::core::audio::SampleBuffer;
    use symphonia::core::codecs::DecoderOptions;
    use symphonia::core::formats::FormatOptions;
    use symphonia::core::io::MediaSourceStream;
    use symphonia::core::meta::MetadataOptions;
    use symphonia::core::probe::Hint;

    let fail = |reason: String| BeatsError::Decode {
        path: path.to_path_buf(),
        reason,
    };
    let file = std::fs::File::open(path).map_err(|source| BeatsError::Io {
        path: path.to_path_buf(),
        reason: source,
    })?;
    let stream = MediaSourceStream::new(Box::new(file), Default::default());
    let mut hint = Hint::new();
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        hint.with_extension(ext);
    }
    let probed = symphonia::default::get_probe()
        .format(
            &hint,
            stream,
            &FormatOptions::default(),
            &MetadataOptions::default(),
        )
        .map_err(|e| fail(e.to_string()))?;
    let mut format = probed.format;
    let track = format
        .default_track()
        .ok_or_else(|| fail("no audio track".into()))?;
    let track_id = track.id;
    let mut decoder = symphonia::default::get_codecs()
        .make(&track.codec_params, &DecoderOptions::default())
        .map_err(|e| fail(e.to_string()))?;
    let mut samples = Vec::new();
    let mut rate = track.codec_params.sample_rate.unwrap_or(0);
    loop {
        let packet = match format.next_packet() {
            Ok(p) => p,
            Err(symphonia::core::errors::Error::IoError(e))
                if e.kind() == std::io::ErrorKind::UnexpectedEof =>
            {
                break;
            }
            Err(e) => return Err(fail(e.to_string())),
        };
        if packet.track_id() != track_id {
            continue;
        }
        let decoded = decoder.decode(&packet).map_err(|e| fail(e.to_string()))?;
        let spec = *decoded.spec();
        rate = spec.rate;
        let mut buffer = SampleBuffer::<f32>::new(decoded.capacity() as u64, spec);
        buffer.copy_interleaved_ref(decoded);
        samples.extend(mono(buffer.samples(), spec.channels.count()));
        too_long(path, samples.len())?;
    }
    if rate == 0 {
        return Err(fail("no sample rate".into()));
    }
    Ok(Audio { samples, rate })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mono_averages_each_frame() {
        assert_eq!(
            mono(&[1.0, 0.0, 0.5, 0.5, -1.0, 1.0], 2),
            vec![0.5, 0.5, 0.0]
        );
        assert_eq!(mono(&[0.25, -0.25], 1), vec![0.25, -0.25]);
    }

    #[test]
    fn a_sixteen_bit_wav_reads_back_as_its_samples() {
        let dir = std::env::temp_dir().join(format!("sinmdm-beats-audio-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("two_channels.wav");
        let spec = hound::WavSpec {
            channels: 2,
            sample_rate: 8000,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut writer = hound::WavWriter::create(&path, spec).unwrap();
        for (l, r) in [(16384i16, 0i16), (-32768, -32768), (0, 8192)] {
            writer.write_sample(l).unwrap();
            writer.write_sample(r).unwrap();
        }
        writer.finalize().unwrap();
        let audio = read_audio(&path).unwrap();
        assert_eq!(audio.rate, 8000);
        assert_eq!(audio.samples, vec![0.25, -1.0, 0.125]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_file_names_itself() {
        let e = read_audio(Path::new("no/such/song.wav")).unwrap_err();
        assert!(e.to_string().contains("no/such/song.wav"), "{e}");
    }
}
