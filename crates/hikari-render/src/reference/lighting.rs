//! What every lighting pass's twin shares: the G-buffer texel as the lighting passes read it,
//! and the clamp of their radiance to what a half float holds.

use glam::{Vec3, Vec4};

/// The largest radiance (nits) a lit image stores (`MAX_RADIANCE` of the lighting shaders).
pub const MAX_RADIANCE: f32 = 65000.0;

/// A G-buffer texel as the lighting pass reads it.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    pub depth: f32,
    pub normal: Vec4,
    pub albedo: Vec4,
    pub material: Vec4,
    /// Emitted nits (rgb) and the dielectric specular weight (a), as `gbuffer.emissive`.
    pub emissive: Vec4,
}

/// Radiance as a lit image stores it: negative (or NaN) lanes 0, the rest at most
/// [`MAX_RADIANCE`].
pub fn clamp(r: Vec3) -> Vec3 {
    Vec3::from_array(
        r.to_array()
            .map(|c| if c >= 0.0 { c.min(MAX_RADIANCE) } else { 0.0 }),
    )
}
