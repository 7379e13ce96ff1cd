//! The full BRDF times the cosine: what a deferred light pass multiplies by a light's
//! irradiance.

use super::energy::Compensation;
use super::fresnel::fresnel_schlick_f90;
use super::ggx::{ggx_ndf, ggx_ndf_aniso};
use super::material::Material;
use super::smith::{visibility, visibility_aniso};
use glam::{DVec3, Vec3};

/// The three lobes of [`evaluate_f64`], each already multiplied by `n·l` (sr⁻¹).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobes {
    /// Single scattering, `D · V · F · (n·l)`.
    pub specular: DVec3,
    /// Multiple scattering, [`Compensation::multiple_scattering`] times `n·l`.
    pub multiple: DVec3,
    /// Albedo-scaled Lambert, [`Compensation::diffuse`] times `n·l`.
    pub diffuse: DVec3,
}

impl Lobes {
    const ZERO: Self = Self {
        specular: DVec3::ZERO,
        multiple: DVec3::ZERO,
        diffuse: DVec3::ZERO,
    };

    /// `specular + multiple + diffuse`.
    pub fn sum(&self) -> DVec3 {
        self.specular + self.multiple + self.diffuse
    }
}

/// `f(v, l) · (n·l)` per RGB channel, sr⁻¹: reflected radiance per unit irradiance arriving
/// from `l` on a plane facing `l` (multiply by a sun's illuminance in lux to get nits, or by
/// W m⁻² to get W m⁻² sr⁻¹).
///
/// `n, t, b` are the orthonormal shading frame (normal, tangent, bitangent; anisotropy
/// stretches along `t` when positive), `v` points toward the viewer, `l` toward the light,
/// all unit vectors. Zero when `n·v ≤ 0` or `n·l ≤ 0`: the BRDF is only defined above the
/// surface; a pass whose normal maps face away from the viewer must bend `n` itself.
///
/// Specular: `D · V · F(v·h)` with [`ggx_ndf_aniso`], [`visibility_aniso`] (height-correlated
/// Smith) and Schlick's Fresnel from [`Material::f0`] to [`Material::f90`], plus the
/// multiple-scattering lobe; diffuse: Lambert scaled by what the specular lobe leaves
/// ([`Compensation`], docs/brdf.md). Computed in `f64`.
pub fn evaluate(material: &Material, n: Vec3, t: Vec3, b: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let d = |x: Vec3| x.as_dvec3();
    evaluate_f64(material, d(n), d(t), d(b), d(v), d(l)).as_vec3()
}

/// [`evaluate`] in `f64`.
pub fn evaluate_f64(
    material: &Material,
    n: DVec3,
    t: DVec3,
    b: DVec3,
    v: DVec3,
    l: DVec3,
) -> DVec3 {
    evaluate_lobes_f64(material, n, t, b, v, l).sum()
}

/// [`evaluate_f64`] with the two lobes kept apart.
pub fn evaluate_lobes_f64(
    material: &Material,
    n: DVec3,
    t: DVec3,
    b: DVec3,
    v: DVec3,
    l: DVec3,
) -> Lobes {
    let to_local = |w: DVec3| DVec3::new(t.dot(w), b.dot(w), n.dot(w));
    let (v_loc, l_loc) = (to_local(v), to_local(l));
    if v_loc.z <= 0.0 || l_loc.z <= 0.0 {
        return Lobes::ZERO;
    }
    let h_loc = (v_loc + l_loc).normalize();
    let (ax, ay) = material.alphas();
    let f0 = material.f0();
    let spec = ggx_ndf_aniso(h_loc, ax, ay)
        * visibility_aniso(v_loc, l_loc, ax, ay)
        * fresnel_schlick_f90(f0, material.f90(), v_loc.dot(h_loc));
    let comp = Compensation::new(material);
    let ms = comp.multiple_scattering(v_loc, l_loc);
    let diff = comp.diffuse(material.diffuse_albedo(), v_loc, l_loc);
    Lobes {
        specular: spec * l_loc.z,
        multiple: ms * l_loc.z,
        diffuse: diff * l_loc.z,
    }
}

/// [`evaluate`] without a tangent frame, for isotropic materials (`anisotropy` is ignored):
/// uses [`ggx_ndf`] and [`visibility`] on cosines only, and the material's own roughness for
/// the compensation.
pub fn evaluate_isotropic(material: &Material, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let d = |x: Vec3| x.as_dvec3();
    evaluate_isotropic_f64(material, d(n), d(v), d(l)).as_vec3()
}

/// [`evaluate_isotropic`] in `f64`.
pub fn evaluate_isotropic_f64(material: &Material, n: DVec3, v: DVec3, l: DVec3) -> DVec3 {
    let (n_dot_v, n_dot_l) = (n.dot(v), n.dot(l));
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let h = (v + l).normalize();
    let alpha = material.alpha();
    let f0 = material.f0();
    let spec = ggx_ndf(n.dot(h), alpha)
        * visibility(n_dot_v, n_dot_l, alpha)
        * fresnel_schlick_f90(f0, material.f90(), v.dot(h));
    let comp = Compensation::new(&material.with_anisotropy(0.0));
    // Isotropic: only the cosines matter; any azimuth will do.
    let (wv, wl) = (polar(n_dot_v), polar(n_dot_l));
    let ms = comp.multiple_scattering(wv, wl);
    let diff = comp.diffuse(material.diffuse_albedo(), wv, wl);
    (spec + ms + diff) * n_dot_l
}

/// A unit vector at cosine `mu` from the normal, in the tangent frame's `xz` plane.
fn polar(mu: f64) -> DVec3 {
    DVec3::new(((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt(), 0.0, mu)
}
