//! From a model's frame to Bevy's: a model's poses are in its clip file's axes and units (any
//! up axis, centimetres or metres or CMU units), Bevy's world is +Y up and in metres.
//!
//! Only the top joint changes: its translation is turned and scaled, its rotation turned; every
//! other joint is relative to its parent, so its rotation is kept and its translation scaled.

use bevy_math::{Mat3, Quat, Vec3};
use bevy_transform::components::Transform;
use sinmdm::motion::units::UnitGuess;
use sinmdm::{ModelMetadata, Pose, Quaternion};

/// How a model's poses are placed in Bevy's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineFrame {
    /// The turn from the file's axes to Bevy's (+Y up).
    pub turn: Quat,
    /// Metres per file unit.
    pub metres_per_unit: f32,
}

impl EngineFrame {
    /// The frame of a model: its up axis from the model file, its unit guessed from the
    /// figure's height (as the glTF writer does) unless `metres_per_unit` says it (which must
    /// then be a positive number).
    pub fn of(
        metadata: &ModelMetadata,
        metres_per_unit: Option<f64>,
    ) -> Result<EngineFrame, String> {
        let layout = &metadata.layout;
        let m = layout.up.canonical_from_file();
        let columns = m.transpose().0.map(|c| c.map(|v| v as f32));
        let turn = Quat::from_mat3(&Mat3::from_cols_array_2d(&columns)).normalize();
        let metres = match metres_per_unit {
            Some(m) if m.is_finite() && m > 0.0 => m,
            Some(m) => {
                return Err(format!(
                    "metres_per_unit must be a positive number of metres per file unit, got {m}"
                ));
            }
            None => UnitGuess::from_height(layout.skeleton_height).metres_per_unit(),
        };
        Ok(EngineFrame {
            turn,
            metres_per_unit: metres as f32,
        })
    }

    /// The local transform of joint `joint` of `pose` in Bevy's frame (`top` when the joint is
    /// the skeleton's top joint, whose transform is in the file's world frame).
    pub fn joint_transform(&self, pose: &Pose, joint: usize, top: bool) -> Transform {
        let t = Vec3::from_array(pose.translations[joint]) * self.metres_per_unit;
        let q = quat(pose.rotations[joint]);
        if top {
            Transform::from_translation(self.turn * t).with_rotation(self.turn * q)
        } else {
            Transform::from_translation(t).with_rotation(q)
        }
    }

    /// Writes `pose` into the transforms of `joints` (the skeleton's joint entities, their
    /// `parents` as the skeleton has them).
    pub(crate) fn write_pose<F: bevy_ecs::query::QueryFilter>(
        &self,
        pose: &Pose,
        joints: &[bevy_ecs::entity::Entity],
        parents: &[Option<usize>],
        transforms: &mut bevy_ecs::system::Query<&mut Transform, F>,
    ) {
        for (j, &entity) in joints.iter().enumerate() {
            if let Ok(mut t) = transforms.get_mut(entity) {
                *t = self.joint_transform(pose, j, parents[j].is_none());
            }
        }
    }

    /// A length in metres as file units.
    pub fn to_file_units(&self, metres: f32) -> f64 {
        f64::from(metres) / f64::from(self.metres_per_unit)
    }

    /// A length in file units as metres.
    pub fn to_metres(&self, units: f64) -> f32 {
        (units * f64::from(self.metres_per_unit)) as f32
    }
}

/// A runtime quaternion as Bevy's.
pub fn quat(q: Quaternion) -> Quat {
    Quat::from_xyzw(q.x, q.y, q.z, q.w)
}

/// The pose a fraction `t` (0..1) of the way from `a` to `b`: rotations by spherical
/// interpolation along the shorter arc, translations linearly. `t == 0` gives `a` exactly.
pub fn interpolate(a: &Pose, b: &Pose, t: f32) -> Pose {
    if t == 0.0 {
        return a.clone();
    }
    let rotations = a
        .rotations
        .iter()
        .zip(&b.rotations)
        .map(|(&qa, &qb)| {
            let q = quat(qa).slerp(quat(qb), t);
            Quaternion {
                x: q.x,
                y: q.y,
                z: q.z,
                w: q.w,
            }
        })
        .collect();
    let translations = a
        .translations
        .iter()
        .zip(&b.translations)
        .map(|(&ta, &tb)| {
            Vec3::from_array(ta)
                .lerp(Vec3::from_array(tb), t)
                .to_array()
        })
        .collect();
    Pose {
        rotations,
        translations,
    }
}
