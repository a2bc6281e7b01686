//! The fbx reader on any bytes: an error or a clip, never a panic, a hang or a runaway
//! allocation.
#![no_main]

mod scratch;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = scratch::file("clip.fbx", data);
    let _ = sinmdm_formats::read_clip(&path, &sinmdm_formats::ReadOptions::default());
    let _ = sinmdm_formats::list_animations(&path);
});
