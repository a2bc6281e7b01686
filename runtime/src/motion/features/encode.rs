//! A clip to features: resample, turn into the canonical frame, label contacts, fill columns.

use super::FeatureMatrix;
use super::error::MotionError;
use super::fill::{fill_features, root_positions};
use super::heading::{
    HEADING_MIN_TRAVEL, HEADING_SMOOTHING_SECONDS, Heading, RootLayout, SideEvidence,
    facing_angles, facing_pair, left_by_name, median_travel, root_columns,
};
use super::layout::{FeatureLayout, RootFeatures};
use crate::limits::MAX_ENCODED_FRAMES;
use crate::motion::bind_pose::{LeadingBindPose, PastBindPose, past_bind_pose};
use crate::motion::clip::{ChannelClip, LocalMotion};
use crate::motion::contacts::{ContactConfig, choose_contact_joints};
use crate::motion::fk::{global_pose, global_poses};
use crate::motion::ground::{Body, ground_level};
use crate::motion::math::{IDENTITY, Mat3, Vec3};
use crate::motion::resample::resample;
use crate::motion::skeleton::{Axis, Channel, Skeleton};
use crate::motion::up::{UP, UpAxis, to_canonical};
use crate::motion::up_detect::{UpDetection, choose_up};

/// How a clip becomes features.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodeOptions {
    /// Target frame rate; `None` keeps the clip's own.
    pub fps: Option<f64>,
    /// Contact joints and threshold.
    pub contacts: ContactConfig,
    /// The clip's up axis; `None` detects it from the motion ([`crate::motion::up_detect::detect_up`]).
    pub up: Option<UpAxis>,
    /// How the root is described ([`super::heading`]).
    pub root: RootLayout,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            fps: Some(30.0),
            contacts: ContactConfig::default(),
            up: None,
            root: RootLayout::World,
        }
    }
}

/// A clip turned into features.
#[derive(Debug, Clone)]
pub struct EncodedClip {
    /// The column description (with the skeleton and static data).
    pub layout: FeatureLayout,
    /// Unnormalised features `[F, N]`.
    pub features: FeatureMatrix,
    /// Share of frames in contact for each contact joint.
    pub contact_share: Vec<f64>,
    /// The up-axis detection and its evidence (`None` when the axis was given).
    pub up_detection: Option<UpDetection>,
    /// The clip is an in-place cycle (its root does not travel) and its contacts were labelled
    /// relative to the treadmill.
    pub in_place: bool,
    /// Why [`RootLayout::Auto`] chose the world root (the clip lacks what the heading-relative
    /// root needs); `None` when it chose the heading root or the layout was asked for.
    pub world_root_reason: Option<String>,
    /// The root layout the options asked for ([`RootLayout::Auto`] where the clip chose), so
    /// that a description of the root can say who chose it.
    pub root_asked: RootLayout,
    /// The clip's first frame, dropped as a converter's bind pose
    /// ([`crate::motion::bind_pose::leading_bind_pose`]); `None` when every frame was kept.
    pub bind_pose: Option<LeadingBindPose>,
}

/// Relative change under which a channel counts as constant.
const CONSTANT_TOLERANCE: f64 = 1e-9;

/// Whether each channel of the clip (in channel order) changes over the clip.
fn varying_channels(clip: &ChannelClip) -> Vec<bool> {
    let width = clip.skeleton.channel_count();
    let first = clip.frame(0);
    let mut varies = vec![false; width];
    for f in 1..clip.frame_count() {
        for (c, (&v, &v0)) in clip.frame(f).iter().zip(first).enumerate() {
            if (v - v0).abs() > CONSTANT_TOLERANCE * (1.0 + v0.abs()) {
                varies[c] = true;
            }
        }
    }
    varies
}

/// The joint that carries the clip's travel: the root, or, while a joint has no varying position
/// channel and exactly one child that has one, that child.
fn motion_root(skeleton: &Skeleton, varying_position: &[bool]) -> usize {
    let mut joint = 0;
    loop {
        if varying_position[joint] {
            return joint;
        }
        match skeleton.children(joint).as_slice() {
            [only] if varying_position[*only] => joint = *only,
            _ => return joint,
        }
    }
}

