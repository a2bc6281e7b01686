//! Audio files as strangers send them: a WAV written byte by byte here reads as its known mono
//! mix, and a header that claims hours, a FIFO or a folder are refused at once, by name.

use std::path::PathBuf;

use sinmdm_beats::{MAX_AUDIO_SAMPLES, read_audio};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sinmdm-audio-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 16-bit PCM WAV file: RIFF header, `fmt ` chunk, and a `data` chunk that says
/// `claimed_bytes` but holds `samples` (interleaved).
fn wav(channels: u16, rate: u32, samples: &[i16], claimed_bytes: Option<u32>) -> Vec<u8> {
    let data: Vec<u8> = samples.iter().flat_map(|s| s.to_le_bytes()).collect();
    let data_size = claimed_bytes.unwrap_or(data.len() as u32);
    let mut out = Vec::new();
    out.extend(b"RIFF");
    out.extend((36 + data_size).to_le_bytes());
    out.extend(b"WAVEfmt ");
    out.extend(16u32.to_le_bytes());
    out.extend(1u16.to_le_bytes()); // PCM
    out.extend(channels.to_le_bytes());
    out.extend(rate.to_le_bytes());
    out.extend((rate * u32::from(channels) * 2).to_le_bytes());
    out.extend((channels * 2).to_le_bytes());
    out.extend(16u16.to_le_bytes());
    out.extend(b"data");
    out.extend(data_size.to_le_bytes());
    out.extend(data);
    out
}

#[test]
fn a_stereo_wav_reads_as_the_mean_of_its_channels() {
    let dir = temp_dir("stereo");
    let file = dir.join("two.wav");
    // Frames (left, right): the mono mix is their mean over 32768.
    let frames = [
        (16384i16, 0i16),
        (-32768, -32768),
        (8192, -8192),
        (100, 300),
    ];
    let interleaved: Vec<i16> = frames.iter().flat_map(|&(l, r)| [l, r]).collect();
    std::fs::write(&file, wav(2, 8000, &interleaved, None)).unwrap();
    let audio = read_audio(&file).unwrap();
    let expected: Vec<f32> = frames
        .iter()
        .map(|&(l, r)| (f32::from(l) / 32768.0 + f32::from(r) / 32768.0) / 2.0)
        .collect();
    assert_eq!(audio.rate, 8000);
    assert_eq!(audio.samples, expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_header_that_claims_more_than_the_limit_is_refused_before_decoding() {
    let dir = temp_dir("long");
    let file = dir.join("long.wav");
    let claimed = 2 * (MAX_AUDIO_SAMPLES as u32 + 1);
    std::fs::write(&file, wav(1, 48_000, &[1, 2, 3], Some(claimed))).unwrap();
    let e = read_audio(&file).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("long.wav") && message.contains("MAX_AUDIO_SAMPLES"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The message holds the reason once, and no source repeats it to a printer of causes.
fn said_once(e: &sinmdm_beats::BeatsError, reason: &str) {
    let message = e.to_string();
    assert_eq!(message.matches(reason).count(), 1, "{message}");
    assert!(std::error::Error::source(e).is_none(), "{message}");
}

#[test]
fn a_folder_a_fifo_or_a_missing_file_is_refused_by_name() {
    let dir = temp_dir("odd");
    let folder = dir.join("music.wav");
    std::fs::create_dir_all(&folder).unwrap();
    let e = read_audio(&folder).unwrap_err();
    said_once(&e, "is a directory, not a regular file");
    let e = read_audio(&dir.join("absent.wav")).unwrap_err();
    assert!(e.to_string().contains("absent.wav"), "{e}");
    said_once(&e, "No such file");
    #[cfg(unix)]
    {
        let fifo = dir.join("pipe.wav");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(made.success());
        // Opening a FIFO for reading would block until a writer comes: refused first.
        let e = read_audio(&fifo).unwrap_err();
        said_once(&e, "a device, FIFO or socket, not a regular file");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
