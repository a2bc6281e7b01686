//! Which animation of a file is the clip, and what a reader of keyframed formats (glTF, FBX) is
//! asked beyond its defaults.

use std::path::Path;

use sinmdm::motion::ChannelClip;

use crate::error::{FormatError, Part};

/// The most frames a clip read from keyframes (glTF, FBX) may have: 14 minutes at 120 fps, far beyond a
/// training clip, and a bound on what a malformed file (keys a million seconds apart, say) can
/// make the reader allocate.
pub const MAX_CLIP_FRAMES: usize = 100_000;
/// The most joint transforms (frames x joints) a clip read from keyframes (glTF, FBX) may have: about 1 GB.
pub const MAX_JOINT_FRAMES: usize = 10_000_000;
/// The most joint transforms a clip read from keyframes may have beyond one per
/// [`BYTES_PER_SPARSE_TRANSFORM`] bytes read: sampling is a reader's costliest step, so a small
/// file whose few keys lie far apart must not make it sample for minutes (a reader's time stays
/// linear in what it reads). 100 000 covers a 55 s, 60-joint clip keyed as sparsely as an
/// animator likes.
pub const MAX_SPARSE_TRANSFORMS: usize = 100_000;
/// Beyond [`MAX_SPARSE_TRANSFORMS`], the bytes read per transform sampled: a file keyed on every
/// frame brings at least 20 (a rotation and its time) for each.
pub const BYTES_PER_SPARSE_TRANSFORM: usize = 4;

/// Checks that sampling `joints` x `frames` transforms from a file of `bytes_read` bytes stays
/// within [`MAX_JOINT_FRAMES`], and within [`MAX_SPARSE_TRANSFORMS`] or one transform per
/// [`BYTES_PER_SPARSE_TRANSFORM`] bytes, whichever is more.
pub(crate) fn check_sampled_size(
    path: &Path,
    joints: usize,
    frames: usize,
    bytes_read: usize,
) -> Result<(), FormatError> {
    let transforms = frames.saturating_mul(joints);
    if transforms > MAX_JOINT_FRAMES {
        return Err(FormatError::bad(
            path,
            Part::Skeleton,
            format!(
                "{joints} joints x {frames} frames are more transforms than the {MAX_JOINT_FRAMES} a clip may have"
            ),
        ));
    }
    if transforms > MAX_SPARSE_TRANSFORMS.max(bytes_read / BYTES_PER_SPARSE_TRANSFORM) {
        return Err(FormatError::bad(
            path,
            Part::Skeleton,
            format!(
                "{joints} joints x {frames} frames are {transforms} transforms to sample from {bytes_read} bytes of keys: more than {MAX_SPARSE_TRANSFORMS} (MAX_SPARSE_TRANSFORMS) or one per {BYTES_PER_SPARSE_TRANSFORM} bytes; are the key times right? A lower frame rate (--fps) samples fewer"
            ),
        ));
    }
    Ok(())
}

/// A clip moves when some channel's standard deviation over its frames is above this (degrees
/// for rotations, file units for positions): far below any motion a person could see, far above
/// the rounding noise of an exporter's still take (Mixamo's `Take 001`: 4e-16).
pub const STILL_TOLERANCE: f64 = 1e-6;

/// Whether some channel of `clip` moves (its standard deviation is above [`STILL_TOLERANCE`]).
pub fn clip_moves(clip: &ChannelClip) -> bool {
    let width = clip.skeleton.channel_count();
    let frames = clip.frame_count();
    if width == 0 || frames < 2 {
        return false;
    }
    (0..width).any(|c| {
        let column = || clip.values.iter().skip(c).step_by(width);
        let mean = column().sum::<f64>() / frames as f64;
        let variance = column().map(|v| (v - mean).powi(2)).sum::<f64>() / frames as f64;
        variance.sqrt() > STILL_TOLERANCE
    })
}

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
    /// The animation to read (default: the first that moves, else the first).
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
    /// Whether nothing in it moves (no channel's standard deviation above [`STILL_TOLERANCE`]);
    /// `None` where it could not be sampled.
    pub still: Option<bool>,
}

impl AnimationInfo {
    /// `'Walk' (#0)` or `#0`, as messages name it.
    pub fn describe(&self) -> String {
        match &self.name {
            Some(name) => format!("'{name}' (#{})", self.index),
            None => format!("#{}", self.index),
        }
    }
}

/// The animation `options` ask for, or by default the first that moves (the first of all when
/// none does), sampled by `sample`; every animation's `still` is filled in on the way. A file
/// such as a Mixamo download holds a still `Take 001` before its motion, and the default is the
/// motion.
pub(crate) fn choose_and_sample(
    path: &Path,
    animations: &mut [AnimationInfo],
    options: &ReadOptions,
    (part, what): (Part, &str),
    mut sample: impl FnMut(usize) -> Result<ChannelClip, FormatError>,
) -> Result<(usize, ChannelClip), FormatError> {
    let asked = match options.animation {
        Some(_) => Some(choose_animation(path, animations, options, (part, what))?),
        None => {
            choose_animation(path, animations, options, (part, what))?;
            None
        }
    };
    // The asked one's result, or by default the first's and the first moving one's.
    let mut first = None;
    let mut chosen = None;
    for (index, animation) in animations.iter_mut().enumerate() {
        let result = sample(index);
        animation.still = result.as_ref().ok().map(|clip| !clip_moves(clip));
        match asked {
            Some(a) if a == index => chosen = Some((index, result)),
            Some(_) => {}
            None if index == 0 => first = Some(result),
            None => {
                if chosen.is_none() && animation.still == Some(false) {
                    chosen = Some((index, result));
                }
            }
        }
    }
    if asked.is_none() && animations[0].still == Some(false) {
        chosen = first.take().map(|r| (0, r));
    }
    let (index, result) = chosen
        .or_else(|| first.map(|r| (0, r)))
        .expect("a file with animations has a chosen one");
    Ok((index, result?))
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