/// Refuses a resampling to `fps` that would make more than [`MAX_ENCODED_FRAMES`] frames.
fn check_resampled_length(clip: &ChannelClip, fps: f64) -> Result<(), MotionError> {
    let resampled = (clip.frame_count() as f64 - 1.0) * fps / clip.fps + 1.0;
    if resampled.is_nan() || resampled > MAX_ENCODED_FRAMES as f64 {
        return Err(MotionError::TooManyFrames {
            frames: clip.frame_count(),
            from_fps: clip.fps,
            to_fps: fps,
            limit: MAX_ENCODED_FRAMES,
        });
    }
    Ok(())
}

/// Turns a clip into features: resampled to `options.fps`, root displacement and height, 6D
/// rotations, varying positions and contact labels; a first frame that is a converter's bind
/// pose is dropped first ([`EncodedClip::bind_pose`]).
pub fn encode(clip: &ChannelClip, options: &EncodeOptions) -> Result<EncodedClip, MotionError> {
    let PastBindPose {
        clip,
        local: file_local,
        bind_pose,
    } = past_bind_pose(clip);
    let clip = clip.as_ref();
    let fps = checked_fps(clip, options)?;
    let skeleton = &clip.skeleton;
    let varies = varying_channels(clip);
    let starts = skeleton.channel_starts();
    let position_varies = |j: usize, axis: Axis| {
        skeleton.joints[j]
            .channels
            .iter()
            .position(|c| *c == Channel::Position(axis))
            .is_some_and(|c| varies[starts[j] + c])
    };
    let any_position_varies: Vec<bool> = (0..skeleton.len())
        .map(|j| {
            [Axis::X, Axis::Y, Axis::Z]
                .iter()
                .any(|&a| position_varies(j, a))
        })
        .collect();
    let root_joint = motion_root(skeleton, &any_position_varies);

    let (up, up_detection) = choose_up(&file_local, options.up);
    let canonical_from_file = up.canonical_from_file();
    let local = to_canonical(&resample(&file_local, fps), up);
    let joints = skeleton.len();

    let rest_translations = rest_translations(clip, &starts, canonical_from_file);
    let frame = container_frame(skeleton, root_joint, &local);
    let root = root_features(skeleton, root_joint, canonical_from_file, frame, &local);
    let rotation_joints: Vec<usize> = (0..joints)
        .filter(|&j| skeleton.joints[j].rotates())
        .collect();
    let position_channels: Vec<(usize, Axis)> = (0..joints)
        .filter(|&j| j != root_joint || root.is_none())
        .flat_map(|j| {
            [Axis::X, Axis::Y, Axis::Z]
                .into_iter()
                .filter(move |&a| position_varies(j, a))
                .map(move |a| (j, a))
        })
        .collect();

    let poses = global_poses(&local);
    let height = Body::carried_by(skeleton, root_joint).height(&poses);
    let contact_joints = contact_joints(skeleton, &options.contacts, &poses, height)?;

    let layout = FeatureLayout {
        skeleton: skeleton.clone(),
        fps,
        root,
        rotation_joints,
        position_channels,
        contact_joints,
        rest_translations,
        contact_speed_threshold: options.contacts.speed_threshold,
        skeleton_height: height,
        up,
        ground: None,
    };
    let mut layout = FeatureLayout {
        ground: Some(ground_level(&layout.contact_joints, &layout.body(), &poses)),
        ..layout
    };
    let (heading, world_root_reason) = root_heading(options.root, &layout, &local, &poses)?;
    if let Some(heading) = heading
        && let Some(root) = layout.root.as_mut()
    {
        root.axes = vec![Axis::X, Axis::Y, Axis::Z];
        root.heading = Some(heading);
    }

    let filled = fill_features(&layout, &local, &poses);
    Ok(EncodedClip {
        layout,
        features: filled.features,
        contact_share: filled.contact_share,
        up_detection,
        in_place: filled.in_place,
        world_root_reason,
        root_asked: options.root,
        bind_pose,
    })
}

/// The frame rate to encode at, after checking the options against the clip.
fn checked_fps(clip: &ChannelClip, options: &EncodeOptions) -> Result<f64, MotionError> {
    if clip.frame_count() == 0 {
        return Err(MotionError::NoFrames);
    }
    let fps = options.fps.unwrap_or(clip.fps);
    if !(fps.is_finite() && fps > 0.0) {
        return Err(MotionError::BadFrameRate(fps));
    }
    for (what, value) in [
        ("speed threshold", options.contacts.speed_threshold),
        ("ground fraction", options.contacts.ground_fraction),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(MotionError::BadContactSetting { what, value });
        }
    }
    check_resampled_length(clip, fps)?;
    Ok(fps)
}

