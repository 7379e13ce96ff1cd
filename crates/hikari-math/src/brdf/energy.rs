//! Energy compensation: the light a single-scattering GGX lobe loses, given back as a
//! multiple-scattering lobe (Kulla & Conty 2017), and the diffuse lobe scaled by what the
//! specular lobe leaves (Kelemen & Szirmay-Kalos 2001), both from the tables of
//! [`super::albedo`].
//!
//! * Multiple scattering: `f_ms(v, l) = F_ms (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg))`, where
//!   `E` is the `F = 1` albedo. Its directional albedo is exactly `F_ms (1 − E(μo))`, so a white
//!   metal reflects `E + (1 − E) = 1`. The colour `F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg))`
//!   sums the bounces of light that each lose `1 − F_avg` to absorption, with
//!   `F_avg = 2 ∫ F(μ) μ dμ = F0 + (1 − F0) / 21` for Schlick's Fresnel.
//! * Diffuse: `ρ/π (1 − E_d(μo)) (1 − E_d(μi)) / (1 − E_d,avg)`, where `E_d` is the directional
//!   albedo of the dielectric's whole specular lobe (F0 = 0.04, single + multiple scattering).
//!   What the interface reflects does not enter the body, on the way in and on the way out;
//!   its directional albedo is exactly `ρ (1 − E_d(μo))`, so a white dielectric reflects
//!   `E_d + (1 − E_d) = 1`. Symmetric in `μo, μi`, so reciprocal.
//!
//! A material of metalness `m` is the blend `(1 − m) dielectric + m metal` of two such BRDFs
//! (glTF 2.0's definition); the single-scattering lobe is linear in F0 and so blends through F0,
//! the multiple-scattering colour is blended itself.
//!
//! A specular weight `s` (KHR_materials_specular's `specularFactor`) scales the dielectric's
//! whole specular lobe, single and multiple scattering: `E_d` becomes `s E_d` throughout, so
//! the diffuse lobe keeps what the weaker interface leaves, `ρ (1 − s E_d(μo))`, and a white
//! dielectric still reflects 1. At `s = 0` the dielectric is exactly Lambert.
//!
//! Anisotropic lobes read the tables at [`isotropic_equivalent_roughness`] (the isotropic lobe
//! with the same peak `D(n)`): the compensation is then that of the isotropic lobe, which is
//! only approximate for them (docs/brdf.md gives the furnace numbers).

use super::albedo::{albedo_tables, isotropic_equivalent_roughness};
use super::diffuse::albedo_scaled_lambert;
use super::material::{DIELECTRIC_F0, Material};
use glam::DVec3;
use std::f64::consts::FRAC_1_PI;

/// Floor of `1 − E_avg` in the compensation denominators: the tables' smoothest row loses
/// 3e-5 of its light, well above this; only protects against a division by 0.
pub const MIN_LOSS: f64 = 1e-6;

/// `F_avg = 2 ∫₀¹ F(μ) μ dμ = F0 + (1 − F0) / 21` for Schlick's Fresnel (since
/// `2 ∫₀¹ (1 − μ)⁵ μ dμ = 1/21`), per channel.
pub fn fresnel_schlick_average(f0: DVec3) -> DVec3 {
    f0 + (DVec3::ONE - f0) / 21.0
}

/// Kulla & Conty 2017's colour of the multiple-scattering lobe,
/// `F_avg² E_avg / (1 − F_avg (1 − E_avg))`, per channel, for average Fresnel `f_avg` and
/// average `F = 1` albedo `e_avg`: 1 for a white metal, about `F_avg²` for a dark one.
pub fn multiple_scattering_fresnel(f_avg: DVec3, e_avg: f64) -> DVec3 {
    f_avg * f_avg * e_avg / (DVec3::ONE - f_avg * (1.0 - e_avg))
}

