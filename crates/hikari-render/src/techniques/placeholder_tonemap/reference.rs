//! CPU twin of `placeholder_tonemap.apply`.

/// Exposure multiplier for a camera at `ev100` (saturation-based sensitivity, Lagarde and de
/// Rousiers 2014, "Moving Frostbite to PBR", eq. 15 with q = 0.65, S = 100, K = 12.5).
pub fn exposure_from_ev100(ev100: f32) -> f32 {
    1.0 / (1.2 * 2f32.powf(ev100))
}

pub fn srgb_encode(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Display value in [0, 1] per channel (before 8-bit quantisation) of HDR radiance `rgb`.
pub fn apply(rgb: [f32; 3], exposure: f32) -> [f32; 3] {
    // `!(x >= 0)` catches NaN as well as negatives.
    let c = rgb.map(|v| {
        let e = v * exposure;
        if e >= 0.0 { e } else { 0.0 }
    });
    let peak = c[0].max(c[1]).max(c[2]);
    c.map(|v| srgb_encode(v / (1.0 + peak)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encode_matches_the_standard_breakpoints() {
        // IEC 61966-2-1: linear 0.0031308 -> 0.04045, 1 -> 1, 0.18 -> 0.46135...
        assert!((srgb_encode(0.003_130_8) - 0.040_45).abs() < 1e-5);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-5);
    }

    #[test]
    fn curve_keeps_hue_and_never_exceeds_one() {
        for v in [0.0f32, 0.1, 1.0, 10.0, 1e4] {
            let out = apply([v, v * 0.5, v * 0.25], 1.0);
            assert!(out.iter().all(|&c| (0.0..=1.0).contains(&c)));
        }
        assert_eq!(apply([f32::NAN, -1.0, 0.0], 1.0), [0.0, 0.0, 0.0]);
    }
}
