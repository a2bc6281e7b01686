//! Beats of a piece of music, for sinmdm's dance task.
//!
//! The tracker follows the well-known dynamic-programming design (Ellis 2007, as in librosa):
//! an onset-strength envelope (log-mel spectral flux, [`onset`]), a tempo from the envelope's
//! windowed autocorrelation weighted by a prior around 120 BPM ([`tempo`]), then the beat
//! sequence that best balances onset strength against a steady period ([`track`]). The tempo
//! reported is the slope of the tracked beats, so it is not limited to the envelope's frame grid.
//!
//! Trackers find the tempo far more often than the phase (on-beat against off-beat), so every
//! consumer of beats also takes them from a file ([`grid::read_beat_file`]) or a tempo and
//! offset ([`grid::beat_grid`]).
//!
//! Audio comes in as WAV ([`audio::read_audio`]; MP3, OGG Vorbis and FLAC with the `compressed`
//! feature), and [`click::write_click_track`] writes the song with a click on every beat, so a
//! person can hear whether the beats are right.

pub mod audio;
pub mod click;
mod error;
pub mod grid;
pub mod onset;
pub mod pulses;
pub mod tempo;
pub mod track;
mod window;

pub use audio::{Audio, MAX_AUDIO_BYTES, MAX_AUDIO_SAMPLES, read_audio};
pub use error::BeatsError;

/// Tempo and beats of a piece of music.
#[derive(Debug, Clone, PartialEq)]
pub struct Beats {
    /// Tempo in beats per minute.
    pub bpm: f64,
    /// Beat times in seconds from the start of the audio, increasing.
    pub times: Vec<f64>,
    /// How strongly the onsets mark the beats, 0 to 1: `1 - m / b`, where `b` is the mean over
    /// beats of the onset strength's largest value within two envelope frames of each, and `m`
    /// its mean over the whole piece (0 when the beats are no stronger than any moment; near 1
    /// when nearly all onset energy sits on them).
    pub confidence: f64,
}

/// Anything that finds the beats of mono audio.
pub trait BeatTracker {
    /// The beats of `audio`.
    fn track(&self, audio: &Audio) -> Result<Beats, BeatsError>;
}

/// Settings of [`DynamicProgrammingTracker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerOptions {
    /// Centre of the tempo prior, in BPM.
    pub prior_bpm: f64,
    /// Width of the tempo prior, in octaves (standard deviation of log2 tempo).
    pub prior_octaves: f64,
    /// Slowest tempo considered, in BPM.
    pub min_bpm: f64,
    /// Fastest tempo considered, in BPM.
    pub max_bpm: f64,
    /// How strongly the beat sequence keeps its period (librosa's `tightness`).
    pub tightness: f64,
}

impl Default for TrackerOptions {
    fn default() -> TrackerOptions {
        TrackerOptions {
            prior_bpm: 120.0,
            prior_octaves: 1.0,
            min_bpm: 30.0,
            max_bpm: 300.0,
            tightness: 100.0,
        }
    }
}

/// The dynamic-programming beat tracker (see the crate's documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DynamicProgrammingTracker {
    /// Its settings.
    pub options: TrackerOptions,
}

impl BeatTracker for DynamicProgrammingTracker {
    fn track(&self, audio: &Audio) -> Result<Beats, BeatsError> {
        let envelope = onset::OnsetEnvelope::of(audio)?;
        let period = tempo::estimate_period(&envelope, &self.options)?;
        let frames = track::beat_frames(&envelope.values, period, self.options.tightness);
        if frames.len() < 2 {
            return Err(BeatsError::NoBeats {
                seconds: audio.seconds(),
            });
        }
        let times: Vec<f64> = frames.iter().map(|&f| envelope.time_of(f)).collect();
        let bpm = 60.0 / grid::fitted_interval(&times);
        Ok(Beats {
            bpm,
            confidence: track::confidence(&envelope.values, &frames),
            times,
        })
    }
}

/// The beats of `audio` with the default tracker.
pub fn track_beats(audio: &Audio) -> Result<Beats, BeatsError> {
    DynamicProgrammingTracker::default().track(audio)
}
