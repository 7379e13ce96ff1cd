//! CPU twin of `direct_lighting.shade`, built on hikari-math's BRDF (f64 inside) rather than a
//! transcription of the shader, so the two agree only if both are right.

use glam::{Vec3, Vec4};
use hikari_math::brdf::{self, Material};

use crate::reference::octahedral;
use crate::scene_gpu::LightGpu;
use crate::techniques::direct_lighting::{
    LIGHTING_EMISSIVE, LIGHTING_PLACEHOLDER_AMBIENT, LIGHTING_PUNCTUAL, LIGHTING_SUN,
    LightingParams,
};

const MAX_RADIANCE: f32 = 65000.0;

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

pub fn sky_placeholder(p: &LightingParams, dir: Vec3) -> Vec3 {
    let t = dir.y.clamp(0.0, 1.0);
    v3(p.sky_horizon).lerp(v3(p.sky_zenith), t.sqrt())
}

pub fn ambient_placeholder(p: &LightingParams, n: Vec3) -> Vec3 {
    let l = 0.5 * (v3(p.sky_zenith) + v3(p.sky_horizon));
    std::f32::consts::PI * l * 0.5 * (1.0 + n.y)
}

pub fn specular_placeholder(p: &LightingParams, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    let r = 2.0 * n.dot(v) * n - v;
    let mean = 0.5 * (v3(p.sky_zenith) + v3(p.sky_horizon));
    let env = if r.y > 0.0 {
        sky_placeholder(p, r).lerp(mean, m.perceptual_roughness)
    } else {
        Vec3::ZERO
    };
    let f0 = brdf::material::f0_from_metalness(m.base_color.as_dvec3(), m.metalness as f64);
    brdf::fresnel::fresnel_schlick(f0, n.dot(v).max(0.0) as f64).as_vec3() * env
}

/// Where the light's illuminance falls to the frame's cutoff, or its own range if nearer.
pub fn light_range(p: &LightingParams, light: &LightGpu) -> f32 {
    let peak = v3(light.intensity).max_element();
    light.position_range[3]
        .min((peak / p.cutoff[0]).sqrt())
        .max(1e-3)
}

/// Illuminance per candela of a punctual light `d2` metres squared away in direction `l`
/// (unit, surface to light): inverse square, the range window, the spot cone.
pub fn light_attenuation(p: &LightingParams, light: &LightGpu, l: Vec3, d2: f32) -> f32 {
    let range = light_range(p, light);
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

/// A G-buffer texel as the lighting pass reads it.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    pub depth: f32,
    pub normal: Vec4,
    pub albedo: Vec4,
    pub material: Vec4,
    pub emissive: Vec3,
}

/// Radiance of one pixel. `world` is the surface point, `v` the unit vector to the camera
/// (for the sky, `-v` is the view direction), `sun_visibility` the shadow lookup's result.
pub fn shade(
    p: &LightingParams,
    lights: &[LightGpu],
    texel: &Texel,
    world: Vec3,
    v: Vec3,
    sun_visibility: f32,
) -> Vec3 {
    let flags = p.config[1];
    if texel.depth <= 0.0 {
        return if flags & LIGHTING_PLACEHOLDER_AMBIENT != 0 {
            clamp(sky_placeholder(p, -v))
        } else {
            Vec3::ZERO
        };
    }
    let n = octahedral::decode(texel.normal.truncate().truncate());
    let ta = octahedral::decode(glam::Vec2::new(texel.normal.z, texel.normal.w));
    let t = (ta - n * n.dot(ta)).normalize();
    let b = n.cross(t);
    let m = Material {
        base_color: texel.albedo.truncate(),
        perceptual_roughness: texel.material.x,
        metalness: texel.material.y,
        anisotropy: texel.material.z,
    };
    let mut radiance = Vec3::ZERO;
    let lux = p.direction_lux[3];
    if flags & LIGHTING_SUN != 0 && lux > 0.0 {
        let l = v3(p.direction_lux);
        radiance += brdf::evaluate(&m, n, t, b, v, l) * v3(p.color) * lux * sun_visibility;
    }
    if flags & LIGHTING_PUNCTUAL != 0 {
        for light in lights.iter().take(p.config[0] as usize) {
            let to_light = v3(light.position_range) - world;
            let d2 = to_light.length_squared();
            let l = to_light / d2.max(1e-8).sqrt();
            radiance += brdf::evaluate(&m, n, t, b, v, l)
                * v3(light.intensity)
                * light_attenuation(p, light, l, d2);
        }
    }
    if flags & LIGHTING_PLACEHOLDER_AMBIENT != 0 {
        let diffuse =
            m.base_color * (1.0 - m.metalness) / std::f32::consts::PI * ambient_placeholder(p, n);
        radiance += (diffuse + specular_placeholder(p, &m, n, v)) * texel.material.w;
    }
    if flags & LIGHTING_EMISSIVE != 0 {
        radiance += texel.emissive;
    }
    clamp(radiance)
}

pub fn clamp(r: Vec3) -> Vec3 {
    Vec3::from_array(
        r.to_array()
            .map(|c| if c >= 0.0 { c.min(MAX_RADIANCE) } else { 0.0 }),
    )
}