/// Everything the compensation needs for one material, independent of directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compensation {
    /// Perceptual roughness at which the tables are read
    /// ([`isotropic_equivalent_roughness`]).
    pub roughness: f64,
    /// `E_avg`: average single-scattering albedo with `F = 1`.
    pub e_avg: f64,
    /// Colour of the multiple-scattering lobe, `(1 − m) s F_ms(0.04) + m F_ms(base colour)`.
    pub ms_fresnel: DVec3,
    /// `F_ms(0.04)`: the dielectric's multiple-scattering colour (grey), unweighted.
    pub dielectric_ms_fresnel: f64,
    /// The dielectric's specular weight `s` ([`Material::specular_weight`]).
    pub specular: f64,
    /// `s E_d,avg`: average albedo of the dielectric's whole specular lobe.
    pub dielectric_avg: f64,
}

impl Compensation {
    /// The terms for `material`.
    pub fn new(material: &Material) -> Self {
        let (ax, ay) = material.alphas();
        let roughness = isotropic_equivalent_roughness(ax, ay);
        let (e_avg, e_w_avg) = albedo_tables().average(roughness);
        let fms = |f0: DVec3| multiple_scattering_fresnel(fresnel_schlick_average(f0), e_avg);
        let dielectric_ms_fresnel = fms(DVec3::splat(DIELECTRIC_F0)).x;
        let metal = material.metalness.clamp(0.0, 1.0) as f64;
        let base = material
            .base_color
            .as_dvec3()
            .clamp(DVec3::ZERO, DVec3::ONE);
        let specular = material.specular_weight();
        let ms_fresnel = DVec3::splat(specular * dielectric_ms_fresnel).lerp(fms(base), metal);
        let dielectric_avg = specular * dielectric_albedo(e_avg, e_w_avg, dielectric_ms_fresnel);
        Self {
            roughness,
            e_avg,
            ms_fresnel,
            dielectric_ms_fresnel,
            specular,
            dielectric_avg,
        }
    }

    /// `(E, E_w)` for direction `w_local` (tangent frame, `z` = `n·w`) from the tables.
    pub fn single_scattering(&self, w_local: DVec3) -> (f64, f64) {
        albedo_tables().lookup(w_local.z, self.roughness)
    }

    /// `s E_d(w)`: directional albedo of the dielectric's specular lobe (single + multiple
    /// scattering, F0 = 0.04, weight `s`) for direction `w_local`.
    pub fn dielectric_specular_albedo(&self, w_local: DVec3) -> f64 {
        let (e, e_w) = self.single_scattering(w_local);
        self.specular * dielectric_albedo(e, e_w, self.dielectric_ms_fresnel)
    }

    /// The multiple-scattering lobe `f_ms(v, l)`, sr⁻¹, per channel, for directions in the
    /// tangent frame (0 if either is at or below the surface).
    pub fn multiple_scattering(&self, v_local: DVec3, l_local: DVec3) -> DVec3 {
        if v_local.z <= 0.0 || l_local.z <= 0.0 {
            return DVec3::ZERO;
        }
        let (e_o, _) = self.single_scattering(v_local);
        let (e_i, _) = self.single_scattering(l_local);
        self.ms_fresnel * ((1.0 - e_o) * (1.0 - e_i) * FRAC_1_PI / (1.0 - self.e_avg).max(MIN_LOSS))
    }

    /// The diffuse lobe for albedo `ρ`: [`albedo_scaled_lambert`] with the dielectric's
    /// specular albedos `E_d(v)`, `E_d(l)` and `E_d,avg`, sr⁻¹; 0 if `v` or `l` is at or
    /// below the surface.
    pub fn diffuse(&self, albedo: DVec3, v_local: DVec3, l_local: DVec3) -> DVec3 {
        if v_local.z <= 0.0 || l_local.z <= 0.0 {
            return DVec3::ZERO;
        }
        albedo_scaled_lambert(
            albedo,
            self.dielectric_specular_albedo(v_local),
            self.dielectric_specular_albedo(l_local),
            self.dielectric_avg,
        )
    }
}

/// `E_d = F0 E + (1 − F0) E_w + F_ms (1 − E)` with `F0 = 0.04`: Schlick's Fresnel is linear in
/// F0, and the multiple-scattering lobe reflects `F_ms (1 − E)`. The same form gives the
/// average from the averages.
fn dielectric_albedo(e: f64, e_w: f64, ms_fresnel: f64) -> f64 {
    DIELECTRIC_F0 * e + (1.0 - DIELECTRIC_F0) * e_w + ms_fresnel * (1.0 - e)
}
