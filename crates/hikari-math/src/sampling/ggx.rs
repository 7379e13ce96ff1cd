//! GGX (Trowbridge-Reitz) microfacet distribution and visible-normal sampling (Heitz 2018,
//! "Sampling the GGX Distribution of Visible Normals"). Local frame: normal = +Z;
//! `alpha` = GGX width (perceptual roughness squared).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Normal distribution `D(h)` for anisotropic widths, per steradian of microfacet normal.
pub fn ggx_d(h: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let t = (h.x / alpha_x).powi(2) + (h.y / alpha_y).powi(2) + h.z * h.z;
    1.0 / (PI * alpha_x * alpha_y * t * t)
}

/// Smith masking `G1(v)` for the GGX distribution.
pub fn smith_g1(v: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if v.z <= 0.0 {
        return 0.0;
    }
    let a2 = ((v.x * alpha_x).powi(2) + (v.y * alpha_y).powi(2)) / (v.z * v.z);
    let lambda = 0.5 * (-1.0 + (1.0 + a2).sqrt());
    1.0 / (1.0 + lambda)
}

/// Density of visible normals `D_v(h) = G1(v) max(0, v·h) D(h) / v.z`, per steradian of `h`.
pub fn vndf_pdf(v: Vec3, h: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if v.z <= 0.0 {
        return 0.0;
    }
    smith_g1(v, alpha_x, alpha_y) * v.dot(h).max(0.0) * ggx_d(h, alpha_x, alpha_y) / v.z
}

/// Samples a microfacet normal visible from unit direction `v` (v.z > 0) with density
/// [`vndf_pdf`], from `u ∈ [0, 1)²` (Heitz 2018: stretch, sample the projected hemisphere,
/// unstretch).
pub fn sample_vndf(v: Vec3, alpha_x: f32, alpha_y: f32, u: Vec2) -> Vec3 {
    // View direction in the stretched (alpha = 1) configuration.
    let vh = Vec3::new(alpha_x * v.x, alpha_y * v.y, v.z).normalize();
    // Orthonormal basis around vh; degenerate at normal incidence, where any tangent works.
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    // Uniform disk point, warped so the disk's upper half shrinks with the visible projection.
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha_x * nh.x, alpha_y * nh.y, nh.z.max(0.0)).normalize()
}
