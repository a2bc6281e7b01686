//! The bone map reader (YAML) on any text: an error or a map, never a panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = sinmdm_formats::retarget::BoneMap::parse(text);
    }
});
