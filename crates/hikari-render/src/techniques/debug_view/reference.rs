//! CPU twin of `display.wgsl`: one texel of a frame's texture as the window shows it.

use glam::{Vec2, Vec3, Vec4};
use hikari_math::color::transfer::srgb_encode_f32;

use super::Mapping;

/// The display value (display-encoded, 0 to 1) of texel `v` under `mapping`, as the GPU
/// computes it before quantising to 8 bits.
pub fn display(v: Vec4, mapping: &Mapping) -> Vec3 {
    let v = Vec4::from_array(v.to_array().map(|x| if x.is_finite() { x } else { 0.0 }));
    let srgb = |c: Vec3| {
        Vec3::new(
            srgb_encode_f32(c.x),
            srgb_encode_f32(c.y),
            srgb_encode_f32(c.z),
        )
    };
    match *mapping {
        Mapping::Raw => v.truncate().clamp(Vec3::ZERO, Vec3::ONE),
        Mapping::Radiance { ev100 } => {
            let c = v.truncate().max(Vec3::ZERO) * exposure_scale(ev100);
            srgb(c / (Vec3::ONE + c))
        }
        Mapping::Normal => {
            let n = crate::reference::octahedral::decode(
                Vec2::new(v.x, v.y).clamp(Vec2::splat(-1.0), Vec2::ONE),
            );
            n * 0.5 + Vec3::splat(0.5)
        }
        Mapping::Depth => Vec3::splat(v.x.clamp(0.0, 1.0).sqrt().sqrt()),
        Mapping::Scalar { channel, white } => {
            let s = v[channel.min(3) as usize] / white.max(1e-20);
            srgb(Vec3::splat(s.clamp(0.0, 1.0)))
        }
        Mapping::Luminance { ev100 } => {
            let y = hikari_math::color::luminance(v.truncate().max(Vec3::ZERO));
            let (lo, span) = luminance_ramp(ev100);
            ramp((y.max(1e-20).log2() - lo) / span)
        }
    }
}

/// 1 / the luminance that an exposure of `ev100` shows as white (the saturation-based
/// rule, L_max = 1.2 · 2^EV100).
pub fn exposure_scale(ev100: f32) -> f32 {
    1.0 / (1.2 * 2f32.powf(ev100))
}

/// The luminance ramp's bottom (log2 nits) and span (EVs) for an exposure of `ev100`: eight
/// stops below the exposure's white to four above it.
pub fn luminance_ramp(ev100: f32) -> (f32, f32) {
    let white = (1.2f32).log2() + ev100;
    (white - 8.0, 12.0)
}

/// Blue (0) through green to red (1).
pub fn ramp(t: f32) -> Vec3 {
    let x = t.clamp(0.0, 1.0);
    let c = |o: f32| (1.5 - (4.0 * x - o).abs()).clamp(0.0, 1.0);
    Vec3::new(c(3.0), c(2.0), c(1.0))
}
