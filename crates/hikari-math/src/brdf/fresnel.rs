//! Schlick's approximation of the Fresnel reflectance (Schlick 1994, "An Inexpensive BRDF
//! Model for Physically-based Rendering").

use glam::DVec3;

/// Schlick weight `(1 − cos θ)⁵`, with `cos θ` clamped to [0, 1].
pub fn schlick_weight(cos_theta: f64) -> f64 {
    (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5)
}

/// `F(θ) = F0 + (1 − F0)(1 − cos θ)⁵` per channel, in [F0, 1]: equal to `F0` at normal
/// incidence and 1 at grazing. For the specular lobe `cos θ = v·h` (the angle to the microfacet
/// that reflects `v` into `l`); the diffuse weights use `n·v` and `n·l`.
pub fn fresnel_schlick(f0: DVec3, cos_theta: f64) -> DVec3 {
    f0 + (DVec3::ONE - f0) * schlick_weight(cos_theta)
}

/// `F(θ) = F0 + (F90 − F0)(1 − cos θ)⁵` per channel: [`fresnel_schlick`] with the grazing
/// reflectance `f90` instead of 1, so that a weighted interface (`s` times a Schlick
/// Fresnel) stays one Schlick form.
pub fn fresnel_schlick_f90(f0: DVec3, f90: f64, cos_theta: f64) -> DVec3 {
    f0 + (DVec3::splat(f90) - f0) * schlick_weight(cos_theta)
}

/// Scalar [`fresnel_schlick`].
pub fn fresnel_schlick_scalar(f0: f64, cos_theta: f64) -> f64 {
    f0 + (1.0 - f0) * schlick_weight(cos_theta)
}
