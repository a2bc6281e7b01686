//! The tracker against exact ground truth: synthetic click tracks at five tempos, three phases
//! each, under white noise. (The drum pattern, the tiled loops and librosa's agreement are in
//! the Python suite, tests/python/test_beat_tracker.py.)

use sinmdm_beats::grid::{f_measure, fitted_interval};
use sinmdm_beats::{Audio, track_beats};

const RATE: u32 = 22050;

/// A small deterministic generator for the noise (xorshift64*), uniform in -1..1.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (v >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    }
}

fn click_track(bpm: f64, phase: f64, seconds: f64, seed: u64) -> (Audio, Vec<f64>) {
    let n = (seconds * RATE as f64) as usize;
    let mut noise = Noise(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let mut samples: Vec<f32> = (0..n).map(|_| 0.035 * noise.next()).collect();
    let interval = 60.0 / bpm;
    let mut beats = Vec::new();
    let mut t = 0.5 + phase * interval;
    while t < seconds - 0.25 {
        beats.push(t);
        let start = (t * RATE as f64).round() as usize;
        for i in 0..(0.02 * RATE as f64) as usize {
            let s = i as f64 / RATE as f64;
            samples[start + i] +=
                (0.8 * (2.0 * std::f64::consts::PI * 1000.0 * s).sin() * (-s / 0.004).exp()) as f32;
        }
        t += interval;
    }
    (
        Audio {
            samples,
            rate: RATE,
        },
        beats,
    )
}

fn median_error(truth: &[f64], found: &[f64]) -> f64 {
    let mut errors: Vec<f64> = truth
        .iter()
        .map(|t| found.iter().map(|f| (f - t).abs()).fold(f64::MAX, f64::min))
        .collect();
    errors.sort_by(f64::total_cmp);
    errors[errors.len() / 2]
}

#[test]
fn click_tracks_give_their_tempo_and_beats() {
    for bpm in [60.0, 90.0, 120.0, 128.0, 174.0] {
        for (k, phase) in [0.0, 0.37, 0.71].into_iter().enumerate() {
            let (audio, truth) = click_track(bpm, phase, 30.0, k as u64 + 1);
            let beats = track_beats(&audio).unwrap();
            let tempo_error = (beats.bpm - bpm).abs() / bpm;
            let f = f_measure(&truth, &beats.times, 0.07);
            let median = median_error(&truth, &beats.times);
            assert!(
                tempo_error <= 0.02 && f >= 0.9 && median <= 0.03,
                "{bpm} BPM, phase {phase}: found {:.2} BPM, F {f:.3}, median error {:.1} ms",
                beats.bpm,
                median * 1000.0
            );
            assert!(beats.confidence > 0.5, "confidence {}", beats.confidence);
            // The reported tempo is the beats' own slope, not the envelope's frame grid.
            assert!((60.0 / fitted_interval(&beats.times) - beats.bpm).abs() < 1e-9);
        }
    }
}

#[test]
fn noise_alone_has_no_confident_beat() {
    let mut noise = Noise(7);
    let audio = Audio {
        samples: (0..RATE as usize * 10)
            .map(|_| 0.3 * noise.next())
            .collect(),
        rate: RATE,
    };
    match track_beats(&audio) {
        Ok(beats) => assert!(beats.confidence < 0.5, "confidence {}", beats.confidence),
        Err(e) => assert!(e.to_string().contains("no beat"), "{e}"),
    }
}

#[test]
fn a_short_clip_is_refused_with_its_length() {
    let audio = Audio {
        samples: vec![0.0; RATE as usize],
        rate: RATE,
    };
    let e = track_beats(&audio).unwrap_err().to_string();
    assert!(e.contains("1.00 s") && e.contains("--bpm"), "{e}");
}

/// With the `compressed` feature, FLAC reads as the same samples as the WAV it was made from
/// (tests/data/audio/drum_heavy_kick.flac: the WAV written by soundfile as 16-bit FLAC).
#[cfg(feature = "compressed")]
#[test]
fn flac_reads_as_its_wav() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/audio");
    let wav = sinmdm_beats::read_audio(&dir.join("drum_heavy_kick.wav")).unwrap();
    let flac = sinmdm_beats::read_audio(&dir.join("drum_heavy_kick.flac")).unwrap();
    assert_eq!(
        (flac.rate, flac.samples.len()),
        (wav.rate, wav.samples.len())
    );
    let worst = wav
        .samples
        .iter()
        .zip(&flac.samples)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(worst <= 1.0 / 32768.0, "{worst}");
}

/// Without it, a compressed file is refused with the way round.
#[cfg(not(feature = "compressed"))]
#[test]
fn flac_needs_the_compressed_feature() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/audio");
    let e = sinmdm_beats::read_audio(&dir.join("drum_heavy_kick.flac"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("compressed") && e.contains("WAV"), "{e}");
}
