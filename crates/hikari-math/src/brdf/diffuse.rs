//! Lambertian diffuse, scaled by the light the specular interface lets through.
//!
//! Plain Lambert `ρ / π` added to a specular lobe reflects more than it receives when `ρ` is
//! white: the interface has already reflected part of the light. Kelemen & Szirmay-Kalos 2001
//! weight Lambert by `(1 − E_s(μo)) (1 − E_s(μi)) / (1 − E_s,avg)`, where `E_s` is the specular
//! lobe's directional albedo and `E_s,avg` its cosine-weighted average: the light the interface
//! does not reflect enters the body on the way in, and leaves it on the way out, and the
//! normalisation makes the diffuse lobe reflect exactly `ρ (1 − E_s(μo))`. It is symmetric in
//! `v` and `l`, so reciprocity holds.
//!
//! hikari weighted Lambert by the Fresnel transmittances `(1 − F(n·v)) (1 − F(n·l))` of the
//! macro-surface before: that treats a rough surface as a mirror at grazing angles, where its
//! specular lobe in fact reflects far less than `F(n·v) → 1`, and lost up to 60 % of the
//! light (docs/brdf.md).

use glam::DVec3;
use std::f64::consts::FRAC_1_PI;

/// Lambert BRDF `ρ / π`, sr⁻¹, for albedo `ρ` in [0, 1] (its directional albedo is `ρ`).
pub fn lambert(albedo: DVec3) -> DVec3 {
    albedo * FRAC_1_PI
}

/// Albedo-scaled Lambert `ρ / π · (1 − e_o) (1 − e_i) / (1 − e_avg)`, sr⁻¹, for the specular
/// lobe's directional albedos `e_o` (toward the viewer), `e_i` (toward the light) and its
/// average `e_avg` (all in [0, 1]; `1 − e_avg` is floored at [`super::energy::MIN_LOSS`]).
pub fn albedo_scaled_lambert(albedo: DVec3, e_o: f64, e_i: f64, e_avg: f64) -> DVec3 {
    lambert(albedo) * ((1.0 - e_o) * (1.0 - e_i) / (1.0 - e_avg).max(super::energy::MIN_LOSS))
}