/// Each joint's translation in the clip's first frame: its offset, with the position channels
/// it has; a top joint's turned to the canonical frame.
fn rest_translations(clip: &ChannelClip, starts: &[usize], canonical_from_file: Mat3) -> Vec<Vec3> {
    let skeleton = &clip.skeleton;
    let first = clip.frame(0);
    skeleton
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let mut translation = joint.offset;
            for (c, channel) in joint.channels.iter().enumerate() {
                if let Channel::Position(axis) = channel {
                    translation[axis.index()] = first[starts[j] + c];
                }
            }
            if joint.parent.is_none() {
                translation = canonical_from_file * translation;
            }
            translation
        })
        .collect()
}

/// The canonical frame of the motion root's container (at frame 0: the container is static);
/// the identity for a top joint.
fn container_frame(skeleton: &Skeleton, root_joint: usize, local: &LocalMotion) -> Mat3 {
    // A motion root below the top joint sits in its container's frame; take that frame (at
    // frame 0: the container is static) to the canonical one.
    // Entries within 1e-9 of 0 or +-1 are snapped, so a container turned by a quarter turn
    // written as text (cos 90 = 6e-17) gives an exact axis permutation.
    match skeleton.joints[root_joint].parent {
        Some(parent) => {
            let frame = global_pose(local, 0).rotations[parent];
            Mat3::from_fn(|r, c| {
                let v = frame[r][c];
                if (v - v.round()).abs() < 1e-9 {
                    v.round() + 0.0
                } else {
                    v
                }
            })
        }
        None => IDENTITY,
    }
}

/// The root's features: the canonical axes its position channels move along, its start and
/// frame; none for a root without position channels.
fn root_features(
    skeleton: &Skeleton,
    root_joint: usize,
    canonical_from_file: Mat3,
    frame: Mat3,
    local: &LocalMotion,
) -> Option<RootFeatures> {
    let to_canonical_axes = if root_joint == 0 {
        canonical_from_file
    } else {
        frame
    };
    let mut root_axes: Vec<usize> = skeleton.joints[root_joint]
        .position_axes()
        .iter()
        .map(|a| {
            let column = [0, 1, 2].map(|i| to_canonical_axes[i][a.index()].abs());
            (0..3)
                .max_by(|&x, &y| column[x].total_cmp(&column[y]))
                .unwrap_or(a.index())
        })
        .collect();
    root_axes.sort_unstable();
    root_axes.dedup();
    (!root_axes.is_empty()).then(|| RootFeatures {
        joint: root_joint,
        axes: root_axes.into_iter().map(Axis::from_index).collect(),
        start_position: (frame * local.translations[root_joint]),
        frame,
        heading: None,
    })
}

