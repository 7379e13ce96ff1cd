//! CPU twin of `tonemap.apply`, in f32 and in the shader's order, from the same
//! [`TonemapParams`]. The matrices themselves are checked against hikari-math (f64) and
//! colour-science fixtures in the tests.

use super::cube::CubeLut;
use super::{
    SWITCH_CURVE, SWITCH_DITHER, SWITCH_LOCAL_GAIN, SWITCH_LOCAL_GRID, SWITCH_LUT, SWITCH_PURKINJE,
    TonemapParams,
};

fn rows3(m: &[[f32; 4]; 3], c: [f32; 3]) -> [f32; 3] {
    m.map(|r| r[0] * c[0] + r[1] * c[1] + r[2] * c[2])
}

/// The talk's three-line Purkinje shift: `lmsr = M c`, `g = 1/sqrt(1 + lmsr.xyz)`,
/// `c + (R g) lmsr.w`, for `c` in nits; the change times `sat / (sat + lmsr.w)` when the
/// rod saturation `sat` is set.
pub fn purkinje(p: &TonemapParams, c: [f32; 3]) -> [f32; 3] {
    let l = p
        .lmsr_from_rgb
        .map(|r| r[0] * c[0] + r[1] * c[1] + r[2] * c[2]);
    let g = [0, 1, 2].map(|i| 1.0 / (1.0 + l[i].max(0.0)).sqrt());
    let d = rows3(&p.rgb_from_lms_gain, g);
    let sat = p.purkinje_fade[0];
    let fade = if sat > 0.0 {
        sat / (sat + l[3].max(0.0))
    } else {
        1.0
    };
    [0, 1, 2].map(|i| c[i] + d[i] * (l[3] * fade))
}

/// Uchimura's curve (CEDEC 2017) at exposed value `x`: a toe `m (x/m)^c + b` blended by a
/// smoothstep into the line `m + a (x - m)`, then from `S0` on the shoulder
/// `P - (P - S1) exp(CP (x - S0))`, which meets the line with the same slope.
pub fn curve(p: &TonemapParams, x: f32) -> f32 {
    let x = x.max(0.0);
    let [pmax, a, m, c] = p.curve;
    let [b, s0, s1, cp] = p.curve_shoulder;
    let t = (x / m).clamp(0.0, 1.0);
    let w0 = 1.0 - t * t * (3.0 - 2.0 * t);
    let w2 = if x >= s0 { 1.0 } else { 0.0 };
    let w1 = 1.0 - w0 - w2;
    let toe = if x > 0.0 { m * (x / m).powf(c) + b } else { b };
    let lin = m + a * (x - m);
    let shoulder = pmax - (pmax - s1) * (cp * (x - s0)).exp();
    toe * w0 + lin * w1 + shoulder * w2
}

pub fn srgb_encode(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The dither added at pixel `(x, y)` with seed `seed`: triangular in [-0.5, 0.5] / 255.
pub fn dither(x: u32, y: u32, seed: u32) -> f32 {
    let h1 = pcg(x.wrapping_add(pcg(y.wrapping_add(pcg(seed)))));
    let h2 = pcg(h1);
    let u1 = (h1 >> 8) as f32 / 16_777_216.0;
    let u2 = (h2 >> 8) as f32 / 16_777_216.0;
    (u1 + u2 - 1.0) * (0.5 / 255.0)
}

/// `lut` with its entries rounded to f16, as [`super::upload_lut`] stores them on the GPU.
pub fn as_uploaded(lut: &CubeLut) -> CubeLut {
    let mut l = lut.clone();
    for e in l.data.iter_mut() {
        *e = e.map(|v| half::f16::from_f32(v).to_f32());
    }
    l
}

/// Exposed linear Rec.709 → display-linear Rec.709 in [0, 1]: to the tonemapping space
/// (white balance included), the curve (or a clip) per channel, back.
pub fn tone(p: &TonemapParams, c: [f32; 3]) -> [f32; 3] {
    let t = rows3(&p.tonemap_from_rec709, c);
    let t = if p.switches[0] & SWITCH_CURVE != 0 {
        t.map(|v| curve(p, v))
    } else {
        t.map(|v| v.clamp(0.0, 1.0))
    };
    rows3(&p.rec709_from_tonemap, t).map(|v| if v >= 0.0 { v.min(1.0) } else { 0.0 })
}

/// The display value in [0, 1] per channel (before the 8-bit store) of radiance `rgb` (nits)
/// at pixel `(x, y)`, with exposure `scale`, the local tonemap's `log2_gain` there (read only
/// if its switch is on), and the grade `lut` (read only if its switch is on).
pub fn apply(
    p: &TonemapParams,
    scale: f32,
    log2_gain: f32,
    lut: Option<&CubeLut>,
    rgb: [f32; 3],
    x: u32,
    y: u32,
) -> [f32; 3] {
    let flags = p.switches[0];
    let mut c = rgb.map(|v| if v >= 0.0 { v.min(6.0e4) } else { 0.0 });
    if flags & SWITCH_PURKINJE != 0 {
        c = purkinje(p, c).map(|v| v.max(0.0));
    }
    let mut s = scale;
    if flags & (SWITCH_LOCAL_GAIN | SWITCH_LOCAL_GRID) != 0 {
        s *= log2_gain.exp2();
    }
    let c = tone(p, c.map(|v| v * s)).map(|v| if v.is_nan() { 0.0 } else { v });
    let mut e = c.map(srgb_encode);
    if flags & SWITCH_LUT != 0
        && let Some(lut) = lut
    {
        e = lut.sample(e);
    }
    if flags & SWITCH_DITHER != 0 {
        let d = dither(x, y, p.switches[1]);
        e = e.map(|v| v + d);
    }
    e.map(|v| v.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::tonemap::settings::TonemapSettings;

    fn params(s: &TonemapSettings) -> TonemapParams {
        TonemapParams::new(s, None, false, 0).unwrap()
    }

    #[test]
    fn the_curve_is_continuous_increasing_and_bounded() {
        let p = params(&TonemapSettings::default());
        let mut last = curve(&p, 0.0);
        assert!(last.abs() < 1e-6);
        let mut x = 1e-4f32;
        while x < 1e3 {
            let y = curve(&p, x);
            assert!(y >= last - 1e-6 && y <= 1.0, "x {x}: {y} after {last}");
            // No jump where the pieces meet (the steps are 1 %).
            assert!(y - last < 0.02, "x {x}: jump {}", y - last);
            last = y;
            x *= 1.01;
        }
        assert!(last > 0.999, "the shoulder approaches the maximum: {last}");
        // The linear section passes through (m, m) with slope a.
        let m = p.curve[2];
        let s0 = p.curve_shoulder[1];
        let mid = 0.5 * (m + s0);
        assert!((curve(&p, mid) - mid).abs() < 1e-6);
    }

    #[test]
    fn the_dither_is_triangular_within_half_a_step() {
        let n = 200_000;
        let v: Vec<f32> = (0..n).map(|i| dither(i % 512, i / 512, 3)).collect();
        let step = 1.0 / 255.0;
        assert!(v.iter().all(|d| d.abs() <= 0.5 * step));
        let mean = v.iter().sum::<f32>() / n as f32;
        assert!(mean.abs() < 0.005 * step, "{mean}");
        // A triangular density on [-h, h] has variance h²/6.
        let var = v.iter().map(|d| d * d).sum::<f32>() / n as f32;
        let h = 0.5 * step;
        assert!((var / (h * h / 6.0) - 1.0).abs() < 0.02, "{var}");
    }
}
