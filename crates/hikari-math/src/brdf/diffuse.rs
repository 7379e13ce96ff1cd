//! Lambertian diffuse, weighted by the light that crosses the specular interface twice.
//!
//! Plain Lambert `ρ / π` added to a specular lobe reflects more than it receives when `ρ` is
//! white: the interface has already reflected `F` of the light. We weight Lambert by
//! `(1 − F(n·l)) (1 − F(n·v))`, the Fresnel transmittance into the surface toward the light
//! and out of it toward the viewer (the coupled diffuse term of Shirley et al. 1997,
//! "A Practitioners' Assessment of Light Reflection Models", without its renormalisation).
//! It is symmetric in `v` and `l`, so reciprocity holds, and it uses the macro-normal
//! cosines, not `v·h`: weighting by `1 − F(v·h)` does not conserve energy at grazing view,
//! where the specular lobe sees `F ≈ 1` but the half-vectors of most diffuse directions see
//! `F ≈ F0`. The total directional albedo (specular + diffuse, white base colour) stays below
//! 1 for every roughness, metalness and angle (checked by `tests/brdf.rs`); the price is that
//! a little energy is lost, because light reflected back inside the interface is dropped.

use super::fresnel::fresnel_schlick;
use glam::DVec3;
use std::f64::consts::FRAC_1_PI;

/// Lambert BRDF `ρ / π`, sr⁻¹, for albedo `ρ` in [0, 1] (its directional albedo is `ρ`).
pub fn lambert(albedo: DVec3) -> DVec3 {
    albedo * FRAC_1_PI
}

/// Fresnel-weighted Lambert `ρ / π · (1 − F(n·v)) (1 − F(n·l))`, sr⁻¹, with `F` Schlick's
/// approximation for normal-incidence reflectance `f0`. 0 if either cosine is ≤ 0.
pub fn fresnel_weighted_lambert(albedo: DVec3, f0: DVec3, n_dot_v: f64, n_dot_l: f64) -> DVec3 {
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let tv = DVec3::ONE - fresnel_schlick(f0, n_dot_v);
    let tl = DVec3::ONE - fresnel_schlick(f0, n_dot_l);
    lambert(albedo) * tv * tl
}
