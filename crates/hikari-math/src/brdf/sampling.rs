//! Importance sampling of the specular lobe through its distribution of visible normals
//! (Heitz 2018), using [`crate::sampling::ggx::sample_vndf`].

use super::fresnel::fresnel_schlick_f90;
use super::ggx::ggx_ndf_aniso;
use super::material::Material;
use super::smith::{smith_g1_aniso, smith_g2_height_correlated_aniso};
use crate::sampling::ggx::sample_vndf;
use glam::{DVec3, Vec2, Vec3};

/// One sampled light direction for the specular lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularSample {
    /// Unit direction toward the light (world space), above the surface.
    pub l: Vec3,
    /// Density of `l`, per steradian: [`specular_pdf_f64`].
    pub pdf: f32,
    /// `f_spec(v, l) (n·l) / pdf = F(v·h) G2(v, l) / G1(v)`, per channel, in [0, 1].
    pub weight: Vec3,
}

/// Density per steradian of `l` when [`sample_specular`] reflects `v` about a visible normal:
/// `D_v(h) / (4 v·h) = G1(v) D(h) / (4 n·v)` (Heitz 2018; `4 v·h` is the Jacobian of the
/// reflection `dω_l = 4 (v·h) dω_h`). 0 below the horizon.
pub fn specular_pdf_f64(
    material: &Material,
    n: DVec3,
    t: DVec3,
    b: DVec3,
    v: DVec3,
    l: DVec3,
) -> f64 {
    let to_local = |w: DVec3| DVec3::new(t.dot(w), b.dot(w), n.dot(w));
    let (v_loc, l_loc) = (to_local(v), to_local(l));
    if v_loc.z <= 0.0 || l_loc.z <= 0.0 {
        return 0.0;
    }
    let h = (v_loc + l_loc).normalize();
    let (ax, ay) = material.alphas();
    smith_g1_aniso(v_loc, ax, ay) * ggx_ndf_aniso(h, ax, ay) / (4.0 * v_loc.z)
}

/// Samples `l` for the specular lobe of `material` seen from `v` (frame `n, t, b` as in
/// [`super::evaluate()`]) from `u ∈ [0, 1)²`. `None` when `v` is below the surface or the
/// reflected direction is (the sample then carries no energy: that is the single-scattering
/// loss of a rough surface).
pub fn sample_specular(
    material: &Material,
    n: Vec3,
    t: Vec3,
    b: Vec3,
    v: Vec3,
    u: Vec2,
) -> Option<SpecularSample> {
    let (n, t, b, v) = (n.as_dvec3(), t.as_dvec3(), b.as_dvec3(), v.as_dvec3());
    let v_loc = DVec3::new(t.dot(v), b.dot(v), n.dot(v));
    if v_loc.z <= 0.0 {
        return None;
    }
    let (ax, ay) = material.alphas();
    let h = sample_vndf(v_loc.as_vec3(), ax as f32, ay as f32, u)
        .as_dvec3()
        .normalize();
    let v_dot_h = v_loc.dot(h);
    let l_loc = 2.0 * v_dot_h * h - v_loc;
    if v_dot_h <= 0.0 || l_loc.z <= 0.0 {
        return None;
    }
    let pdf = smith_g1_aniso(v_loc, ax, ay) * ggx_ndf_aniso(h, ax, ay) / (4.0 * v_loc.z);
    let g = smith_g2_height_correlated_aniso(v_loc, l_loc, ax, ay) / smith_g1_aniso(v_loc, ax, ay);
    let l = t * l_loc.x + b * l_loc.y + n * l_loc.z;
    Some(SpecularSample {
        l: l.normalize().as_vec3(),
        pdf: pdf as f32,
        weight: (fresnel_schlick_f90(material.f0(), material.f90(), v_dot_h) * g).as_vec3(),
    })
}
