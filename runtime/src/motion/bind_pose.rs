//! A converter's bind pose (a T-pose) left in a clip's first frame, found and dropped: BVH
//! releases of the CMU database, among others, put one before the captured motion, and a model
//! trained on it learns a jump into a T-pose as part of the motion.

use std::borrow::Cow;

use super::clip::{ChannelClip, LocalMotion};
use super::math::Mat3;

/// The least typical turn of the joints into the second frame, in degrees, for the first frame
/// to be a bind pose: captured motion does not turn the whole body this far in one frame.
pub const BIND_POSE_MIN_DEGREES: f64 = 10.0;

/// How many times the largest typical turn between two later frames the first frame's must be:
/// a clip whose motion is fast everywhere keeps its first frame.
pub const BIND_POSE_RATIO: f64 = 4.0;

/// The share of the joints, those that turn most, left out of a frame's typical turn, so that a
/// few joints' noise (CMU's thumbs flip by 180 degrees between two frames) neither makes nor
/// hides a bind pose.
pub const NOISY_JOINT_SHARE: f64 = 0.1;

/// A first frame that is not part of the motion, and the evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct LeadingBindPose {
    /// The joint that turns most from the first frame into the second.
    pub joint: String,
    /// The joints' typical turn ([`typical_turn`]) from the first frame into the second, in
    /// degrees.
    pub jump_degrees: f64,
    /// The largest typical turn between two later frames, in degrees.
    pub largest_later_degrees: f64,
}

impl LeadingBindPose {
    /// One line for a person: what was dropped and why.
    pub fn describe(&self) -> String {
        format!(
            "the first frame, a bind pose: the joints turn {:.0} degrees, typically, into the \
             second frame (the most, {}), {:.0} times as far as between any two later frames \
             ({:.1} degrees)",
            self.jump_degrees,
            self.joint,
            self.jump_degrees / self.largest_later_degrees.max(f64::MIN_POSITIVE),
            self.largest_later_degrees
        )
    }
}

/// The angle of the rotation that takes `a` to `b`, in degrees.
fn turn_degrees(a: &Mat3, b: &Mat3) -> f64 {
    let mut trace = 0.0;
    for r in 0..3 {
        for c in 0..3 {
            trace += a.0[r][c] * b.0[r][c];
        }
    }
    ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Each joint's turn from frame `f` to the next, in degrees.
fn turns(motion: &LocalMotion, f: usize) -> Vec<f64> {
    let joints = motion.skeleton.len();
    let (a, b) = (
        &motion.rotations[f * joints..(f + 1) * joints],
        &motion.rotations[(f + 1) * joints..(f + 2) * joints],
    );
    a.iter().zip(b).map(|(x, y)| turn_degrees(x, y)).collect()
}

/// The mean turn of the joints, leaving out the [`NOISY_JOINT_SHARE`] that turn most (at least
/// one where there are two or more) and any that is not finite; 0 for none.
pub fn typical_turn(turns: &[f64]) -> f64 {
    let mut finite: Vec<f64> = turns.iter().copied().filter(|t| t.is_finite()).collect();
    finite.sort_by(f64::total_cmp);
    let noisy = if finite.len() >= 2 {
        ((finite.len() as f64 * NOISY_JOINT_SHARE).ceil() as usize).max(1)
    } else {
        0
    };
    let kept = &finite[..finite.len() - noisy];
    if kept.is_empty() {
        0.0
    } else {
        kept.iter().sum::<f64>() / kept.len() as f64
    }
}

/// The first frame of `motion` when it is a bind pose: the joints' typical turn into the second
/// frame is at least [`BIND_POSE_MIN_DEGREES`], and at least [`BIND_POSE_RATIO`] times the
/// largest between any two later frames. A clip of fewer than four frames is left
/// alone.
pub fn leading_bind_pose(motion: &LocalMotion) -> Option<LeadingBindPose> {
    let frames = motion.frame_count();
    if motion.skeleton.is_empty() || frames < 4 {
        return None;
    }
    let first = turns(motion, 0);
    let jump = typical_turn(&first);
    if jump < BIND_POSE_MIN_DEGREES {
        return None;
    }
    let later = (1..frames - 1)
        .map(|f| typical_turn(&turns(motion, f)))
        .fold(0.0f64, f64::max);
    let most = first
        .iter()
        .enumerate()
        .filter(|(_, t)| t.is_finite())
        .fold((0, f64::NEG_INFINITY), |best, (j, &t)| {
            if t > best.1 { (j, t) } else { best }
        })
        .0;
    (jump >= BIND_POSE_RATIO * later).then(|| LeadingBindPose {
        joint: motion.skeleton.joints[most].name.clone(),
        jump_degrees: jump,
        largest_later_degrees: later,
    })
}

/// A clip ready to encode: its channels and its local motion (computed once, for the search and
/// for the encoder), without the first frame when that frame is a bind pose.
pub struct PastBindPose<'a> {
    /// The channels, trimmed where a bind pose was found.
    pub clip: Cow<'a, ChannelClip>,
    /// The same frames as local transforms.
    pub local: LocalMotion,
    /// What was left out ([`leading_bind_pose`]); `None` when every frame is kept.
    pub bind_pose: Option<LeadingBindPose>,
}

/// `clip` and its local motion, the first frame left out when it is a bind pose
/// ([`leading_bind_pose`]).
pub fn past_bind_pose(clip: &ChannelClip) -> PastBindPose<'_> {
    let mut local = clip.to_local();
    let Some(found) = leading_bind_pose(&local) else {
        return PastBindPose {
            clip: Cow::Borrowed(clip),
            local,
            bind_pose: None,
        };
    };
    let (width, joints) = (clip.skeleton.channel_count(), clip.skeleton.len());
    local.rotations.drain(..joints);
    local.translations.drain(..joints);
    PastBindPose {
        clip: Cow::Owned(ChannelClip {
            skeleton: clip.skeleton.clone(),
            fps: clip.fps,
            values: clip.values[width..].to_vec(),
        }),
        local,
        bind_pose: Some(found),
    }
}
