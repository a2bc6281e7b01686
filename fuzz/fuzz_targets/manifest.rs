//! The library's manifest reader (YAML) on any bytes: an error or a manifest, never a panic.
#![no_main]

mod scratch;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = scratch::file("library.yaml", data);
    let _ = sinmdm_library::manifest::Manifest::load(&path);
});
