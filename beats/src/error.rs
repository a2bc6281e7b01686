use std::path::PathBuf;

use thiserror::Error;

/// Why beats could not be read, found or written.
#[derive(Debug, Error)]
pub enum BeatsError {
    /// A file that could not be opened, read or written. The reason is said in the message and
    /// not chained as a source, so a printer of causes (`{:#}`) says it once.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's reason, or the limit the file broke.
        reason: std::io::Error,
    },
    /// An audio file that could not be decoded.
    #[error("{path}: {reason}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// What the decoder said.
        reason: String,
    },
    /// An audio format this build does not read.
    #[error(
        "{path}: only WAV is read by this build; MP3, OGG and FLAC need the `compressed` feature (cargo build --features compressed), or convert the file to WAV"
    )]
    Unsupported {
        /// The file.
        path: PathBuf,
    },
    /// Audio too short to hold a tempo.
    #[error(
        "the audio is {seconds:.2} s long; at least 2 s are needed to find a tempo (give the beats with --beats or --bpm instead)"
    )]
    TooShort {
        /// Its length.
        seconds: f64,
    },
    /// Audio in which no beat stands out (silence, a drone).
    #[error(
        "no beat found in {seconds:.1} s of audio (silence or no onsets); give the beats with --beats or --bpm"
    )]
    NoBeats {
        /// Its length.
        seconds: f64,
    },
    /// A motion in which no regular beat stands out (fewer than two speed minima on a beat).
    #[error(
        "no dance beat in {seconds:.1} s of motion: fewer than two speed minima fall on a regular beat"
    )]
    NoMotionBeats {
        /// Its length.
        seconds: f64,
    },
    /// A bad line in a beat file.
    #[error("{path}, line {line}: {reason}")]
    BeatFile {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A tempo or offset that makes no beat grid.
    #[error("{0}")]
    Grid(String),
}
