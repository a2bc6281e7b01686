//! Poses for engines: per frame, the root position and every joint's local rotation as a
//! quaternion, without touching the file system.

use super::clip::LocalMotion;
use super::features::{FeatureLayout, FeatureMatrix, MotionError, encode_motion};
use super::math::{Vec3, mat_from_quat, quat_from_mat};
use super::skeleton::Skeleton;

/// A unit quaternion with named components (`w` the scalar part), laid out `x, y, z, w` in
/// memory as engines (Unity, Unreal, glTF) store it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    /// `x` of the vector part.
    pub x: f32,
    /// `y` of the vector part.
    pub y: f32,
    /// `z` of the vector part.
    pub z: f32,
    /// The scalar part.
    pub w: f32,
}

/// One frame of a skeleton pose, in the clip's units and its file's right-handed frame (its up axis is
/// [`super::FeatureLayout::up`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Local rotation of every joint relative to its parent.
    pub rotations: Vec<Quaternion>,
    /// Local translation of every joint from its parent (the OFFSET, or the animated position
    /// where a joint has position channels); the root joint's is its world position.
    pub translations: Vec<[f32; 3]>,
}

impl Pose {
    /// World position of the root joint: its translation. A model's skeleton has its root first
    /// (model files are checked for it), so this is `translations[0]`; zeros for an empty pose.
    pub fn root_position(&self) -> [f32; 3] {
        self.translations.first().copied().unwrap_or([0.0; 3])
    }
}

/// One [`Pose`] per frame.
pub fn poses(motion: &LocalMotion) -> Vec<Pose> {
    let joints = motion.skeleton.len();
    let narrow = |v: Vec3| v.0.map(|c| c as f32);
    (0..motion.frame_count())
        .map(|f| {
            let range = f * joints..(f + 1) * joints;
            Pose {
                rotations: motion.rotations[range.clone()]
                    .iter()
                    .map(|m| {
                        let [x, y, z, w] = quat_from_mat(m);
                        Quaternion {
                            x: x as f32,
                            y: y as f32,
                            z: z as f32,
                            w: w as f32,
                        }
                    })
                    .collect(),
                translations: motion.translations[range]
                    .iter()
                    .map(|&t| narrow(t))
                    .collect(),
            }
        })
        .collect()
}

/// The inverse of [`poses`]: engine poses of `skeleton` at `fps` as a motion, to give a model as
/// a reference or content (poses in, the same layout the runtime returns). Quaternions are
/// normalised; the root joint's translation is its world position. Poses whose joint
/// counts differ from the skeleton's, zero quaternions and non-finite numbers are refused,
/// naming the frame.
pub fn motion_from_poses(
    skeleton: &Skeleton,
    fps: f64,
    poses: &[Pose],
) -> Result<LocalMotion, MotionError> {
    if poses.is_empty() {
        return Err(MotionError::NoPoses);
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(MotionError::BadFrameRate(fps));
    }
    let joints = skeleton.len();
    let mut rotations = Vec::with_capacity(poses.len() * joints);
    let mut translations = Vec::with_capacity(poses.len() * joints);
    let wide = |v: [f32; 3]| Vec3(v.map(f64::from));
    for (frame, pose) in poses.iter().enumerate() {
        let bad = |problem: String| MotionError::BadPose { frame, problem };
        if pose.rotations.len() != joints || pose.translations.len() != joints {
            return Err(bad(format!(
                "{} rotations and {} translations for a skeleton of {joints} joints",
                pose.rotations.len(),
                pose.translations.len()
            )));
        }
        for (j, q) in pose.rotations.iter().enumerate() {
            let q = [q.x, q.y, q.z, q.w].map(f64::from);
            // Summed scalar first, so lengths round as they always have.
            let length = (q[3] * q[3] + q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            if !(length.is_finite() && length > 1e-6) {
                return Err(bad(format!(
                    "joint {j} ('{}') has a rotation that is not a unit quaternion ({q:?}, x y z w)",
                    skeleton.joints[j].name
                )));
            }
            rotations.push(mat_from_quat(q.map(|v| v / length)));
        }
        for (j, t) in pose.translations.iter().enumerate() {
            if !t.iter().all(|v| v.is_finite()) {
                return Err(bad(format!(
                    "joint {j} ('{}') has a translation that is not finite",
                    skeleton.joints[j].name
                )));
            }
            translations.push(wide(*t));
        }
    }
    Ok(LocalMotion {
        skeleton: skeleton.clone(),
        fps,
        rotations,
        translations,
    })
}

/// Engine poses of a model's skeleton as raw features in its `layout`: a reference or content for
/// in-betweening, expansion, composition or harmonization, given as poses instead of a file.
/// The poses are at the layout's frame rate, in its file's frame and units.
pub fn features_from_poses(
    layout: &FeatureLayout,
    poses: &[Pose],
) -> Result<FeatureMatrix, MotionError> {
    let motion = motion_from_poses(&layout.skeleton, layout.fps, poses)?;
    Ok(encode_motion(layout, &motion))
}
