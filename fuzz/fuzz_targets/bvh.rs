//! The BVH reader on any text: an error or a clip, never a panic, a hang or a runaway allocation.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = sinmdm::bvh::parse_bvh(text, "fuzz.bvh");
    }
});
