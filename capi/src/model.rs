//! Loading onnxruntime, opening models, and what a model's skeleton is.

use std::ffi::c_char;

use sinmdm::{Model, ModelOptions, UpAxis};

use crate::status::{Failure, SinmdmStatus, guard};
use crate::text::{copy_str, give, handle, out_slice, slice_arg, str_arg};

/// An open model (opaque): the network and its metadata.
pub struct SinmdmModel {
    pub(crate) model: Model,
}

/// The model behind a handle.
///
/// # Safety
/// `model` is NULL or a live handle from `sinmdm_model_open*`.
pub(crate) unsafe fn model_arg<'a>(model: *const SinmdmModel) -> Result<&'a Model, Failure> {
    Ok(&unsafe { handle(model.cast_mut(), "model") }?.model)
}

/// The facts of a model an engine needs to hold its poses.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct SinmdmModelInfo {
    /// Joints in the skeleton (End Sites are not joints).
    pub joints: usize,
    /// Feature rows of the network.
    pub features: usize,
    /// Contact joints (their indices: `sinmdm_model_contact_joints`).
    pub contact_joints: usize,
    /// Frames per second of the motion it makes.
    pub fps: f64,
    /// The figure's height in file units (a human clip in centimetres is about 170).
    pub skeleton_height: f64,
    /// The file's up axis as a unit vector (0,1,0 for Y-up, 0,0,1 for Z-up).
    pub up: [f64; 3],
    /// Frames of the clip the model was trained on.
    pub clip_frames: usize,
    /// The network's receptive field in frames.
    pub receptive_field: usize,
    /// Diffusion steps T (the most a run can take).
    pub diffusion_steps: usize,
}

/// The library's version, a static NUL-terminated string.
#[unsafe(no_mangle)]
pub extern "C" fn sinmdm_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Loads onnxruntime from the shared library at `path` (an engine that ships its own copy), or
/// finds it when `path` is NULL (`ORT_DYLIB_PATH`, then the project's `.venv`). Opening a model
/// does this on its own with NULL; call it first to choose the library. Asking for a second,
/// different library once one is loaded fails.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_load_onnxruntime(path: *const c_char) -> SinmdmStatus {
    guard(|| {
        let loaded = if path.is_null() {
            sinmdm::init_onnxruntime()
        } else {
            sinmdm::load_onnxruntime(unsafe { str_arg(path, "path") }?)
        };
        loaded
            .map(|_| ())
            .map_err(|e| Failure::new(SinmdmStatus::SinmdmRuntimeLibrary, e.to_string()))
    })
}

fn options(threads: u32) -> ModelOptions {
    ModelOptions {
        threads: (threads > 0).then_some(threads as usize),
    }
}

/// Opens the model file at `path`, running it on `threads` threads (0: every core), and writes
/// its handle to `out`. The file is checked before anything runs: a file that is not a model
/// gives `SINMDM_BAD_MODEL` and names the field or problem.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_open(
    path: *const c_char,
    threads: u32,
    out: *mut *mut SinmdmModel,
) -> SinmdmStatus {
    guard(|| {
        let path = unsafe { str_arg(path, "path") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let model = Model::open(path, &options(threads))?;
        unsafe { give(out, SinmdmModel { model }) };
        Ok(())
    })
}

/// Opens a model from the `length` bytes at `bytes` (a file the engine read or packed itself).
///
/// # Safety
/// `bytes` is readable for `length` bytes; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_open_bytes(
    bytes: *const u8,
    length: usize,
    threads: u32,
    out: *mut *mut SinmdmModel,
) -> SinmdmStatus {
    guard(|| {
        let bytes = unsafe { slice_arg(bytes, length, "bytes") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let model = Model::from_bytes(bytes, "model bytes", &options(threads))?;
        unsafe { give(out, SinmdmModel { model }) };
        Ok(())
    })
}

/// Frees a model (NULL is fine). Streams made on it must not be advanced afterwards.
///
/// # Safety
/// `model` is NULL or a handle from `sinmdm_model_open*`, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_free(model: *mut SinmdmModel) {
    if !model.is_null() {
        drop(unsafe { Box::from_raw(model) });
    }
}

