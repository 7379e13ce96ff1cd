#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| hikari_fuzz::glb(data));