/// The contact joints: the ones named in the options, or chosen from the poses.
fn contact_joints(
    skeleton: &Skeleton,
    contacts: &ContactConfig,
    poses: &[crate::motion::fk::GlobalPose],
    height: f64,
) -> Result<Vec<usize>, MotionError> {
    Ok(match &contacts.joints {
        Some(names) => names
            .iter()
            .map(|name| {
                skeleton
                    .find(name)
                    .ok_or_else(|| MotionError::UnknownContactJoint {
                        name: name.clone(),
                        available: skeleton
                            .joints
                            .iter()
                            .map(|j| j.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", "),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?,
        None => choose_contact_joints(skeleton, poses, height, contacts.ground_fraction),
    })
}

/// The heading-relative root's facts when the root layout asks for one (for `Auto`, a clip
/// whose root travels), or why the root stays in world axes.
fn root_heading(
    root_layout: RootLayout,
    layout: &FeatureLayout,
    local: &LocalMotion,
    poses: &[crate::motion::fk::GlobalPose],
) -> Result<(Option<Heading>, Option<String>), MotionError> {
    let mut world_root_reason = None;
    let heading = match root_layout {
        RootLayout::World => None,
        RootLayout::Heading => Some(choose_heading(layout, local, poses)?),
        RootLayout::Auto => {
            let travel = layout.root.as_ref().map_or(0.0, |r| {
                median_travel(poses, r.joint, layout.fps, layout.skeleton_height)
            });
            if travel < HEADING_MIN_TRAVEL {
                world_root_reason = Some(format!(
                    "its root travels {travel:.2} heights/s (the median over 1-second windows), \
                     under the {HEADING_MIN_TRAVEL} of locomotion, so there is nothing to steer"
                ));
                None
            } else {
                match choose_heading(layout, local, poses) {
                    Ok(heading) => Some(heading),
                    Err(MotionError::Heading(why)) => {
                        world_root_reason = Some(why);
                        None
                    }
                    Err(e) => return Err(e),
                }
            }
        }
    };
    Ok((heading, world_root_reason))
}

/// The heading-relative root's facts for a clip (see [`super::heading`]), or why it has none.
fn choose_heading(
    layout: &FeatureLayout,
    local: &LocalMotion,
    poses: &[crate::motion::fk::GlobalPose],
) -> Result<Heading, MotionError> {
    let skeleton = &layout.skeleton;
    let root = layout.root.as_ref().ok_or_else(|| {
        MotionError::Heading("its root has no position channels, so it never travels".into())
    })?;
    let name = |j: usize| skeleton.joints[j].name.as_str();
    let ground = [Axis::X, Axis::Z];
    if !ground.iter().all(|a| root.axes.contains(a)) {
        return Err(MotionError::Heading(format!(
            "its root '{}' does not move on both ground axes",
            name(root.joint)
        )));
    }
    if !skeleton.joints[root.joint].rotates() {
        return Err(MotionError::Heading(format!(
            "its root '{}' has no rotation channels to turn with the facing",
            name(root.joint)
        )));
    }
    let (a, b) =
        facing_pair(skeleton, root.joint, &poses[0], layout.skeleton_height).ok_or_else(|| {
            MotionError::Heading(
                "no left/right pair of joints (hips or shoulders) gives it a facing".into(),
            )
        })?;
    let sigma = HEADING_SMOOTHING_SECONDS * layout.fps;
    let (left, right, sides) = match left_by_name(name(a), name(b)) {
        Some(true) => (a, b, SideEvidence::Names),
        Some(false) => (b, a, SideEvidence::Names),
        None => {
            // The side that makes the clip travel forward is the left one.
            let headings = facing_angles(poses, a, b, sigma);
            let positions = root_positions(root, local);
            let [forward, _, _, _] = root_columns(&positions, &headings);
            let along: f64 = forward.iter().sum();
            let travel: f64 = positions
                .windows(2)
                .map(|w| {
                    let mut d = w[1] - w[0];
                    d[UP] = 0.0;
                    d.norm()
                })
                .sum();
            if along.abs() < 0.1 * travel || travel < 0.05 * layout.skeleton_height {
                (a, b, SideEvidence::Unresolved)
            } else if along > 0.0 {
                (a, b, SideEvidence::Travel)
            } else {
                (b, a, SideEvidence::Travel)
            }
        }
    };
    let start = facing_angles(poses, left, right, sigma)
        .first()
        .copied()
        .unwrap_or(0.0);
    Ok(Heading {
        left,
        right,
        sides,
        smoothing: HEADING_SMOOTHING_SECONDS,
        start,
    })
}

/// Encodes a clip of the same skeleton in an existing layout (a model's): resampled to the
/// layout's frame rate, read with the layout's up axis, with the layout's columns, contact joints
/// and contact threshold, so the result lines up with the features the model was trained on; a
/// first frame that is a bind pose is left out, as [`encode`] leaves it out of a training clip.
pub fn encode_for(
    clip: &ChannelClip,
    layout: &FeatureLayout,
) -> Result<FeatureMatrix, MotionError> {
    if clip.frame_count() == 0 {
        return Err(MotionError::NoFrames);
    }
    let trimmed = past_bind_pose(clip);
    if let Some(problem) = layout.skeleton.difference(&trimmed.clip.skeleton) {
        return Err(MotionError::SkeletonMismatch(problem));
    }
    check_resampled_length(&trimmed.clip, layout.fps)?;
    let local = to_canonical(&resample(&trimmed.local, layout.fps), layout.up);
    let poses = global_poses(&local);
    Ok(fill_features(layout, &local, &poses).features)
}

/// Encodes a motion already in a layout's skeleton and frame rate (a decoded or planted
/// sample, in the file's frame) with the layout's columns; contact labels are measured from
/// its own feet, as for a clip.
pub fn encode_motion(layout: &FeatureLayout, motion: &LocalMotion) -> FeatureMatrix {
    let local = to_canonical(motion, layout.up);
    let poses = global_poses(&local);
    fill_features(layout, &local, &poses).features
}
