//! CPU twin of the light code every lighting pass shares: `lights/area_polygon.wgsl` (a
//! polygon's vector irradiance, an area light's reach) and the attenuation of point and spot
//! lights with the frame's cut-off (`light_attenuation` of `hikari::scene_gpu`), which the
//! direct lighting, the area lights, the GI's hits, the haze and the reflection probes use.

use glam::{DVec3, Vec3};
use hikari_math::color::luminance;

use super::polygon::{AreaLightGpu, AreaTriangleGpu};
use crate::scene::upload::LightGpu;

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Lambert's vector irradiance per unit radiance (sr) of the polygon `q` (vertices relative to
/// the receiving point, wound so that its front faces the point), clipped to the hemisphere
/// around `n`: the irradiance on a surface of normal `n` is `L n·F` (Lambert 1760; Arvo 1995).
pub fn polygon_vector_irradiance(q: &[DVec3], n: DVec3) -> DVec3 {
    let mut clipped = Vec::with_capacity(q.len() + 1);
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let (da, db) = (a.dot(n), b.dot(n));
        if da >= 0.0 {
            clipped.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped.push(a + (b - a) * (da / (da - db)));
        }
    }
    if clipped.len() < 3 {
        return DVec3::ZERO;
    }
    let mut f = DVec3::ZERO;
    for i in 0..clipped.len() {
        let a = clipped[i].normalize();
        let b = clipped[(i + 1) % clipped.len()].normalize();
        let c = b.cross(a);
        let s = c.length();
        let theta = s.atan2(a.dot(b));
        f += 0.5 * if s < 1e-12 { c } else { c * (theta / s) };
    }
    f
}

/// Vector irradiance per unit radiance of a light's triangles at `world` (see
/// [`polygon_vector_irradiance`]): back faces skipped, or turned round when double-sided.
pub fn light_vector_irradiance(
    tris: &[AreaTriangleGpu],
    double_sided: bool,
    world: DVec3,
    n: DVec3,
) -> DVec3 {
    let mut f = DVec3::ZERO;
    for t in tris {
        let q0 = v3(t.p0_cdf).as_dvec3() - world;
        let mut q1 = v3(t.p1).as_dvec3() - world;
        let mut q2 = v3(t.p2).as_dvec3() - world;
        if -q0.dot((q1 - q0).cross(q2 - q0)) <= 0.0 {
            if !double_sided {
                continue;
            }
            std::mem::swap(&mut q1, &mut q2);
        }
        f += polygon_vector_irradiance(&[q0, q1, q2], n);
    }
    f
}

/// Distance (m) from an area light's centroid beyond which it brings less than `cutoff_lux`:
/// no point of it is nearer than d − r, and it brings at most L A / (d − r)².
pub fn area_light_reach(l: &AreaLightGpu, cutoff_lux: f32) -> f32 {
    let peak = luminance(v3(l.radiance_flux)) * l.normal_area[3];
    l.centroid_radius[3] + (peak.max(0.0) / cutoff_lux).sqrt()
}

/// Where a point or spot light's illuminance falls to `cutoff_lux`, or its own range if nearer.
pub fn light_range(light: &LightGpu, cutoff_lux: f32) -> f32 {
    let peak = v3(light.intensity).max_element();
    light.position_range[3]
        .min((peak / cutoff_lux).sqrt())
        .max(1e-3)
}

/// Illuminance per candela of a punctual light `d2` metres squared away in direction `l`
/// (unit, surface to light): inverse square, the range window at `cutoff_lux`, the spot cone.
pub fn light_attenuation(cutoff_lux: f32, light: &LightGpu, l: Vec3, d2: f32) -> f32 {
    let range = light_range(light, cutoff_lux);
    let x = d2 / (range * range);
    let window = (1.0 - x * x).clamp(0.0, 1.0);
    let mut a = window * window / d2.max(1e-4);
    if light.direction_kind[3] > 0.5 {
        let s =
            ((-l).dot(v3(light.direction_kind)) * light.spot[0] + light.spot[1]).clamp(0.0, 1.0);
        a *= s * s;
    }
    a
}
