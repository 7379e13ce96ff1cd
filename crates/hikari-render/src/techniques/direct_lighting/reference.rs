//! CPU twin of `direct_lighting.shade`, built on hikari-math's BRDF (f64 inside) rather than a
//! transcription of the shader, so the two agree only if both are right.

use glam::Vec3;
use hikari_math::brdf::{self, Material};
use hikari_math::sh::{Sh, zonal};

use crate::lights::reference::light_attenuation;
use crate::reference::lighting::clamp;
pub use crate::reference::lighting::{MAX_RADIANCE, Texel};
use crate::reference::octahedral;
use crate::scene::upload::LightGpu;
use crate::techniques::direct_lighting::{
    LIGHTING_EMISSIVE, LIGHTING_PLACEHOLDER_AMBIENT, LIGHTING_PROBES, LIGHTING_PUNCTUAL,
    LIGHTING_SKY, LIGHTING_SUN, LightingParams,
};
use crate::techniques::sky::reference::SkyTwin;

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
    fresnel_at(m, n, v) * env
}

/// The atmosphere's light in one frame, as the lighting pass sees it with `LIGHTING_SKY`.
pub struct SkyLight<'a> {
    /// The sky's deringed L2 SH of radiance, nits (coefficients 9..18 of the `sky.sh` buffer,
    /// hikari-math's `sh` convention).
    pub sh: Sh<Vec3, 9>,
    /// The weather's ambient balance: diffuse and specular scale (`SkyAmbientParams`).
    pub balance: [f32; 2],
    /// The sky seen where depth is 0; `None` leaves sky pixels black. The twin has no sun or
    /// moon disk, so pixels on a disk differ from the shader's.
    pub background: Option<&'a SkyTwin<'a>>,
    /// The irradiance probes' irradiance at the shaded point (lux, already times the diffuse
    /// balance), when `LIGHTING_PROBES` is set and probes cover the point
    /// (`irradiance_probes::reference::irradiance_at`); replaces the SH's diffuse term.
    pub probe_irradiance: Option<Vec3>,
}

impl SkyLight<'_> {
    /// Irradiance from the sky's SH on a surface with unit normal `n`, lux, times the diffuse
    /// balance (Ramamoorthi & Hanrahan's clamped-cosine convolution; negative lobes clamped).
    pub fn irradiance(&self, n: Vec3) -> Vec3 {
        zonal::irradiance_at(&self.sh, n).max(Vec3::ZERO) * self.balance[0]
    }

    /// Specular ambient along the mirror direction `r`: the SH's radiance there, blended with
    /// roughness towards the cosine-weighted mean (irradiance / pi), nits, times the specular
    /// balance.
    pub fn specular(&self, r: Vec3, perceptual_roughness: f32) -> Vec3 {
        let sharp = self.sh.eval(r).max(Vec3::ZERO);
        let blurred = zonal::irradiance_at(&self.sh, r).max(Vec3::ZERO) / std::f32::consts::PI;
        sharp.lerp(blurred, perceptual_roughness) * self.balance[1]
    }
}

fn fresnel_at(m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    brdf::fresnel::fresnel_schlick_f90(m.f0(), m.f90(), n.dot(v).max(0.0) as f64).as_vec3()
}

/// Radiance of one pixel. `world` is the surface point, `v` the unit vector to the camera
/// (for the sky, `-v` is the view direction), `sun_visibility` the shadow lookup's result.
/// Without the atmosphere: a frame with `LIGHTING_SKY` needs [`shade_with_sky`].
pub fn shade(
    p: &LightingParams,
    lights: &[LightGpu],
    texel: &Texel,
    world: Vec3,
    v: Vec3,
    sun_visibility: f32,
) -> Vec3 {
    shade_with_sky(p, lights, texel, world, v, sun_visibility, None)
}

/// [`shade`] with the atmosphere's light, which `LIGHTING_SKY` adds: the sky where depth is
/// 0 and the sky's SH as ambient (sky visibility 1, as the shader until the probes). With
/// `sky` `None` those terms are left out.
pub fn shade_with_sky(
    p: &LightingParams,
    lights: &[LightGpu],
    texel: &Texel,
    world: Vec3,
    v: Vec3,
    sun_visibility: f32,
    sky: Option<&SkyLight>,
) -> Vec3 {
    let flags = p.config[1];
    let sky = sky.filter(|_| flags & LIGHTING_SKY != 0);
    if texel.depth <= 0.0 {
        let mut l = if flags & LIGHTING_PLACEHOLDER_AMBIENT != 0 {
            sky_placeholder(p, -v)
        } else {
            Vec3::ZERO
        };
        if let Some(twin) = sky.and_then(|s| s.background) {
            l = twin.background_no_disks(-v);
        }
        return clamp(l);
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
        specular: texel.emissive.w,
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
                * light_attenuation(p.cutoff[0], light, l, d2);
        }
    }
    if flags & LIGHTING_PLACEHOLDER_AMBIENT != 0 {
        let diffuse =
            m.base_color * (1.0 - m.metalness) / std::f32::consts::PI * ambient_placeholder(p, n);
        radiance += (diffuse + specular_placeholder(p, &m, n, v)) * texel.material.w;
    }
    if let Some(sky) = sky {
        let ambient = match sky.probe_irradiance {
            Some(e) if flags & LIGHTING_PROBES != 0 => e,
            _ => sky.irradiance(n),
        };
        let diffuse = m.base_color * (1.0 - m.metalness) / std::f32::consts::PI * ambient;
        let r = 2.0 * n.dot(v) * n - v;
        let specular = fresnel_at(&m, n, v) * sky.specular(r, m.perceptual_roughness);
        radiance += (diffuse + specular) * texel.material.w;
    }
    if flags & LIGHTING_EMISSIVE != 0 {
        radiance += texel.emissive.truncate();
    }
    clamp(radiance)
}
