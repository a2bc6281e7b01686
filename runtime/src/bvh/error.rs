//! What can be wrong with a BVH file, said with its file name and line.

use std::fmt;
use thiserror::Error;

/// A BVH file that could not be read or written. Displays as `file:line: problem`.
#[derive(Debug, Error)]
pub struct BvhError {
    /// The file's path as given, or `<memory>` for text parsed from memory.
    pub file: String,
    /// 1-based line number, where one applies.
    pub line: Option<usize>,
    /// What is wrong.
    pub kind: BvhErrorKind,
}

impl fmt::Display for BvhError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.file, line, self.kind),
            None => write!(f, "{}: {}", self.file, self.kind),
        }
    }
}

/// The problem itself.
#[derive(Debug, Error)]
pub enum BvhErrorKind {
    /// Reading or writing the file failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The file holds nothing but white space.
    #[error("the file is empty")]
    Empty,
    /// A keyword or symbol other than the one the format needs here.
    #[error("expected {expected}, found '{found}'")]
    Expected {
        /// What the format needs.
        expected: &'static str,
        /// What the file has.
        found: String,
    },
    /// The file ends where more is needed.
    #[error("the file ends where {expected} was expected")]
    UnexpectedEnd {
        /// What the format needs.
        expected: String,
    },
    /// A `CHANNELS` entry that is not one of the six BVH channel names.
    #[error(
        "joint '{joint}': unknown channel '{name}' (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)"
    )]
    UnknownChannel {
        /// The joint.
        joint: String,
        /// The unknown name.
        name: String,
    },
    /// The same channel listed twice for one joint.
    #[error("joint '{joint}': channel {channel} is listed twice")]
    RepeatedChannel {
        /// The joint.
        joint: String,
        /// The repeated channel.
        channel: String,
    },
    /// A joint without channels (the model could not animate it).
    #[error("joint '{joint}' has no channels")]
    NoChannels {
        /// The joint.
        joint: String,
    },
    /// A joint without an `OFFSET` line.
    #[error("joint '{joint}' has no OFFSET")]
    MissingOffset {
        /// The joint.
        joint: String,
    },
    /// Two joints with one name.
    #[error("joint name '{name}' is used twice (first at line {first_line})")]
    DuplicateJoint {
        /// The repeated name.
        name: String,
        /// Where it was first used.
        first_line: usize,
    },
    /// A number that does not parse.
    #[error("{what}: '{text}' is not a number")]
    BadNumber {
        /// Which number (e.g. `OFFSET of joint 'Hips'` or `frame 12, Hips Xposition`).
        what: String,
        /// The text found.
        text: String,
    },
    /// NaN or infinity.
    #[error("{what}: '{text}' is not a finite number")]
    NonFinite {
        /// Which number.
        what: String,
        /// The text found.
        text: String,
    },
    /// A motion line with too many or too few values.
    #[error("frame {frame} has {found} values, but the hierarchy declares {expected} channels")]
    WrongValueCount {
        /// 0-based frame index.
        frame: usize,
        /// Channels declared by the hierarchy.
        expected: usize,
        /// Values found on the line.
        found: usize,
    },
    /// Fewer frame lines than `Frames:` announces.
    #[error("truncated MOTION block: 'Frames: {announced}' but only {found} frame lines")]
    Truncated {
        /// Frames announced.
        announced: usize,
        /// Frame lines present.
        found: usize,
    },
    /// More frame lines than `Frames:` announces.
    #[error("more frame lines than the {announced} announced by 'Frames:'")]
    TooManyFrames {
        /// Frames announced.
        announced: usize,
    },
    /// More of something (joints, nesting, name bytes) than the reader takes.
    #[error("{what}: more than the {limit} a BVH file may have ({name})")]
    OverLimit {
        /// What is counted (`joint 'j4096'`).
        what: String,
        /// The limit.
        limit: usize,
        /// The constant that sets it.
        name: &'static str,
    },
    /// `Frames: 0`.
    #[error("the clip has zero frames")]
    ZeroFrames,
    /// A frame time that is zero, negative or not finite.
    #[error("Frame Time must be a positive number of seconds, found '{0}'")]
    BadFrameTime(String),
}
