//! Mappings from the unit square to the sphere and hemisphere (z up), with their pdfs
//! (per steradian).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Uniform direction on the sphere; pdf `1 / 4π`.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform direction on the hemisphere z ≥ 0; pdf `1 / 2π`.
pub fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Cosine-weighted direction on the hemisphere z ≥ 0 (Malley: uniform disk lifted); pdf
/// `cos θ / π`.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (x, y) = (r * phi.cos(), r * phi.sin());
    Vec3::new(x, y, (1.0 - u.x).max(0.0).sqrt())
}

/// pdf of [`cosine_hemisphere`] for direction `d`, per steradian.
pub fn cosine_hemisphere_pdf(d: Vec3) -> f32 {
    d.z.max(0.0) / PI
}

/// Point `i` of an `n`-point Fibonacci (golden-angle spiral) sphere: equal-area bands in z,
/// golden-angle steps in azimuth, so every point stands for `4π / n` steradians.
pub fn fibonacci_sphere(i: u32, n: u32) -> Vec3 {
    let n = n.max(1) as f64;
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (2.0 * i as f64 + 1.0) / n;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = golden_angle * i as f64;
    glam::DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3()
}
