//! The path of the shared library (or executable) that holds this code, where the platform
//! can tell: the C ABI's library inside an engine's plugin folder looks next to itself.

/// The path of the shared library (or executable) that holds this code.
#[cfg(unix)]
mod platform {
    use std::ffi::{CStr, c_char, c_int, c_void};
    use std::path::PathBuf;

    #[repr(C)]
    struct DlInfo {
        dli_fname: *const c_char,
        dli_fbase: *mut c_void,
        dli_sname: *const c_char,
        dli_saddr: *mut c_void,
    }

    unsafe extern "C" {
        fn dladdr(address: *const c_void, info: *mut DlInfo) -> c_int;
    }

    pub(crate) fn path() -> Option<PathBuf> {
        let mut info = DlInfo {
            dli_fname: std::ptr::null(),
            dli_fbase: std::ptr::null_mut(),
            dli_sname: std::ptr::null(),
            dli_saddr: std::ptr::null_mut(),
        };
        let address = path as fn() -> Option<PathBuf> as *const c_void;
        // SAFETY: dladdr only reads the address and fills `info`; the name it points to
        // belongs to the loader and is copied at once.
        let found = unsafe { dladdr(address, &mut info) };
        if found == 0 || info.dli_fname.is_null() {
            return None;
        }
        let name = unsafe { CStr::from_ptr(info.dli_fname) };
        let path = PathBuf::from(name.to_string_lossy().into_owned());
        path.is_absolute().then_some(path)
    }
}

/// The path of the DLL (or executable) that holds this code.
#[cfg(windows)]
mod platform {
    use std::ffi::c_void;
    use std::os::windows::ffi::OsStringExt;
    use std::path::PathBuf;

    const FROM_ADDRESS: u32 = 0x4;
    const UNCHANGED_REFCOUNT: u32 = 0x2;

    #[link(name = "kernel32")]
    unsafe extern "system" {
        fn GetModuleHandleExW(flags: u32, address: *const u16, module: *mut *mut c_void) -> i32;
        fn GetModuleFileNameW(module: *mut c_void, name: *mut u16, size: u32) -> u32;
    }

    pub(crate) fn path() -> Option<PathBuf> {
        let mut module = std::ptr::null_mut();
        let address = path as fn() -> Option<PathBuf> as *const u16;
        // SAFETY: the flags ask for the module holding `address` without touching its count.
        let ok =
            unsafe { GetModuleHandleExW(FROM_ADDRESS | UNCHANGED_REFCOUNT, address, &mut module) };
        if ok == 0 {
            return None;
        }
        let mut buffer = vec![0u16; 32_768];
        let length =
            unsafe { GetModuleFileNameW(module, buffer.as_mut_ptr(), buffer.len() as u32) };
        (length > 0 && (length as usize) < buffer.len())
            .then(|| PathBuf::from(std::ffi::OsString::from_wide(&buffer[..length as usize])))
    }
}

/// Elsewhere the folder of the library holding this code is not looked up.
#[cfg(not(any(unix, windows)))]
mod platform {
    pub(crate) fn path() -> Option<std::path::PathBuf> {
        None
    }
}

pub(super) use platform::path;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_library_holding_this_code_is_found() {
        let own = path().expect("dladdr names this test binary");
        assert!(own.is_file(), "{}", own.display());
    }
}
