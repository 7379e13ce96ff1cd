//! The GGX / Trowbridge-Reitz normal distribution function (Trowbridge & Reitz 1975,
//! Walter et al. 2007), isotropic and anisotropic (Burley 2012, Heitz 2014).
//!
//! `D(h)` is a density of microfacet normals per steradian (sr⁻¹), normalised so that the
//! projected microfacet area equals the macro-surface: `∫ D(h) (n·h) dω_h = 1`.

use glam::DVec3;
use std::f64::consts::PI;

/// Isotropic GGX `D(h) = α² / (π ((n·h)² (α² − 1) + 1)²)` (Walter et al. 2007, eq. 33, in
/// its cosine form), sr⁻¹. `n_dot_h` is the cosine between the normal and the microfacet
/// normal; 0 for `n_dot_h ≤ 0`. `alpha > 0` (use [`super::material::alpha_from_perceptual`]).
pub fn ggx_ndf(n_dot_h: f64, alpha: f64) -> f64 {
    if n_dot_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    // (1 − c)(1 + c) instead of 1 − c², which cancels catastrophically near the peak.
    let sin2 = (1.0 - n_dot_h) * (1.0 + n_dot_h);
    let d = sin2 + n_dot_h * n_dot_h * a2;
    a2 / (PI * d * d)
}

/// Anisotropic GGX `D(h) = 1 / (π α_x α_y ((h_x/α_x)² + (h_y/α_y)² + h_z²)²)` (Heitz 2014,
/// section 5.4), sr⁻¹, with `h_local = (t·h, b·h, n·h)` in the tangent frame; 0 for `h_z ≤ 0`.
/// Equals [`ggx_ndf`] when `alpha_x = alpha_y`.
pub fn ggx_ndf_aniso(h_local: DVec3, alpha_x: f64, alpha_y: f64) -> f64 {
    if h_local.z <= 0.0 {
        return 0.0;
    }
    let s = DVec3::new(h_local.x / alpha_x, h_local.y / alpha_y, h_local.z);
    let d = s.length_squared();
    1.0 / (PI * alpha_x * alpha_y * d * d)
}
