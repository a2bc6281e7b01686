//! Strings and pointers across the boundary: C strings in, strings out into caller buffers.

use std::ffi::{CStr, c_char};

use crate::status::{Failure, SinmdmStatus};

/// A NUL-terminated UTF-8 argument.
///
/// # Safety
/// `text` is NULL or points to a NUL-terminated string.
pub(crate) unsafe fn str_arg<'a>(text: *const c_char, argument: &str) -> Result<&'a str, Failure> {
    if text.is_null() {
        return Err(Failure::null(argument));
    }
    unsafe { CStr::from_ptr(text) }
        .to_str()
        .map_err(|_| Failure::invalid(format!("{argument} is not UTF-8")))
}

/// Copies `text` and a NUL into `buffer` of `capacity` bytes; `needed` (if not NULL) gets the
/// size with the NUL. A NULL `buffer` only asks for the size.
///
/// # Safety
/// `buffer` is NULL or writable for `capacity` bytes; `needed` is NULL or writable.
pub(crate) unsafe fn copy_str(
    text: &str,
    buffer: *mut c_char,
    capacity: usize,
    needed: *mut usize,
) -> Result<(), Failure> {
    let size = text.len() + 1;
    if !needed.is_null() {
        unsafe { *needed = size };
    }
    if buffer.is_null() {
        return Ok(());
    }
    if capacity < size {
        return Err(Failure::new(
            SinmdmStatus::BufferTooSmall,
            format!("the text needs {size} bytes with its NUL, the buffer holds {capacity}"),
        ));
    }
    unsafe {
        std::ptr::copy_nonoverlapping(text.as_ptr().cast::<c_char>(), buffer, text.len());
        *buffer.add(text.len()) = 0;
    }
    Ok(())
}

/// Copies `values` into the caller's array `buffer` of `capacity` values; `needed` (if not
/// NULL) gets their count. A NULL `buffer` only asks for the count; a short one writes nothing
/// and fails with `SINMDM_BUFFER_TOO_SMALL`.
///
/// # Safety
/// `buffer` is NULL or writable for `capacity` values; `needed` is NULL or writable.
pub(crate) unsafe fn copy_array<T: Copy>(
    values: &[T],
    buffer: *mut T,
    capacity: usize,
    needed: *mut usize,
    argument: &str,
) -> Result<(), Failure> {
    if !needed.is_null() {
        unsafe { *needed = values.len() };
    }
    if buffer.is_null() {
        return Ok(());
    }
    let out = unsafe { out_slice(buffer, capacity, values.len(), argument) }?;
    out.copy_from_slice(values);
    Ok(())
}

/// A caller's array of `count` values as a slice (empty for a NULL pointer with count 0).
///
/// # Safety
/// `data` is NULL or readable for `count` values.
pub(crate) unsafe fn slice_arg<'a, T>(
    data: *const T,
    count: usize,
    argument: &str,
) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if data.is_null() {
        return Err(Failure::null(argument));
    }
    if count > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(Failure::invalid(format!(
            "{argument} is said to hold {count} values, more than memory can"
        )));
    }
    Ok(unsafe { std::slice::from_raw_parts(data, count) })
}

/// A caller's output array of `capacity` values, checked to hold `needed`.
///
/// # Safety
/// `data` is NULL or writable for `capacity` values.
pub(crate) unsafe fn out_slice<'a, T>(
    data: *mut T,
    capacity: usize,
    needed: usize,
    argument: &str,
) -> Result<&'a mut [T], Failure> {
    if data.is_null() {
        return Err(Failure::null(argument));
    }
    if capacity < needed {
        return Err(Failure::new(
            SinmdmStatus::BufferTooSmall,
            format!("{argument} holds {capacity} values, {needed} are needed"),
        ));
    }
    Ok(unsafe { std::slice::from_raw_parts_mut(data, needed) })
}

/// The handle or struct behind a `const` pointer, shared: what the C signature promises not to
/// change is never reached through `&mut`.
///
/// # Safety
/// `handle` is NULL or points to a live `T` (a handle made by this library, or a caller's
/// struct) that nothing changes during the call.
pub(crate) unsafe fn handle_ref<'a, T>(handle: *const T, argument: &str) -> Result<&'a T, Failure> {
    if handle.is_null() {
        return Err(Failure::null(argument));
    }
    Ok(unsafe { &*handle })
}

/// The handle or out-struct behind a `mut` pointer, exclusive.
///
/// # Safety
/// `handle` is NULL or points to a live `T` that nothing else reaches during the call.
pub(crate) unsafe fn handle_mut<'a, T>(
    handle: *mut T,
    argument: &str,
) -> Result<&'a mut T, Failure> {
    if handle.is_null() {
        return Err(Failure::null(argument));
    }
    Ok(unsafe { &mut *handle })
}

/// Handles given out and not yet freed, of every kind.
static LIVE_HANDLES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Writes a new handle to `out`.
///
/// # Safety
/// `out` is writable (checked for NULL by the caller).
pub(crate) unsafe fn give<T>(out: *mut *mut T, value: T) {
    LIVE_HANDLES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    unsafe { *out = Box::into_raw(Box::new(value)) };
}

/// Frees a handle made by [`give`] (NULL is fine).
///
/// # Safety
/// `handle` is NULL or a handle of type `T` from [`give`], not used again.
pub(crate) unsafe fn free_handle<T>(handle: *mut T) {
    if !handle.is_null() {
        LIVE_HANDLES.fetch_sub(1, std::sync::atomic::Ordering::Relaxed);
        drop(unsafe { Box::from_raw(handle) });
    }
}

/// Takes back a handle made by [`give`] as its value (it no longer counts as live).
///
/// # Safety
/// `handle` is a handle of type `T` from [`give`], not used again.
pub(crate) unsafe fn take_handle<T>(handle: *mut T) -> Box<T> {
    LIVE_HANDLES.fetch_sub(1, std::sync::atomic::Ordering::Relaxed);
    unsafe { Box::from_raw(handle) }
}

/// How many handles (models, runs, results, streams) are alive: given out and not freed. A
/// host can check it for leaks, for example after its last `_free` at shutdown.
#[unsafe(no_mangle)]
pub extern "C" fn sinmdm_live_handles() -> usize {
    LIVE_HANDLES.load(std::sync::atomic::Ordering::Relaxed)
}
