//! Status codes, the thread-local last error, and the guard every entry point runs in: a panic
//! is caught and reported as [`SinmdmStatus::SinmdmInternal`], never unwound into the caller.

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What a call did. Every function returns one; on anything but `SINMDM_OK`,
/// `sinmdm_last_error` says why, in words that name the argument, field or file.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SinmdmStatus {
    /// It worked.
    SinmdmOk = 0,
    /// A pointer that must not be NULL was NULL.
    SinmdmNullArgument = 1,
    /// An argument out of range or malformed (a count, an index, a string that is not UTF-8,
    /// poses that do not fit the skeleton).
    SinmdmInvalidArgument = 2,
    /// An output buffer too small; the message gives the size needed.
    SinmdmBufferTooSmall = 3,
    /// A joint name the skeleton does not have.
    SinmdmUnknownJoint = 4,
    /// onnxruntime could not be loaded.
    SinmdmRuntimeLibrary = 5,
    /// A model file that could not be opened or is not a valid model.
    SinmdmBadModel = 6,
    /// A request the model refused (spans, lengths, counts), or a run that failed.
    SinmdmTaskFailed = 7,
    /// Reading or writing a file failed.
    SinmdmIo = 8,
    /// A bug in the library (a caught panic); the handle involved should be freed.
    SinmdmInternal = 9,
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
        Failure::new(
            SinmdmStatus::SinmdmNullArgument,
            format!("{argument} is NULL"),
        )
    }

    pub fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(SinmdmStatus::SinmdmInvalidArgument, message)
    }
}

impl From<sinmdm::TaskError> for Failure {
    fn from(e: sinmdm::TaskError) -> Failure {
        let status = match e {
            sinmdm::TaskError::UnknownJoint { .. } => SinmdmStatus::SinmdmUnknownJoint,
            _ => SinmdmStatus::SinmdmTaskFailed,
        };
        Failure::new(status, e.to_string())
    }
}

impl From<sinmdm::motion::MotionError> for Failure {
    fn from(e: sinmdm::motion::MotionError) -> Failure {
        Failure::invalid(e.to_string())
    }
}

impl From<sinmdm::ModelError> for Failure {
    fn from(e: sinmdm::ModelError) -> Failure {
        let status = match e {
            sinmdm::ModelError::Runtime(_) => SinmdmStatus::SinmdmRuntimeLibrary,
            _ => SinmdmStatus::SinmdmBadModel,
        };
        Failure::new(status, e.to_string())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|slot| *slot.borrow_mut() = text);
}

/// Runs an entry point's body: records its error, and turns a panic into a status.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Failure>) -> SinmdmStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => {
            set_last_error("");
            SinmdmStatus::SinmdmOk
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
            SinmdmStatus::SinmdmInternal
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
