//! The release of a loaded onnxruntime library, as the library itself reports it.

use std::ffi::CStr;
use std::path::Path;

/// The version string of the onnxruntime library at `path` (`"1.31.1"`), asked of the library
/// through `OrtGetApiBase().GetVersionString()`; `None` when it cannot be asked. Call it on a
/// library that is already loaded: opening it again then only takes another reference.
pub(crate) fn library_version(path: &Path) -> Option<String> {
    // SAFETY: the library is onnxruntime, already loaded and initialised by ort from this path,
    // so opening it runs no new initialisers.
    let library = unsafe { libloading::Library::new(path) }.ok()?;
    // SAFETY: `OrtGetApiBase` has this signature in every onnxruntime release (its C API's
    // fixed entry point).
    let get_base = unsafe {
        library.get::<unsafe extern "C" fn() -> *const ort::sys::OrtApiBase>(b"OrtGetApiBase")
    }
    .ok()?;
    // SAFETY: the entry point returns a pointer to a static table, or null.
    let base = unsafe { get_base() };
    if base.is_null() {
        return None;
    }
    // SAFETY: `base` is the library's static table; `GetVersionString` returns a static,
    // NUL-terminated string (or null, checked).
    let text = unsafe { ((*base).GetVersionString)() };
    if text.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated, as above.
    let version = unsafe { CStr::from_ptr(text) };
    version.to_str().ok().map(str::to_owned)
}
