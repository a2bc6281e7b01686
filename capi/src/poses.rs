//! Poses across the boundary: flat float arrays in (references, supplied stream poses, BVH
//! output) and out (results and stream chunks).

use std::ffi::c_char;

use sinmdm::{Model, Pose, Quaternion, motion_from_poses};

use crate::model::{SinmdmModel, model_arg};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::text::{handle_ref, out_slice, slice_arg, str_arg};

/// Poses given to the library, `frames` of them for the model's `joints` joints, as flat
/// arrays in the model file's frame and units.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmPoses {
    /// Frames.
    pub frames: usize,
    /// The root joint's position per frame: `3 x frames` floats.
    pub root_positions: *const f32,
    /// Every joint's local rotation per frame, `x, y, z, w`: `4 x joints x frames` floats.
    pub rotations: *const f32,
    /// Every joint's local translation per frame: `3 x joints x frames` floats, or NULL for
    /// the rest offsets (what a skeleton without stretching has).
    pub translations: *const f32,
}

/// Caller-owned arrays the library fills with poses; capacities are in floats. Needed: root
/// positions `3 x frames`, rotations `4 x joints x frames`, translations `3 x joints x frames`
/// (translations may be NULL when not wanted).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmPoseBuffers {
    /// Root position per frame.
    pub root_positions: *mut f32,
    /// Capacity of `root_positions`.
    pub root_positions_capacity: usize,
    /// Local rotation (`x, y, z, w`) per frame and joint.
    pub rotations: *mut f32,
    /// Capacity of `rotations`.
    pub rotations_capacity: usize,
    /// Local translation per frame and joint, or NULL.
    pub translations: *mut f32,
    /// Capacity of `translations`.
    pub translations_capacity: usize,
}

/// Reads caller poses of the model's skeleton (checked against it where they are used:
/// `motion_from_poses`, `features_from_poses`, `Stream::supply`).
///
/// # Safety
/// The arrays of `poses` are readable for the sizes its documentation gives.
pub(crate) unsafe fn poses_in(
    model: &Model,
    poses: *const SinmdmPoses,
    argument: &str,
) -> Result<Vec<Pose>, Failure> {
    let poses = unsafe { handle_ref(poses, argument) }?;
    let layout = &model.metadata().layout;
    let joints = layout.skeleton.len();
    let frames = poses.frames;
    if frames == 0 || frames > sinmdm::limits::MAX_SAMPLE_FRAMES {
        return Err(Failure::invalid(format!(
            "{argument}.frames must be between 1 and {}, got {frames}",
            sinmdm::limits::MAX_SAMPLE_FRAMES
        )));
    }
    let roots = unsafe { slice_arg(poses.root_positions, 3 * frames, "root_positions") }?;
    let rotations = unsafe { slice_arg(poses.rotations, 4 * joints * frames, "rotations") }?;
    let translations = if poses.translations.is_null() {
        None
    } else {
        Some(unsafe { slice_arg(poses.translations, 3 * joints * frames, "translations") }?)
    };
    Ok((0..frames)
        .map(|f| Pose {
            rotations: (0..joints)
                .map(|j| {
                    let q = &rotations[4 * (f * joints + j)..][..4];
                    Quaternion {
                        x: q[0],
                        y: q[1],
                        z: q[2],
                        w: q[3],
                    }
                })
                .collect(),
            // The root's translation is its position (the C arrays keep it apart, so that the
            // translations may be left out).
            translations: (0..joints)
                .map(|j| match translations {
                    _ if layout.skeleton.joints[j].parent.is_none() => {
                        [roots[3 * f], roots[3 * f + 1], roots[3 * f + 2]]
                    }
                    Some(t) => {
                        let t = &t[3 * (f * joints + j)..][..3];
                        [t[0], t[1], t[2]]
                    }
                    None => layout.rest_translations[j].map(|v| v as f32),
                })
                .collect(),
        })
        .collect())
}

/// The caller's buffers for `frames` poses of `joints` joints, checked (NULL, capacity):
/// root positions, rotations, and translations when wanted.
type PoseSlices<'a> = (&'a mut [f32], &'a mut [f32], Option<&'a mut [f32]>);

/// Checks the caller's buffers for `frames` poses of `joints` joints and gives them as slices.
///
/// # Safety
/// The arrays of `buffers` are writable for their capacities.
pub(crate) unsafe fn pose_slices<'a>(
    buffers: *const SinmdmPoseBuffers,
    frames: usize,
    joints: usize,
) -> Result<PoseSlices<'a>, Failure> {
    let b = unsafe { handle_ref(buffers, "buffers") }?;
    let size = |per_frame: usize| {
        per_frame.checked_mul(frames).ok_or_else(|| {
            Failure::invalid(format!(
                "{frames} frames of {joints} joints do not fit in memory"
            ))
        })
    };
    let (root_size, rotation_size, translation_size) =
        (size(3)?, size(4 * joints)?, size(3 * joints)?);
    let roots = unsafe {
        out_slice(
            b.root_positions,
            b.root_positions_capacity,
            root_size,
            "root_positions",
        )
    }?;
    let rotations = unsafe {
        out_slice(
            b.rotations,
            b.rotations_capacity,
            rotation_size,
            "rotations",
        )
    }?;
    let translations = if b.translations.is_null() {
        None
    } else {
        Some(unsafe {
            out_slice(
                b.translations,
                b.translations_capacity,
                translation_size,
                "translations",
            )
        }?)
    };
    Ok((roots, rotations, translations))
}

/// Writes poses into caller buffers.
///
/// # Safety
/// The arrays of `buffers` are writable for their capacities.
pub(crate) unsafe fn poses_out(
    poses: &[Pose],
    joints: usize,
    buffers: *const SinmdmPoseBuffers,
) -> Result<(), Failure> {
    let (roots, rotations, translations) = unsafe { pose_slices(buffers, poses.len(), joints) }?;
    for (f, pose) in poses.iter().enumerate() {
        roots[3 * f..3 * f + 3].copy_from_slice(&pose.root_position());
        for (j, q) in pose.rotations.iter().enumerate() {
            rotations[4 * (f * joints + j)..][..4].copy_from_slice(&[q.x, q.y, q.z, q.w]);
        }
    }
    if let Some(out) = translations {
        for (f, pose) in poses.iter().enumerate() {
            for (j, t) in pose.translations.iter().enumerate() {
                out[3 * (f * joints + j)..][..3].copy_from_slice(t);
            }
        }
    }
    Ok(())
}

/// Writes `poses` of the model's skeleton to the BVH file `path` (at the model's frame rate,
/// with the skeleton, channels and up axis of its training clip), atomically: the file
/// appears whole or not at all.
///
/// # Safety
/// `model` is a live handle; `poses` as its documentation says; `path` NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_write_bvh(
    model: *const SinmdmModel,
    poses: *const SinmdmPoses,
    path: *const c_char,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let path = unsafe { str_arg(path, "path") }?;
        let layout = &model.metadata().layout;
        let motion = motion_from_poses(&layout.skeleton, layout.fps, &unsafe {
            poses_in(model, poses, "poses")
        }?)?;
        sinmdm::bvh::write_bvh(path, &motion.to_channels())
            .map_err(|e| Failure::new(SinmdmStatus::Io, e.to_string()))
    })
}
