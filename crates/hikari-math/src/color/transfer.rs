//! Transfer functions (encodings), IEC 61966-2-1 sRGB.

/// Linear → sRGB-encoded, for values in [0, 1] (extended symmetrically for negatives).
pub fn srgb_encode(x: f64) -> f64 {
    let a = x.abs();
    let e = if a <= 0.003_130_8 {
        12.92 * a
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    e.copysign(x)
}

/// sRGB-encoded → linear, inverse of [`srgb_encode`].
pub fn srgb_decode(e: f64) -> f64 {
    let a = e.abs();
    let x = if a <= 0.040_45 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    x.copysign(e)
}

/// f32 version of [`srgb_encode`] (what a shader computes).
pub fn srgb_encode_f32(x: f32) -> f32 {
    srgb_encode(x as f64) as f32
}

/// f32 version of [`srgb_decode`].
pub fn srgb_decode_f32(e: f32) -> f32 {
    srgb_decode(e as f64) as f32
}
