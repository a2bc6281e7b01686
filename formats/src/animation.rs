//! Which animation of a file is the clip, and what a reader of keyframed formats (glTF, FBX) is
//! asked beyond its defaults.

use std::path::Path;

use crate::error::{FormatError, Part};

/// The most frames a clip read from keyframes (glTF, FBX) may have: 14 minutes at 120 fps, far beyond a
/// training clip, and a bound on what a malformed file (keys a million seconds apart, say) can
/// make the reader allocate.
pub const MAX_CLIP_FRAMES: usize = 100_000;
/// The most joint transforms (frames x joints) a clip read from keyframes (glTF, FBX) may have: about 1 GB.
pub const MAX_JOINT_FRAMES: usize = 10_000_000;

/// Which animation of a file is the clip.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AnimationChoice {
    /// By position in the file's list of animations.
    Index(usize),
    /// By name.
    Name(String),
}

impl AnimationChoice {
    /// A number is an index, anything else a name.
    pub fn parse(text: &str) -> AnimationChoice {
        match text.parse() {
            Ok(index) => AnimationChoice::Index(index),
            Err(_) => AnimationChoice::Name(text.to_string()),
        }
    }
}

/// What a reader is asked to do beyond the defaults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// The animation to read (default: the first).
    pub animation: Option<AnimationChoice>,
    /// The frame rate to sample at (default: the file's, or for glTF the key spacing).
    pub fps: Option<f64>,
}

/// One animation of a file, as `inspect` lists them.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationInfo {
    /// Its index in the file.
    pub index: usize,
    /// Its name, if it has one.
    pub name: Option<String>,
    /// From its first key to its last, in seconds.
    pub seconds: f64,
}

/// The index of the animation `options` ask for (default: the first); `what` is the format's
/// word for an animation in messages.
pub(crate) fn choose_animation(
    path: &Path,
    animations: &[AnimationInfo],
    options: &ReadOptions,
    (part, what): (Part, &str),
) -> Result<usize, FormatError> {
    let bad = |message: String| FormatError::bad(path, part.clone(), message);
    if animations.is_empty() {
        return Err(bad(format!("has no {what}")));
    }
    match &options.animation {
        None => Ok(0),
        Some(AnimationChoice::Index(i)) if *i < animations.len() => Ok(*i),
        Some(AnimationChoice::Index(i)) => Err(bad(format!(
            "has {} {what}s; there is no {what} {i}",
            animations.len()
        ))),
        Some(AnimationChoice::Name(name)) => animations
            .iter()
            .position(|a| a.name.as_deref() == Some(name.as_str()))
            .ok_or_else(|| {
                let names: Vec<String> = animations
                    .iter()
                    .map(|a| a.name.clone().unwrap_or_else(|| format!("#{}", a.index)))
                    .collect();
                bad(format!(
                    "has no {what} named '{name}' (it has: {})",
                    names.join(", ")
                ))
            }),
    }
}
