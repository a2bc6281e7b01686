//! Poses for engines: per frame, the root position and every joint's local rotation as a
//! quaternion, without touching the file system.

use super::clip::LocalMotion;
use super::math::quat_wxyz_from_mat;

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
    /// World position of the root joint.
    pub root_position: [f32; 3],
    /// Local rotation of every joint relative to its parent.
    pub rotations: Vec<Quaternion>,
    /// Local translation of every joint from its parent (the OFFSET, or the animated position
    /// where a joint has position channels).
    pub translations: Vec<[f32; 3]>,
}

/// One [`Pose`] per frame.
pub fn poses(motion: &LocalMotion) -> Vec<Pose> {
    let joints = motion.skeleton.len();
    let narrow = |v: [f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32];
    (0..motion.frame_count())
        .map(|f| {
            let range = f * joints..(f + 1) * joints;
            Pose {
                root_position: narrow(motion.translations[f * joints]),
                rotations: motion.rotations[range.clone()]
                    .iter()
                    .map(|m| {
                        let [w, x, y, z] = quat_wxyz_from_mat(m);
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
