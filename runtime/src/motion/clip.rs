//! A clip as a file stores it (channel values per frame) and as the math needs it (local
//! rotations and translations per joint), with the conversions between the two.

use super::math::{Mat3, Vec3};
use super::rotation::{euler_to_mat, mat_to_euler, unwrap_degrees};
use super::skeleton::{Channel, Skeleton};

/// Frame rates within this relative distance of a whole number are taken as that number
/// (`Frame Time: .0083333` is 120 fps, not 120.0005).
const FPS_SNAP_TOLERANCE: f64 = 1e-3;

/// The frames per second of a BVH `Frame Time`, snapped to a whole number when it is one.
pub fn fps_from_frame_time(frame_time: f64) -> f64 {
    let fps = 1.0 / frame_time;
    let rounded = fps.round();
    if rounded >= 1.0 && ((fps - rounded) / rounded).abs() < FPS_SNAP_TOLERANCE {
        rounded
    } else {
        fps
    }
}

/// A clip in channel form: one value per channel per frame, exactly as in a BVH MOTION block.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelClip {
    /// The skeleton the channels belong to.
    pub skeleton: Skeleton,
    /// Frames per second.
    pub fps: f64,
    /// Row-major `[frames][channel_count]` values: positions in file units, rotations in degrees.
    pub values: Vec<f64>,
}

impl ChannelClip {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.values
            .len()
            .checked_div(self.skeleton.channel_count())
            .unwrap_or(0)
    }

    /// The values of one frame.
    pub fn frame(&self, index: usize) -> &[f64] {
        let width = self.skeleton.channel_count();
        &self.values[index * width..(index + 1) * width]
    }

    /// The clip as local rotations and translations.
    pub fn to_local(&self) -> LocalMotion {
        let joint_count = self.skeleton.len();
        let frames = self.frame_count();
        let starts = self.skeleton.channel_starts();
        let mut rotations = Vec::with_capacity(frames * joint_count);
        let mut translations = Vec::with_capacity(frames * joint_count);
        let mut order = Vec::with_capacity(3);
        let mut angles = Vec::with_capacity(3);
        for f in 0..frames {
            let frame = self.frame(f);
            for (j, joint) in self.skeleton.joints.iter().enumerate() {
                let mut translation = joint.offset;
                order.clear();
                angles.clear();
                for (c, channel) in joint.channels.iter().enumerate() {
                    let value = frame[starts[j] + c];
                    match channel {
                        Channel::Position(axis) => translation[axis.index()] = value,
                        Channel::Rotation(axis) => {
                            order.push(*axis);
                            angles.push(value.to_radians());
                        }
                    }
                }
                rotations.push(euler_to_mat(&order, &angles));
                translations.push(translation);
            }
        }
        LocalMotion {
            skeleton: self.skeleton.clone(),
            fps: self.fps,
            rotations,
            translations,
        }
    }
}

/// A clip as per-joint local transforms: for every frame and joint, the rotation relative to the
/// parent and the translation from the parent (the OFFSET, with any position channels replacing
/// the components they animate, as Blender and most readers do).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalMotion {
    /// The skeleton.
    pub skeleton: Skeleton,
    /// Frames per second.
    pub fps: f64,
    /// Row-major `[frames][joints]` local rotation matrices.
    pub rotations: Vec<Mat3>,
    /// Row-major `[frames][joints]` local translations (file units).
    pub translations: Vec<Vec3>,
}

impl LocalMotion {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        if self.skeleton.is_empty() {
            0
        } else {
            self.rotations.len() / self.skeleton.len()
        }
    }

    /// Back to channel values. Euler angles use each joint's own order and are unwrapped over
    /// time so every curve is continuous (no jumps at +/-180 degrees).
    pub fn to_channels(&self) -> ChannelClip {
        let joint_count = self.skeleton.len();
        let width = self.skeleton.channel_count();
        let frames = self.frame_count();
        let orders: Vec<_> = self
            .skeleton
            .joints
            .iter()
            .map(|j| j.rotation_order())
            .collect();
        let mut values = Vec::with_capacity(frames * width);
        let mut previous: Vec<Vec<f64>> = vec![Vec::new(); joint_count];
        for f in 0..frames {
            for (j, joint) in self.skeleton.joints.iter().enumerate() {
                let k = f * joint_count + j;
                let mut degrees: Vec<f64> = mat_to_euler(&orders[j], &self.rotations[k])
                    .into_iter()
                    .map(f64::to_degrees)
                    .collect();
                if f > 0 {
                    unwrap_degrees(&mut degrees, &previous[j]);
                }
                let mut next_angle = degrees.iter();
                for channel in &joint.channels {
                    values.push(match channel {
                        Channel::Position(axis) => self.translations[k][axis.index()],
                        Channel::Rotation(_) => *next_angle.next().unwrap_or(&0.0),
                    });
                }
                previous[j] = degrees;
            }
        }
        ChannelClip {
            skeleton: self.skeleton.clone(),
            fps: self.fps,
            values,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_times_snap_to_whole_frame_rates() {
        assert_eq!(fps_from_frame_time(0.0083333), 120.0);
        assert_eq!(fps_from_frame_time(0.0333333), 30.0);
        assert_eq!(fps_from_frame_time(1.0 / 24.0), 24.0);
        let odd = fps_from_frame_time(0.037);
        assert!((odd - 1.0 / 0.037).abs() < 1e-12);
    }
}
