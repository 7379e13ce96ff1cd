//! The Metro Exodus irradiance encoding (Shyshkovtsov et al., GDC 2019, bonus slides):
//! HDR RGB split into luminance-like `Y` stored as L1 SH and chroma `Co, Cg` stored as scalars
//! (6 numbers per pixel), plus the decoders: colour, diffuse resolve, dominant direction and a
//! recomputed specular roughness.
//!
//! Normalisation: a pixel's encoding is the *mean* of [`ShL1YCoCg::encode`] over its ray
//! samples, drawn from a uniform hemisphere (pdf `1 / 2π`). The true radiance SH is therefore
//! `2π ·` the stored Y SH, which is where the factor 2 of the talk's resolve comes from
//! (`2π / π`, the `1/π` being the Lambertian BRDF).

use super::{ShL1, basis};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// RGB → (Y, Co, Cg) with `Y = R/4 + G/2 + B/4`, `Co = R − B`, `Cg = G − (R + B)/2`
/// (the lifting form of the talk, exactly invertible).
pub fn rgb_to_ycocg(c: Vec3) -> Vec3 {
    let co = c.x - c.z;
    let t = c.z + co * 0.5;
    let cg = c.y - t;
    Vec3::new(t + cg * 0.5, co, cg)
}

/// (Y, Co, Cg) → RGB, inverse of [`rgb_to_ycocg`].
pub fn ycocg_to_rgb(v: Vec3) -> Vec3 {
    let t = v.x - v.z * 0.5;
    let g = v.z + t;
    let b = t - v.y * 0.5;
    Vec3::new(b + v.y, g, b)
}

/// Luminance L1 SH plus chroma, the per-pixel GI signal of Metro Exodus.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShL1YCoCg {
    /// `Y` as L1 SH (crate order: c0, y, z, x).
    pub y: ShL1,
    /// Mean `(Co, Cg)`.
    pub co_cg: Vec2,
}

impl ShL1YCoCg {
    /// Encodes one radiance sample `color` (linear RGB) arriving from unit direction `dir`.
    /// `Y` is clamped at 0 as in the talk (negative luminance would flip the SH lobe).
    pub fn encode(color: Vec3, dir: Vec3) -> Self {
        let v = rgb_to_ycocg(color);
        let y = v.x.max(0.0);
        Self {
            y: ShL1::delta(dir, y),
            co_cg: Vec2::new(v.y, v.z),
        }
    }

    /// `self + other` (accumulation); divide by the count with [`ShL1YCoCg::scale`].
    pub fn add(&self, other: &Self) -> Self {
        Self {
            y: self.y + other.y,
            co_cg: self.co_cg + other.co_cg,
        }
    }

    /// `self * s`.
    pub fn scale(&self, s: f32) -> Self {
        Self {
            y: self.y.scale(s),
            co_cg: self.co_cg * s,
        }
    }

    /// `lerp(self, other, t)` (temporal accumulation).
    pub fn lerp(&self, other: &Self, t: f32) -> Self {
        Self {
            y: self.y.lerp(&other.y, t),
            co_cg: self.co_cg.lerp(other.co_cg, t),
        }
    }

    /// Mean colour of the samples, without any directional resolve, clamped at 0.
    pub fn to_color(&self) -> Vec3 {
        let y = self.y.coeffs[0] / basis::C0 as f32;
        ycocg_to_rgb(Vec3::new(y, self.co_cg.x, self.co_cg.y)).max(Vec3::ZERO)
    }

    /// Outgoing diffuse radiance of a white Lambertian surface with unit normal `n`
    /// (multiply by albedo), i.e. irradiance / π. Chroma is rescaled by the ratio of resolved to
    /// mean luminance so the hue of the samples is kept.
    pub fn resolve_diffuse(&self, n: Vec3) -> Vec3 {
        let c = &self.y.coeffs;
        let d = c[3] * n.x + c[1] * n.y + c[2] * n.z;
        // 2π (hemisphere pdf) · [ (2π/3) C1 d + π C0 c0 ] / π
        let a1 = (2.0 * PI / 3.0) * basis::C1 as f32;
        let a0 = PI * basis::C0 as f32;
        let y = (2.0 * (a1 * d + a0 * c[0])).max(0.0);
        let co_cg = self.co_cg * (basis::C0 as f32 * y / (c[0] + 1e-6));
        ycocg_to_rgb(Vec3::new(y, co_cg.x, co_cg.y)).max(Vec3::ZERO)
    }

    /// Direction the light mostly comes from: the band-1 vector, normalised. `None` if zero.
    pub fn dominant_direction(&self) -> Option<Vec3> {
        let c = &self.y.coeffs;
        Vec3::new(c[3], c[1], c[2]).try_normalize()
    }

    /// How directional the light is, in [0, 1]: the mean resultant length `|E[ω]|` of the
    /// luminance distribution, `|L1| / (√3 c0)` (1 for a single direction, 0 for uniform).
    pub fn directionality(&self) -> f32 {
        let c = &self.y.coeffs;
        if c[0] <= 0.0 {
            return 0.0;
        }
        let l1 = Vec3::new(c[1], c[2], c[3]).length();
        (l1 * basis::C0 as f32 / (basis::C1 as f32 * c[0])).clamp(0.0, 1.0)
    }

    /// GGX `α` to use for specular from this SH (Metro: "if the SH is non-directional the light
    /// is uniform, which is the same as a rough material"). The talk gives no formula; ours:
    /// treat the light as a von Mises-Fisher lobe whose mean resultant length is
    /// [`Self::directionality`] (`κ ≈ R(3 − R²)/(1 − R²)`, Banerjee et al. 2005), map it to a GGX
    /// width `α_L² = 2 / (κ + 2)`, and combine widths: `α = min(1, √(α_m² + α_L²))`.
    pub fn specular_alpha(&self, material_alpha: f32) -> f32 {
        let r = self.directionality().min(0.999_999);
        let kappa = r * (3.0 - r * r) / (1.0 - r * r);
        let alpha_l2 = 2.0 / (kappa + 2.0);
        (material_alpha * material_alpha + alpha_l2).sqrt().min(1.0)
    }
}
