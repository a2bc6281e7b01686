//! The music reader on any bytes: an error or samples, never a panic, a hang or a runaway
//! allocation.
#![no_main]

mod scratch;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = scratch::file("song.wav", data);
    let _ = sinmdm_beats::audio::read_audio(&path);
});
