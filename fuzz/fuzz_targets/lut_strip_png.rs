#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| hikari_fuzz::lut_strip_png(data));