/// Writes the model's facts to `info`.
///
/// # Safety
/// `model` is a live handle; `info` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_info(
    model: *const SinmdmModel,
    info: *mut SinmdmModelInfo,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let info = unsafe { handle(info, "info") }?;
        let metadata = model.metadata();
        let up: UpAxis = metadata.layout.up;
        *info = SinmdmModelInfo {
            joints: model.skeleton().len(),
            features: metadata.network.features,
            contact_joints: metadata.layout.contact_joints.len(),
            fps: model.fps(),
            skeleton_height: metadata.layout.skeleton_height,
            up: up.direction().0,
            clip_frames: model.clip_frames(),
            receptive_field: metadata.network.receptive_field,
            diffusion_steps: metadata.diffusion.steps,
        };
        Ok(())
    })
}

/// Copies the name of joint `joint` into `buffer` (see the size convention in the header's
/// introduction); `needed` gets its size with the NUL.
///
/// # Safety
/// `model` is a live handle; `buffer` NULL or writable for `capacity` bytes; `needed` NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_joint_name(
    model: *const SinmdmModel,
    joint: usize,
    buffer: *mut c_char,
    capacity: usize,
    needed: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let skeleton = model.skeleton();
        let name = &skeleton
            .joints
            .get(joint)
            .ok_or_else(|| {
                Failure::invalid(format!(
                    "joint {joint} is not in the skeleton of {} joints",
                    skeleton.len()
                ))
            })?
            .name;
        unsafe { copy_str(name, buffer, capacity, needed) }
    })
}

/// Writes the index of the joint called `name` to `index`, or fails with
/// `SINMDM_UNKNOWN_JOINT` (the message lists the joints).
///
/// # Safety
/// `model` is a live handle; `name` a NUL-terminated string; `index` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_find_joint(
    model: *const SinmdmModel,
    name: *const c_char,
    index: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let name = unsafe { str_arg(name, "name") }?;
        let index = unsafe { handle(index, "index") }?;
        let skeleton = model.skeleton();
        *index = skeleton.find(name).ok_or_else(|| {
            let names: Vec<&str> = skeleton.joints.iter().map(|j| j.name.as_str()).collect();
            Failure::new(
                SinmdmStatus::SinmdmUnknownJoint,
                format!(
                    "joint '{name}' is not in the model's skeleton (joints: {})",
                    names.join(", ")
                ),
            )
        })?;
        Ok(())
    })
}

/// Writes every joint's parent index (-1 for the root) to `parents`, which holds `capacity`
/// values (at least the joint count).
///
/// # Safety
/// `model` is a live handle; `parents` writable for `capacity` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_parents(
    model: *const SinmdmModel,
    parents: *mut i32,
    capacity: usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let joints = &model.skeleton().joints;
        let out = unsafe { out_slice(parents, capacity, joints.len(), "parents") }?;
        for (slot, joint) in out.iter_mut().zip(joints) {
            *slot = joint.parent.map_or(-1, |p| p as i32);
        }
        Ok(())
    })
}

/// Writes every joint's rest offset from its parent (x, y, z; file units) to `offsets`, which
/// holds `capacity` floats (at least 3 x the joint count).
///
/// # Safety
/// `model` is a live handle; `offsets` writable for `capacity` floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_rest_offsets(
    model: *const SinmdmModel,
    offsets: *mut f32,
    capacity: usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let rest = &model.metadata().layout.rest_translations;
        let out = unsafe { out_slice(offsets, capacity, rest.len() * 3, "offsets") }?;
        for (slot, value) in out.iter_mut().zip(rest.iter().flatten()) {
            *slot = *value as f32;
        }
        Ok(())
    })
}

/// Writes the contact joints' indices (feet, paws: where planting holds the motion on the
/// ground) to `joints`, which holds `capacity` values (`SinmdmModelInfo::contact_joints`).
///
/// # Safety
/// `model` is a live handle; `joints` writable for `capacity` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_contact_joints(
    model: *const SinmdmModel,
    joints: *mut usize,
    capacity: usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let contacts = &model.metadata().layout.contact_joints;
        if contacts.is_empty() {
            return Ok(());
        }
        let out = unsafe { out_slice(joints, capacity, contacts.len(), "joints") }?;
        out.copy_from_slice(contacts);
        Ok(())
    })
}
