//! Loading onnxruntime, opening models, and what a model's skeleton is.

use std::ffi::{c_char, c_void};
use std::sync::atomic::{AtomicU64, Ordering};

use sinmdm::{Model, ModelOptions, UpAxis};

use crate::limits::SINMDM_MAX_MODEL_BYTES;
use crate::status::{Failure, SinmdmStatus, guard, guard_out};
use crate::text::{copy_array, copy_str, give, handle_mut, handle_ref, slice_arg, str_arg};

/// A progress callback: called after each denoising step of a blocking task on the model it was
/// set on, with the host's `userdata` first, then the steps done and the steps in all. Return
/// `SINMDM_PROGRESS_CONTINUE` to go on, or `SINMDM_PROGRESS_CANCEL` (any value but 0) to stop:
/// the call then returns `SINMDM_CANCELLED` and gives no result. It runs on the thread that
/// made the call and must not call back into the library with the same model.
pub type SinmdmProgressFn =
    Option<unsafe extern "C" fn(userdata: *mut c_void, done: usize, total: usize) -> i32>;

/// A progress callback's answer: go on.
pub const SINMDM_PROGRESS_CONTINUE: i32 = 0;
/// A progress callback's answer: stop the run (any value but 0 does the same).
pub const SINMDM_PROGRESS_CANCEL: i32 = 1;

/// The progress callback of a model and its host's pointer.
#[derive(Clone, Copy)]
pub(crate) struct Progress {
    pub callback: SinmdmProgressFn,
    pub userdata: *mut c_void,
}

impl Progress {
    /// Calls the callback (if any): whether to go on.
    pub(crate) fn go_on(&self, done: usize, total: usize) -> bool {
        match self.callback {
            // SAFETY: the host set this function and pointer with sinmdm_model_set_progress.
            Some(callback) => (unsafe { callback(self.userdata, done, total) }) == 0,
            None => true,
        }
    }
}

/// An open model (opaque): the network and its metadata.
pub struct SinmdmModel {
    pub(crate) model: Model,
    /// Unique in the process: runs and streams remember the model they were made on.
    pub(crate) id: u64,
    pub(crate) progress: Progress,
}

impl SinmdmModel {
    fn new(model: Model) -> SinmdmModel {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        SinmdmModel {
            model,
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            progress: Progress {
                callback: None,
                userdata: std::ptr::null_mut(),
            },
        }
    }

    /// Refuses a handle (a run, a stream) made on another model.
    pub(crate) fn check_same(&self, made_on: u64, what: &str) -> Result<(), Failure> {
        if made_on == self.id {
            Ok(())
        } else {
            Err(Failure::invalid(format!(
                "the {what} was made with another model; pass the model it was made with"
            )))
        }
    }
}

/// The model behind a handle.
///
/// # Safety
/// `model` is NULL or a live handle from `sinmdm_model_open*`.
pub(crate) unsafe fn model_arg<'a>(model: *const SinmdmModel) -> Result<&'a Model, Failure> {
    Ok(&unsafe { handle_ref(model, "model") }?.model)
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

/// The major version of this header: a library of another major may break it.
pub const SINMDM_VERSION_MAJOR: u32 = 0;
/// The minor version of this header: a newer minor adds (and, while the major is 0, may change
/// what the header's CHANGES list).
pub const SINMDM_VERSION_MINOR: u32 = 1;
/// The patch version of this header: fixes only.
pub const SINMDM_VERSION_PATCH: u32 = 0;

/// The loaded library's version, `"MAJOR.MINOR.PATCH"`, a static NUL-terminated string. A host
/// checks it at load against `SINMDM_VERSION_MAJOR` and `_MINOR` (see the introduction's
/// Version), since the header it was built with may not be the library's.
#[unsafe(no_mangle)]
pub extern "C" fn sinmdm_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Loads onnxruntime from the shared library at `path` (an engine that ships its own copy), or
/// finds it when `path` is NULL, in this order: `ORT_DYLIB_PATH`, next to the executable, next
/// to this library, the system loader's search path, a developer checkout's `.venv`. A release
/// older than 1.17 is refused and the search goes on. Opening a model does this on its own with
/// NULL; call it first to choose the library. Asking for a second, different library once one
/// is loaded fails.
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
            .map_err(|e| Failure::new(SinmdmStatus::RuntimeLibrary, e.to_string()))
    })
}

fn options(threads: u32) -> ModelOptions {
    ModelOptions {
        threads: (threads > 0).then_some(threads as usize),
    }
}

/// Opens the model file at `path` and writes its handle to `out`. `threads` is how many samples
/// of a batch run at once, each on its own thread (0: every core; at most
/// `SINMDM_MAX_THREADS`); it changes speed, never values. The file is checked before anything
/// runs: a file that is not a model gives `SINMDM_BAD_MODEL` and names the field or problem.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_open(
    path: *const c_char,
    threads: u32,
    out: *mut *mut SinmdmModel,
) -> SinmdmStatus {
    unsafe {
        guard_out(out, |out| {
            let path = str_arg(path, "path")?;
            let model = Model::open(path, &options(threads))?;
            give(out, SinmdmModel::new(model));
            Ok(())
        })
    }
}

