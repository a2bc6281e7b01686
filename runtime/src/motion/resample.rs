//! Changing a clip's frame rate: linear interpolation for translations, slerp for rotations.

use super::clip::LocalMotion;
use super::math::{self, Mat3};

/// Number of frames a clip of `frames` frames at `from_fps` has at `to_fps` over the same span.
pub fn resampled_frame_count(frames: usize, from_fps: f64, to_fps: f64) -> usize {
    if frames <= 1 {
        return frames;
    }
    let span = (frames - 1) as f64 / from_fps;
    (span * to_fps + 1e-9).floor() as usize + 1
}

/// The clip at `to_fps`: frame `m` is the source sampled at time `m / to_fps`. Returns a copy
/// when the rates already agree.
pub fn resample(motion: &LocalMotion, to_fps: f64) -> LocalMotion {
    let frames = motion.frame_count();
    if (motion.fps - to_fps).abs() < 1e-9 || frames <= 1 {
        let mut same = motion.clone();
        same.fps = to_fps;
        return same;
    }
    let joints = motion.skeleton.len();
    let out_frames = resampled_frame_count(frames, motion.fps, to_fps);
    let mut rotations: Vec<Mat3> = Vec::with_capacity(out_frames * joints);
    let mut translations = Vec::with_capacity(out_frames * joints);
    for m in 0..out_frames {
        let source = (m as f64 * motion.fps / to_fps).min((frames - 1) as f64);
        let lo = (source.floor() as usize).min(frames - 1);
        let hi = (lo + 1).min(frames - 1);
        let w = source - lo as f64;
        for j in 0..joints {
            let (a, b) = (lo * joints + j, hi * joints + j);
            let ta = motion.translations[a];
            let tb = motion.translations[b];
            translations.push((ta * (1.0 - w)) + (tb * w));
            rotations.push(if w == 0.0 {
                motion.rotations[a]
            } else {
                let qa = math::quat_from_mat(&motion.rotations[a]);
                let qb = math::quat_from_mat(&motion.rotations[b]);
                math::mat_from_quat(math::slerp(qa, qb, w))
            });
        }
    }
    LocalMotion {
        skeleton: motion.skeleton.clone(),
        fps: to_fps,
        rotations,
        translations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math::{IDENTITY, Vec3, axis_rotation, mat_max_abs_diff};
    use crate::motion::skeleton::{Axis, Channel, Joint, Skeleton};

    fn single_joint(frames: usize, fps: f64, velocity: Vec3, spin: f64) -> LocalMotion {
        let skeleton = Skeleton {
            joints: vec![Joint {
                name: "root".into(),
                parent: None,
                offset: Vec3::ZERO,
                channels: vec![
                    Channel::Position(Axis::X),
                    Channel::Position(Axis::Y),
                    Channel::Position(Axis::Z),
                    Channel::Rotation(Axis::Y),
                ],
                end_site: None,
            }],
        };
        let translations = (0..frames).map(|f| velocity * (f as f64 / fps)).collect();
        let rotations = (0..frames)
            .map(|f| axis_rotation(1, spin * f as f64 / fps))
            .collect();
        LocalMotion {
            skeleton,
            fps,
            rotations,
            translations,
        }
    }

    #[test]
    fn constant_velocity_root_stays_on_its_line_at_the_new_rate() {
        // 120 fps for 2 s (241 frames) moving at (3, 0, -1.5) units/s and turning 0.5 rad/s.
        let source = single_joint(241, 120.0, Vec3::new(3.0, 0.0, -1.5), 0.5);
        let out = resample(&source, 30.0);
        assert_eq!(out.frame_count(), 61);
        assert_eq!(out.fps, 30.0);
        for m in 0..61 {
            let t = m as f64 / 30.0;
            let want = [3.0 * t, 0.0, -1.5 * t];
            assert!((out.translations[m] - Vec3(want)).norm() < 1e-12);
            assert!(mat_max_abs_diff(&out.rotations[m], &axis_rotation(1, 0.5 * t)) < 1e-12);
        }
    }

    #[test]
    fn upsampling_interpolates_between_frames() {
        // 24 -> 30 fps: frame 1 at t = 1/30 lies 0.8 of the way from source frame 0 to 1.
        let source = single_joint(25, 24.0, Vec3::new(2.4, 0.0, 0.0), 2.4);
        let out = resample(&source, 30.0);
        assert_eq!(out.frame_count(), 31);
        assert!((out.translations[1][0] - 2.4 / 30.0).abs() < 1e-12);
        assert!(mat_max_abs_diff(&out.rotations[1], &axis_rotation(1, 2.4 / 30.0)) < 1e-12);
    }

    #[test]
    fn same_rate_is_a_copy() {
        let source = single_joint(10, 30.0, Vec3::new(1.0, 0.0, 0.0), 0.0);
        assert_eq!(resample(&source, 30.0), source);
        assert_eq!(source.rotations[3], IDENTITY);
    }
}
