//! Status codes, the thread-local last error, and the guard every entry point runs in: a panic
//! is caught and reported as [`SinmdmStatus::Internal`], never unwound into the caller.

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// cbindgen:rename-all=QualifiedScreamingSnakeCase
/// What a call did. Every function returns one; on anything but `SINMDM_OK`,
/// `sinmdm_last_error` says why, in words that name the argument, field or file. One kind of
/// mistake always gets the same status, whichever function it is made at.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SinmdmStatus {
    /// It worked.
    Ok = 0,
    /// A pointer that must not be NULL was NULL.
    NullArgument = 1,
    /// An argument outside its documented range, or malformed: a count, length, step count,
    /// ramp, span, joint index, factor, share or thread count past its bound (`SINMDM_MAX_*`),
    /// an unknown constant, a string that is not UTF-8, poses that do not fit the skeleton, a
    /// handle used with another model, or a call its handle's state does not allow.
    InvalidArgument = 2,
    /// An output buffer too small; nothing was written and the message gives the size needed
    /// (pass a NULL buffer to ask for it).
    BufferTooSmall = 3,
    /// A joint name the skeleton does not have.
    UnknownJoint = 4,
    /// onnxruntime could not be found or loaded (the message lists where it was looked for).
    RuntimeLibrary = 5,
    /// A model file that could not be opened or is not a valid model.
    BadModel = 6,
    /// A valid request whose run failed inside onnxruntime (out of memory, say).
    TaskFailed = 7,
    /// Reading or writing a file failed.
    Io = 8,
    /// A bug in the library (a caught panic); the handle involved should be freed.
    Internal = 9,
    /// A blocking task's progress callback asked to stop, after any step, the last included: the
    /// call gives no result and the model can be used on. Only blocking tasks call the callback,
    /// so a stepped run (`sinmdm_run_step`) never gives this; a host stops one by freeing it.
    Cancelled = 10,
}

/// A failed call: its status and message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: SinmdmStatus,
    pub message: String,
}

impl Failure {
    pub fn new(status: SinmdmStatus, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    pub fn null(argument: &str) -> Failure {
        Failure::new(SinmdmStatus::NullArgument, format!("{argument} is NULL"))
    }

    pub fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(SinmdmStatus::InvalidArgument, message)
    }
}

impl From<sinmdm::TaskError> for Failure {
    fn from(e: sinmdm::TaskError) -> Failure {
        use sinmdm::TaskError;
        let status = match &e {
            TaskError::Model(model) => return Failure::from_model(model, e.to_string()),
            TaskError::UnknownJoint { .. } => SinmdmStatus::UnknownJoint,
            TaskError::Cancelled { .. } => SinmdmStatus::Cancelled,
            // Everything else is a request checked before it runs: an argument out of range.
            _ => SinmdmStatus::InvalidArgument,
        };
        Failure::new(status, e.to_string())
    }
}

impl From<sinmdm::motion::MotionError> for Failure {
    fn from(e: sinmdm::motion::MotionError) -> Failure {
        Failure::invalid(e.to_string())
    }
}

impl Failure {
    /// The status of a model error: the library, a bad file, a bad argument, or a failed run.
    fn from_model(e: &sinmdm::ModelError, message: String) -> Failure {
        use sinmdm::ModelError;
        let status = match e {
            ModelError::Runtime(_) => SinmdmStatus::RuntimeLibrary,
            ModelError::Threads(_)
            | ModelError::FeatureRows { .. }
            | ModelError::StepCount { .. } => SinmdmStatus::InvalidArgument,
            ModelError::Run { .. } => SinmdmStatus::TaskFailed,
            _ => SinmdmStatus::BadModel,
        };
        Failure::new(status, message)
    }
}

impl From<sinmdm::ModelError> for Failure {
    fn from(e: sinmdm::ModelError) -> Failure {
        let message = e.to_string();
        Failure::from_model(&e, message)
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|slot| *slot.borrow_mut() = text);
}

/// Runs the body of an entry point that gives a handle through `out`: `*out` is set to NULL
/// first (when `out` is not NULL), so a failed call never leaves a stale pointer there.
///
/// # Safety
/// `out` is NULL or writable.
pub(crate) unsafe fn guard_out<T>(
    out: *mut *mut T,
    body: impl FnOnce(*mut *mut T) -> Result<(), Failure>,
) -> SinmdmStatus {
    guard(|| {
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        unsafe { *out = std::ptr::null_mut() };
        body(out)
    })
}

/// Runs an entry point's body: records its error, and turns a panic into a status.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Failure>) -> SinmdmStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => {
            set_last_error("");
            SinmdmStatus::Ok
        }
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            failure.status
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            set_last_error(&format!("internal error (please report it): {what}"));
            SinmdmStatus::Internal
        }
    }
}

/// The message of the last failed call on this thread ("" after a call that worked). The text
/// belongs to the library and stays valid until the next call on the same thread; copy it to
/// keep it. Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn sinmdm_last_error() -> *const c_char {
    LAST_ERROR.with(|slot| slot.borrow().as_ptr())
}
