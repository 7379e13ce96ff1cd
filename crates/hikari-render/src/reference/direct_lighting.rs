//! CPU twin of `direct_lighting.sun`.

use glam::{Vec2, Vec3};

use super::octahedral;
use crate::passes::direct_lighting::SunParams;

const MAX_RADIANCE: f32 = 65000.0;

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

pub fn sky_placeholder(p: &SunParams, dir: Vec3) -> Vec3 {
    let t = dir.y.clamp(0.0, 1.0);
    v3(p.sky_horizon).lerp(v3(p.sky_zenith), t.sqrt())
}

pub fn ambient_placeholder(p: &SunParams, n: Vec3) -> Vec3 {
    let l = 0.5 * (v3(p.sky_zenith) + v3(p.sky_horizon));
    std::f32::consts::PI * l * 0.5 * (1.0 + n.y)
}

/// Radiance of a surface texel (encoded normal as stored in the G-buffer, base colour).
pub fn surface(p: &SunParams, normal_oct: Vec2, albedo: Vec3) -> Vec3 {
    let n = octahedral::decode(normal_oct);
    let l = v3(p.direction_lux);
    let e = v3(p.color) * p.direction_lux[3] * n.dot(l).max(0.0) + ambient_placeholder(p, n);
    clamp(albedo / std::f32::consts::PI * e)
}

pub fn clamp(r: Vec3) -> Vec3 {
    Vec3::from_array(
        r.to_array()
            .map(|c| if c >= 0.0 { c.min(MAX_RADIANCE) } else { 0.0 }),
    )
}