/// Opens a model from the `length` bytes at `bytes` (a file the engine read or packed itself).
/// The bytes are copied: they may be freed as soon as the call returns.
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
    unsafe {
        guard_out(out, |out| {
            if length > SINMDM_MAX_MODEL_BYTES {
                return Err(Failure::invalid(format!(
                    "length is {length} bytes; an ONNX file holds at most {SINMDM_MAX_MODEL_BYTES}"
                )));
            }
            let bytes = slice_arg(bytes, length, "bytes")?;
            let model = Model::from_bytes(bytes, "model bytes", &options(threads))?;
            give(out, SinmdmModel::new(model));
            Ok(())
        })
    }
}

/// Sets the progress callback of the blocking tasks run on `model` (`sinmdm_generate` and the
/// other tasks), with the host's `userdata` handed back to it; a NULL `callback` removes it.
/// Meant for a host that runs tasks on a worker thread and wants to show progress or cancel;
/// a game that spreads a run over frames uses `sinmdm_*_begin` and `sinmdm_run_step` instead.
///
/// # Safety
/// `model` is a live handle; `callback` NULL or a function as `SinmdmProgressFn` says, which
/// with `userdata` stays valid while it is set.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_set_progress(
    model: *mut SinmdmModel,
    callback: SinmdmProgressFn,
    userdata: *mut c_void,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { handle_mut(model, "model") }?;
        model.progress = Progress { callback, userdata };
        Ok(())
    })
}

/// Frees a model (NULL is fine). Streams made on it must not be advanced afterwards.
///
/// # Safety
/// `model` is NULL or a handle from `sinmdm_model_open*`, not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_free(model: *mut SinmdmModel) {
    unsafe { crate::text::free_handle(model) }
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
        let info = unsafe { handle_mut(info, "info") }?;
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

/// Writes to `values` the f32 values one frame of one sample needs while a run is made on
/// `model`: `max(F + 8 C, 12 x joints)`, with F `SinmdmModelInfo::features` and C the
/// network's channels. A request of `count` samples of `frames` frames is refused with
/// `SINMDM_INVALID_ARGUMENT` when `count x frames x values` passes `SINMDM_MAX_RUN_VALUES`; a
/// function rather than a field, since the layout of `SinmdmModelInfo` does not change.
///
/// # Safety
/// `model` is a live handle; `values` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_values_per_frame(
    model: *const SinmdmModel,
    values: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let values = unsafe { handle_mut(values, "values") }?;
        *values = sinmdm::tasks::run_values_per_frame(model.metadata());
        Ok(())
    })
}

/// Copies the name of joint `joint` into `buffer` of `capacity` bytes; `needed` (if not NULL)
/// gets its size with the NUL, also when the buffer is NULL (a size query) or too small.
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
        let index = unsafe { handle_mut(index, "index") }?;
        let skeleton = model.skeleton();
        *index = skeleton.find(name).ok_or_else(|| {
            let names: Vec<&str> = skeleton.joints.iter().map(|j| j.name.as_str()).collect();
            Failure::new(
                SinmdmStatus::UnknownJoint,
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
/// values; `needed` (if not NULL) gets the joint count, also for a NULL `parents` (a size query).
///
/// # Safety
/// `model` is a live handle; `parents` NULL or writable for `capacity` values; `needed` NULL
/// or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_parents(
    model: *const SinmdmModel,
    parents: *mut i32,
    capacity: usize,
    needed: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let values: Vec<i32> = model
            .skeleton()
            .joints
            .iter()
            .map(|joint| joint.parent.map_or(-1, |p| p as i32))
            .collect();
        unsafe { copy_array(&values, parents, capacity, needed, "parents") }
    })
}

/// Writes every joint's rest offset from its parent (x, y, z; file units) to `offsets`, which
/// holds `capacity` floats; `needed` (if not NULL) gets 3 x the joint count, also for a NULL
/// `offsets` (a size query).
///
/// # Safety
/// `model` is a live handle; `offsets` NULL or writable for `capacity` floats; `needed` NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_rest_offsets(
    model: *const SinmdmModel,
    offsets: *mut f32,
    capacity: usize,
    needed: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let values: Vec<f32> = model
            .metadata()
            .layout
            .rest_translations
            .iter()
            .flatten()
            .map(|&v| v as f32)
            .collect();
        unsafe { copy_array(&values, offsets, capacity, needed, "offsets") }
    })
}

/// Writes the contact joints' indices (feet, paws: where planting holds the motion on the
/// ground) to `joints`, which holds `capacity` values; `needed` (if not NULL) gets their count
/// (`SinmdmModelInfo::contact_joints`), also for a NULL `joints` (a size query).
///
/// # Safety
/// `model` is a live handle; `joints` NULL or writable for `capacity` values; `needed` NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_model_contact_joints(
    model: *const SinmdmModel,
    joints: *mut usize,
    capacity: usize,
    needed: *mut usize,
) -> SinmdmStatus {
    guard(|| {
        let model = unsafe { model_arg(model) }?;
        let contacts = &model.metadata().layout.contact_joints;
        unsafe { copy_array(contacts, joints, capacity, needed, "joints") }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_version_macros_are_the_crates() {
        let number = |text: &str| text.parse::<u32>().unwrap();
        assert_eq!(
            SINMDM_VERSION_MAJOR,
            number(env!("CARGO_PKG_VERSION_MAJOR"))
        );
        assert_eq!(
            SINMDM_VERSION_MINOR,
            number(env!("CARGO_PKG_VERSION_MINOR"))
        );
        assert_eq!(
            SINMDM_VERSION_PATCH,
            number(env!("CARGO_PKG_VERSION_PATCH"))
        );
    }
}
