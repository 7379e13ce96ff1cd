//! CPU twin of `area_lights.shade`: the polygon integration in f64, the BRDF from
//! hikari-math (f64), the shader's picks of lights for the shadow-ray budget (the same hash,
//! in the same order), shadow rays through hikari-bvh's CPU traversal of the same BVH, with
//! the shader's sample pattern.

use glam::{Vec2, Vec3};
use hikari_bvh::{Blas, Ray, Tlas};
use hikari_math::brdf::{self, Material};

use super::settings::{MAX_LIGHTS_PER_PIXEL, MAX_SHADOW_PICKS};
use super::{AREA_POLYGONS, AREA_PUNCTUAL, AreaLightParams};
use crate::lights::polygon::{AREA_LIGHT_DOUBLE_SIDED, AREA_LIGHT_FORCED, PolygonLights};
use crate::lights::reference::{area_light_reach, light_attenuation, light_vector_irradiance};
use crate::reference::lighting::{Texel, clamp};
use crate::reference::octahedral;
use crate::scene::upload::LightGpu;

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

fn luminance(c: Vec3) -> f32 {
    hikari_math::color::luminance(c)
}

/// The shader's sample `i` of `pixel` under the frame rotation `rotation` (R2 sequence, shifted
/// by interleaved gradient noise and the rotation), in f32 as the shader computes it.
pub fn sample_2d(pixel: [u32; 2], i: u32, rotation: [f32; 4]) -> Vec2 {
    let fract = |x: f32| x - x.floor();
    let (x, y) = (pixel[0] as f32, pixel[1] as f32);
    let ign = fract(52.982_92 * fract(0.067_110_56 * x + 0.005_837_15 * y));
    let ign2 = fract(52.982_92 * fract(0.067_110_56 * (x + 5.0) + 0.005_837_15 * (y + 7.0)));
    let r2 = Vec2::new(fract(i as f32 * 0.754_877_7), fract(i as f32 * 0.569_840_3));
    let s = r2 + Vec2::new(ign, ign2) + Vec2::new(rotation[0], rotation[1]);
    Vec2::new(fract(s.x), fract(s.y))
}

/// The shader's `pcg` hash (O'Neill's PCG output permutation).
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The shader's offset in [0, 1) of the pixel's picks in frame `frame`
/// (`AreaLightParams::config[2]`): a hash of the pixel plus the frame times the golden ratio,
/// in 32-bit fixed point.
pub fn pick_offset(frame: u32, pixel: [u32; 2]) -> f32 {
    let h =
        pcg(pixel[0] ^ pcg(pixel[1] ^ 0x5bd1_e995)).wrapping_add(frame.wrapping_mul(2_654_435_769));
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// A pick's key for point or spot light `i` (area light `i`'s key is `i`).
pub const PUNCTUAL_KEY: u32 = 0x8000_0000;

/// One light's unshadowed light at a pixel, in the order the shader offers them to the picks
/// (the selected area lights largest score first, then point and spot lights by index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightShare {
    /// Area light index, or point or spot light index | [`PUNCTUAL_KEY`].
    pub key: u32,
    /// Radiance it brings unshadowed, nits.
    pub radiance: Vec3,
    /// Illuminance it brings unshadowed, lux.
    pub lux: f32,
}

/// What the twin computes at one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shaded {
    /// Radiance, nits (the texture's rgb).
    pub radiance: Vec3,
    /// Illuminance, lux, shadowed (the texture's alpha).
    pub lux: f32,
    /// Shadow rays traced through the BVH.
    pub rays: u32,
}

/// The scene as the twin traces it: the BVH of `AreaLightScene` (BLAS per mesh, a TLAS over
/// [`super::shadow_casters`]) and the cut-out test.
pub struct TwinScene<'a> {
    pub blases: &'a [Blas],
    pub tlas: &'a Tlas,
    pub accept: &'a dyn Fn(u32, u32, f32, f32) -> bool,
}

impl TwinScene<'_> {
    fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let ray = Ray::new(origin, dir, 0.0, t_max);
        self.tlas
            .any_hit_filtered(self.blases, &ray, |i, p, u, v| (self.accept)(i, p, u, v))
    }
}

struct Frame {
    n: Vec3,
    t: Vec3,
    b: Vec3,
    v: Vec3,
    m: Material,
}

impl Frame {
    /// (specular, diffuse + multiple scattering) of `hikari_math::brdf` towards `l`, each
    /// divided by n·l: the BRDF, sr⁻¹.
    fn lobes(&self, l: Vec3) -> (Vec3, Vec3) {
        let d = |x: Vec3| x.as_dvec3();
        let lobes =
            brdf::evaluate_lobes_f64(&self.m, d(self.n), d(self.t), d(self.b), d(self.v), d(l));
        let cos = (self.n.dot(l) as f64).max(1e-4);
        (
            (lobes.specular / cos).as_vec3(),
            ((lobes.diffuse + lobes.multiple) / cos).as_vec3(),
        )
    }
}

/// Radiance of one pixel (nits): `texel` the G-buffer's, `world` its surface point, `eye` the
/// camera position. Zero where the G-buffer is empty or the pass is off.
#[allow(clippy::too_many_arguments)]
pub fn shade(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    scene: &TwinScene,
    pixel: [u32; 2],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
) -> Vec3 {
    shade_with_lux(p, lights, punctual, scene, pixel, texel, world, eye).0
}

/// The BRDF frame at a pixel and the shadow rays' origin.
fn pixel_frame(texel: &Texel, world: Vec3, eye: Vec3) -> (Frame, Vec3) {
    let n = octahedral::decode(texel.normal.truncate().truncate());
    let ta = octahedral::decode(Vec2::new(texel.normal.z, texel.normal.w));
    let t = (ta - n * n.dot(ta)).normalize();
    let f = Frame {
        n,
        t,
        b: n.cross(t),
        v: (eye - world).normalize(),
        m: Material {
            base_color: texel.albedo.truncate(),
            perceptual_roughness: texel.material.x,
            metalness: texel.material.y,
            anisotropy: texel.material.z,
            specular: texel.emissive.w,
        },
    };
    let origin = world + n * (1e-3 + 1e-3 * (eye - world).length());
    (f, origin)
}

/// Radiance of one pixel (nits) and the illuminance in lux the lights bring to the surface,
/// shadowed (the texture's alpha, for the exposure meter).
#[allow(clippy::too_many_arguments)]
pub fn shade_with_lux(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    scene: &TwinScene,
    pixel: [u32; 2],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
) -> (Vec3, f32) {
    let s = shade_counted(p, lights, punctual, scene, pixel, texel, world, eye);
    (s.radiance, s.lux)
}

/// [`shade_with_lux`], and the shadow rays it traced: the shader's estimator step by step.
#[allow(clippy::too_many_arguments)]
pub fn shade_counted(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    scene: &TwinScene,
    pixel: [u32; 2],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
) -> Shaded {
    if texel.depth <= 0.0 || p.config[1] == 0 {
        return Shaded::default();
    }
    let (f, origin) = pixel_frame(texel, world, eye);
    let shares = light_shares(p, lights, punctual, world, &f);
    let mut out = shares.iter().map(|s| s.radiance).sum::<Vec3>();
    let mut lux = shares.iter().map(|s| s.lux).sum::<f32>();
    // The picks: systematic sampling of the lights by weight, in the shader's order, pick s at
    // (s + offset) W / picks along the running sum; rounding's leftovers to the last light.
    let picks = p.counts[2].min(MAX_SHADOW_PICKS) as usize;
    let mut keys = [None::<usize>; MAX_SHADOW_PICKS as usize];
    let weights: Vec<f32> = shares
        .iter()
        .map(|s| luminance(s.radiance))
        .map(|w| if w > 0.0 { w } else { 0.0 })
        .collect();
    let total = weights.iter().fold(0.0f32, |t, &w| t + w);
    let step = total / picks.max(1) as f32;
    let offset = pick_offset(p.config[2], pixel);
    let (mut cum, mut last) = (0.0f32, None);
    for (j, &w) in weights.iter().enumerate() {
        if w <= 0.0 {
            continue;
        }
        cum += w;
        last = Some(j);
        for (s, slot) in keys.iter_mut().enumerate().take(picks) {
            if slot.is_none() && (s as f32 + offset) * step < cum {
                *slot = Some(j);
            }
        }
    }
    for slot in keys.iter_mut().take(picks) {
        if slot.is_none() {
            *slot = last;
        }
    }
    let mut rays = 0;
    if picks > 0 && total > 0.0 {
        let mut nd = [(0.0f32, 0.0f32); MAX_SHADOW_PICKS as usize];
        for s in 0..picks {
            let Some(j) = keys[s] else { continue };
            let (first, count) = p.pick_rays(s as u32);
            for r in first..first + count {
                let (num, den, traced) = shadow_ray(
                    p,
                    lights,
                    punctual,
                    scene,
                    shares[j].key,
                    r,
                    pixel,
                    origin,
                    f.n,
                );
                nd[s].0 += num;
                nd[s].1 += den;
                rays += traced as u32;
            }
        }
        let mut shadowed = (Vec3::ZERO, 0.0f32);
        for s in 0..picks {
            let Some(j) = keys[s] else { continue };
            let (nn, dd) = (0..picks)
                .filter(|&q| keys[q] == Some(j))
                .fold((0.0, 0.0), |a, q| (a.0 + nd[q].0, a.1 + nd[q].1));
            let vis = if dd > 0.0 { nn / dd } else { 1.0 };
            let w = luminance(shares[j].radiance);
            shadowed.0 += vis * (shares[j].radiance / w);
            shadowed.1 += vis * (shares[j].lux / w);
        }
        out = shadowed.0 * (total / picks as f32);
        lux = shadowed.1 * (total / picks as f32);
    }
    let lux = if lux >= 0.0 { lux.min(65000.0) } else { 0.0 };
    Shaded {
        radiance: clamp(out),
        lux,
        rays,
    }
}

/// The light without a budget: every light the pixel shades times its own visibility, the
/// ratio estimator over `rays_per_light` rays (the shader's pattern, rays 0, 1, ...). With many
/// rays, what the budgeted estimator's mean over frames must tend to.
#[allow(clippy::too_many_arguments)]
pub fn shade_unbudgeted(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    scene: &TwinScene,
    pixel: [u32; 2],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
    rays_per_light: u32,
) -> (Vec3, f32) {
    if texel.depth <= 0.0 || p.config[1] == 0 {
        return (Vec3::ZERO, 0.0);
    }
    let (f, origin) = pixel_frame(texel, world, eye);
    let (mut out, mut lux) = (Vec3::ZERO, 0.0);
    for share in light_shares(p, lights, punctual, world, &f) {
        let (mut num, mut den) = (0.0, 0.0);
        for r in 0..rays_per_light {
            let (a, b, _) =
                shadow_ray(p, lights, punctual, scene, share.key, r, pixel, origin, f.n);
            num += a;
            den += b;
        }
        let vis = if den > 0.0 { num / den } else { 1.0 };
        out += share.radiance * vis;
        lux += share.lux * vis;
    }
    (clamp(out), lux.clamp(0.0, 65000.0))
}

/// A pixel's light without shadows, (radiance in nits, illuminance in lux): the pass's
/// `area_lights.unshadowed`, the sum of [`pixel_shares`].
pub fn shade_unshadowed(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
) -> (Vec3, f32) {
    pixel_shares(p, lights, punctual, texel, world, eye)
        .iter()
        .fold((Vec3::ZERO, 0.0), |(r, e), s| (r + s.radiance, e + s.lux))
}

/// The lights a pixel shades, unshadowed, in the shader's order (see [`LightShare`]).
pub fn pixel_shares(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    texel: &Texel,
    world: Vec3,
    eye: Vec3,
) -> Vec<LightShare> {
    if texel.depth <= 0.0 || p.config[1] == 0 {
        return Vec::new();
    }
    let (f, _) = pixel_frame(texel, world, eye);
    light_shares(p, lights, punctual, world, &f)
}

fn light_shares(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    world: Vec3,
    f: &Frame,
) -> Vec<LightShare> {
    let flags = p.config[1];
    let n = f.n;
    let mut out = Vec::new();
    if flags & AREA_POLYGONS != 0 {
        let keep = p.counts[1].min(MAX_LIGHTS_PER_PIXEL) as usize;
        let mut scored: Vec<(f32, usize)> = Vec::new();
        for (i, l) in lights.lights.iter().enumerate().take(p.config[0] as usize) {
            if l.radiance_flux[3] < p.values[0] && l.range[2] & AREA_LIGHT_FORCED == 0 {
                continue;
            }
            let to_c = v3(l.centroid_radius) - world;
            let r = l.centroid_radius[3];
            if to_c.dot(n) < -r {
                continue;
            }
            let nl = v3(l.normal_area);
            if l.range[2] & AREA_LIGHT_DOUBLE_SIDED == 0
                && nl.length() > 0.99
                && (-to_c).dot(nl) < -r
            {
                continue;
            }
            // Beyond the distance where its illuminance must be below the cut-off (the
            // shader culls per tile with the same bound).
            if to_c.length() >= area_light_reach(l, p.values[2]) {
                continue;
            }
            let s = l.radiance_flux[3] / to_c.length_squared().max(r * r);
            if s > 0.0 {
                scored.push((s, i));
            }
        }
        // Largest first; ties keep the lower index, as the shader's insertion does.
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        for &(_, i) in scored.iter().take(keep) {
            if let Some((radiance, lux)) = area_light_share(lights, i, world, f) {
                out.push(LightShare {
                    key: i as u32,
                    radiance,
                    lux,
                });
            }
        }
    }
    if flags & AREA_PUNCTUAL != 0 {
        for (i, light) in punctual.iter().enumerate().take(p.config[3] as usize) {
            let to_light = v3(light.position_range) - world;
            let d2 = to_light.length_squared();
            let l = to_light / d2.max(1e-8).sqrt();
            let e = v3(light.intensity) * light_attenuation(p.values[2], light, l, d2);
            if luminance(e).is_nan() || luminance(e) <= 0.0 {
                continue;
            }
            let (s, d) = f.lobes(l);
            out.push(LightShare {
                key: i as u32 | PUNCTUAL_KEY,
                radiance: (s + d) * e * n.dot(l).max(0.0),
                lux: luminance(e) * n.dot(l).max(0.0),
            });
        }
    }
    out
}

fn orthonormal(n: Vec3) -> Vec3 {
    let a = if n.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
    n.cross(a).normalize()
}

/// The shader's `shadow_ray`: ray `r` of the pixel towards the light of `key`, as (its weight
/// if unblocked, its weight, whether it was traced).
#[allow(clippy::too_many_arguments)]
fn shadow_ray(
    p: &AreaLightParams,
    lights: &PolygonLights,
    punctual: &[LightGpu],
    scene: &TwinScene,
    key: u32,
    r: u32,
    pixel: [u32; 2],
    origin: Vec3,
    n: Vec3,
) -> (f32, f32, bool) {
    if key & PUNCTUAL_KEY != 0 {
        let light = &punctual[(key & !PUNCTUAL_KEY) as usize];
        let pos = v3(light.position_range);
        let axis = (pos - origin).normalize();
        let t = orthonormal(axis);
        let b = axis.cross(t);
        let u = sample_2d(pixel, 64 + r, p.rotation);
        let radius = if light.spot[2] >= 0.0 {
            light.spot[2]
        } else {
            p.values[1]
        };
        let rho = radius * u.x.sqrt();
        let phi = 2.0 * std::f32::consts::PI * u.y;
        let q = pos + rho * (phi.cos() * t + phi.sin() * b);
        let dist = (q - origin).length();
        let blocked = scene.occluded(origin, (q - origin) / dist.max(1e-6), dist * (1.0 - 1e-3));
        return (if blocked { 0.0 } else { 1.0 }, 1.0, true);
    }
    let i = key as usize;
    let light = &lights.lights[i];
    let tris = lights.triangles_of(i);
    let double_sided = light.range[2] & AREA_LIGHT_DOUBLE_SIDED != 0;
    let u = sample_2d(pixel, r, p.rotation);
    let mut j = 0;
    let mut lo = 0.0;
    while u.x > tris[j].p0_cdf[3] && j + 1 < tris.len() {
        lo = tris[j].p0_cdf[3];
        j += 1;
    }
    let tri = &tris[j];
    let hi = tri.p0_cdf[3];
    let ux = ((u.x - lo) / (hi - lo).max(1e-12)).clamp(0.0, 1.0);
    let su = ux.sqrt();
    let (p0, p1, p2) = (v3(tri.p0_cdf), v3(tri.p1), v3(tri.p2));
    let q = p0 * (1.0 - su) + p1 * (su * (1.0 - u.y)) + p2 * (su * u.y);
    let dist = (q - origin).length();
    if dist.is_nan() || dist <= 1e-6 {
        return (0.0, 0.0, false);
    }
    let dir = (q - origin) / dist;
    let ng = (p1 - p0).cross(p2 - p0).normalize();
    let mut cos_l = -dir.dot(ng);
    if double_sided {
        cos_l = cos_l.abs();
    }
    let w = dir.dot(n).max(0.0) * cos_l.max(0.0) / (dist * dist);
    if w.is_nan() || w <= 0.0 {
        return (0.0, 0.0, false);
    }
    let blocked = scene.occluded(origin, dir, dist * (1.0 - 1e-3));
    let f = texture_factor(
        lights,
        i,
        j,
        Vec3::new(1.0 - su, su * (1.0 - u.y), su * u.y),
    );
    (if blocked { 0.0 } else { w * f }, w, true)
}

/// shade.wgsl's `texture_factor`: light `i`'s emissive texture luminance at barycentrics `b`
/// of its triangle `j` over the texture's mean, 1 untextured. The GPU reads the scene's sRGB
/// array, where the image may be resampled to the array's layer size; this reads the image.
pub fn texture_factor(lights: &PolygonLights, i: usize, j: usize, b: Vec3) -> f32 {
    let Some(Some(tex)) = lights.textures.get(i) else {
        return 1.0;
    };
    let k = 2 * (lights.lights[i].range[0] as usize + j);
    let (Some(a), Some(c)) = (lights.uvs.get(k), lights.uvs.get(k + 1)) else {
        return 1.0;
    };
    let uv = glam::Vec2::new(a[0], a[1]) * b.x
        + glam::Vec2::new(a[2], a[3]) * b.y
        + glam::Vec2::new(c[0], c[1]) * b.z;
    tex.sample(uv) * c[2]
}

/// Area light `i`'s unshadowed (radiance, lux) at `world`, or `None` where it brings none.
fn area_light_share(
    lights: &PolygonLights,
    i: usize,
    world: Vec3,
    f: &Frame,
) -> Option<(Vec3, f32)> {
    let light = &lights.lights[i];
    let double_sided = light.range[2] & AREA_LIGHT_DOUBLE_SIDED != 0;
    let n = f.n;
    let fv = light_vector_irradiance(
        lights.triangles_of(i),
        double_sided,
        world.as_dvec3(),
        n.as_dvec3(),
    );
    let e = fv.dot(n.as_dvec3()) as f32;
    if e.is_nan() || e <= 0.0 {
        return None;
    }
    let radiance = v3(light.radiance_flux) * e;
    let l_d = fv.normalize().as_vec3();
    let (_, diffuse) = f.lobes(l_d);
    // The representative point of the specular lobe (see the shader).
    let c = v3(light.centroid_radius);
    let radius = light.centroid_radius[3];
    let nl = v3(light.normal_area);
    let r = 2.0 * n.dot(f.v) * n - f.v;
    let mut q = c;
    let denom = r.dot(nl);
    if nl.length() > 0.1 && denom.abs() > 1e-6 {
        let t = (c - world).dot(nl) / denom;
        if t > 0.0 {
            q = world + r * t;
        }
    }
    let mut off = q - c;
    if nl.length() > 0.1 {
        let u = nl.normalize();
        off -= u * off.dot(u);
    }
    if off.length() > radius {
        off *= radius / off.length();
    }
    let mut l_s = (c + off - world).normalize();
    if l_s.dot(n) <= 1e-4 {
        l_s = l_d;
    }
    let (ax, ay) = f.m.alphas();
    let alpha = (ax * ay).sqrt() as f32;
    let size =
        (light.normal_area[3] / std::f32::consts::PI).sqrt() / (c - world).length().max(1e-4);
    let widened = (alpha + 0.5 * size).min(1.0);
    let norm = (alpha / widened).powi(2);
    let (specular, _) = f.lobes(l_s);
    Some(((specular * norm + diffuse) * radiance, luminance(radiance)))
}

// The shadow denoiser's twins (`area_lights/temporal.wgsl`, `area_lights/spatial.wgsl`), in
// f32 as the shaders compute; the GPU stores f16, which the tests' tolerances allow for.

use super::denoise::{MAX_VISIBILITY, SHADOW_DENOISE_RESET, ShadowDenoiseParams, VISIBILITY_EPS};
use crate::techniques::gi_denoiser::GiDenoiserParams;
use crate::techniques::gi_denoiser::reference as gi;
use crate::techniques::ray_traced_gi::reference::{REPROJECTION_MIN_WEIGHT, bilinear_taps};
use crate::view::View;

/// One frame of the denoiser's inputs: row-major images of `width` x `height` texels.
pub struct DenoiseInput<'a> {
    pub width: u32,
    pub height: u32,
    /// Reverse-Z depth (0 on the sky).
    pub depth: &'a [f32],
    /// The G-buffer normal's octahedral encoding (its xy).
    pub normal_oct: &'a [[f32; 2]],
    /// The G-buffer's motion: xy to last frame's pixel, z view depth (m).
    pub motion: &'a [[f32; 4]],
    /// `area_lights.radiance` and `area_lights.unshadowed`.
    pub shadowed: &'a [[f32; 4]],
    pub unshadowed: &'a [[f32; 4]],
}

/// The temporal pass's history: visibility, length (frames) and view depth per texel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VisibilityHistory {
    pub visibility: Vec<[f32; 4]>,
    pub length: Vec<f32>,
    pub view_depth: Vec<f32>,
}

fn finite4(v: [f32; 4]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Per channel, shadowed / unshadowed where the unshadowed light is defined (finite, above
/// [`VISIBILITY_EPS`]) and the shadowed finite, else 1 (the shader's `raw_visibility`).
pub fn raw_visibility(shadowed: [f32; 4], unshadowed: [f32; 4]) -> [f32; 4] {
    let ok = finite4(shadowed) && finite4(unshadowed);
    std::array::from_fn(|c| {
        if ok && unshadowed[c] > VISIBILITY_EPS {
            (shadowed[c] / unshadowed[c]).clamp(0.0, MAX_VISIBILITY)
        } else {
            1.0
        }
    })
}

/// The temporal pass: (this frame's raw visibility, the history after it). `prev`: last
/// frame's history (`None`: no valid history, as on a reset). Bilinear taps that pass the
/// tests, or where they weigh under [`REPROJECTION_MIN_WEIGHT`] the 3x3 about the nearest
/// texel that pass them, equally weighted (SVGF's fallback).
pub fn denoise_temporal(
    p: &ShadowDenoiseParams,
    view: &View,
    input: &DenoiseInput,
    prev: Option<&VisibilityHistory>,
) -> (Vec<[f32; 4]>, VisibilityHistory) {
    let (w, h) = (input.width, input.height);
    let n = (w * h) as usize;
    let mut raw = Vec::with_capacity(n);
    let mut out = VisibilityHistory::default();
    let prev_vp = glam::Mat4::from_cols_array_2d(&view.prev_view_proj);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let r = raw_visibility(input.shadowed[i], input.unshadowed[i]);
            raw.push(r);
            let d = input.depth[i];
            let (v, len, z) = 'px: {
                if !(d > 0.0 && d.is_finite()) {
                    break 'px ([1.0; 4], 0.0, 0.0);
                }
                let m = input.motion[i];
                let z = if m[2].is_finite() { m[2] } else { 0.0 };
                let world = gi::world_from_depth(view, glam::UVec2::new(x, y), d);
                let (px, py) = (x as f32 + 0.5 + m[0], y as f32 + 0.5 + m[1]);
                let Some(prev) = prev.filter(|_| p.config[0] & SHADOW_DENOISE_RESET == 0) else {
                    break 'px (r, 1.0, z);
                };
                if !(m[0].is_finite() && m[1].is_finite() && m[2].is_finite() && world.is_finite())
                    || px < 0.0
                    || py < 0.0
                    || px >= w as f32
                    || py >= h as f32
                {
                    break 'px (r, 1.0, z);
                }
                let expected = (prev_vp * world.extend(1.0)).w;
                // The history texel at (tx, ty) where it is inside, finite, has history and saw
                // this surface (written so that NaN rejects).
                let agreeing = |tx: i64, ty: i64| {
                    if tx < 0 || ty < 0 || tx >= w as i64 || ty >= h as i64 {
                        return None;
                    }
                    let j = (ty as u32 * w + tx as u32) as usize;
                    let (tv, tl, tz) = (prev.visibility[j], prev.length[j], prev.view_depth[j]);
                    let depth_ok = (tz - expected).abs() <= p.values[0] * expected.abs();
                    (finite4(tv) && tl.is_finite() && tl >= 1.0 && tz.is_finite() && depth_ok)
                        .then_some((tv, tl))
                };
                let mut taps: Vec<(([f32; 4], f32), f32)> = bilinear_taps(glam::Vec2::new(px, py))
                    .into_iter()
                    .filter(|(_, wt)| *wt > 0.0)
                    .filter_map(|([tx, ty], wt)| agreeing(tx, ty).map(|t| (t, wt)))
                    .collect();
                // SVGF's fallback: the 3x3 about the nearest texel, equally weighted.
                if taps.iter().map(|(_, wt)| wt).sum::<f32>() < REPROJECTION_MIN_WEIGHT {
                    let (qx, qy) = (px as i64, py as i64);
                    taps = (-1..=1)
                        .flat_map(|dy| (-1..=1).map(move |dx| (qx + dx, qy + dy)))
                        .filter_map(|(tx, ty)| agreeing(tx, ty).map(|t| (t, 1.0)))
                        .collect();
                    if taps.is_empty() {
                        break 'px (r, 1.0, z);
                    }
                }
                let (mut hv, mut hl, mut weight) = ([0f32; 4], 0f32, 0f32);
                for ((tv, tl), wt) in taps {
                    for c in 0..4 {
                        hv[c] += wt * tv[c];
                    }
                    hl += wt * tl;
                    weight += wt;
                }
                let hv: [f32; 4] = std::array::from_fn(|c| hv[c] / weight);
                let hl = hl / weight;
                let len = (hl + 1.0).min(p.config[1].max(1) as f32);
                let k = 1.0 / len;
                (std::array::from_fn(|c| hv[c] + (r[c] - hv[c]) * k), len, z)
            };
            out.visibility.push(v);
            out.length.push(len);
            out.view_depth.push(z);
        }
    }
    (raw, out)
}

/// The spatial pass over the accumulated history `acc`: (filtered visibility, the pixel's
/// light: unshadowed x filtered visibility, or the raw shadowed light where the unshadowed is
/// below [`VISIBILITY_EPS`]).
pub fn denoise_spatial(
    p: &ShadowDenoiseParams,
    view: &View,
    input: &DenoiseInput,
    acc: &VisibilityHistory,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (w, h) = (input.width, input.height);
    let or = |v: [f32; 4], f: f32| if finite4(v) { v } else { [f; 4] };
    let plane = GiDenoiserParams {
        radius: [0.0, 0.0, 0.0, p.values[1]],
        ..bytemuck::Zeroable::zeroed()
    };
    let (mut filtered, mut light) = (Vec::new(), Vec::new());
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let v0 = or(acc.visibility[i], 1.0);
            let (s0, u0) = (or(input.shadowed[i], 0.0), or(input.unshadowed[i], 0.0));
            let mut f = v0;
            let oct = input.normal_oct[i];
            let surface = gi::make_surface(
                view,
                glam::UVec2::new(x, y),
                input.depth[i],
                Vec2::from_array(oct),
            );
            let l = acc.length[i];
            let len = if l.is_finite() { l.max(1.0) } else { 1.0 };
            let r = p.values[2] / len.sqrt();
            if let Some(s) = surface.filter(|_| r >= 0.5) {
                let reach = (r.ceil() as i32).min(super::settings::MAX_DENOISE_RADIUS_PX as i32);
                let (mut sum, mut sum_w) = ([0.0f32; 4], [0.0f32; 4]);
                for dy in -reach..=reach {
                    for dx in -reach..=reach {
                        if (dx * dx + dy * dy) as f32 > r * r {
                            continue;
                        }
                        let (qx, qy) = (x as i32 + dx, y as i32 + dy);
                        if qx < 0 || qy < 0 || qx >= w as i32 || qy >= h as i32 {
                            continue;
                        }
                        let j = (qy as u32 * w + qx as u32) as usize;
                        let dq = input.depth[j];
                        if !(dq > 0.0 && dq.is_finite()) {
                            continue;
                        }
                        let q = glam::UVec2::new(qx as u32, qy as u32);
                        let mut wt =
                            gi::geometry_weight(&s, gi::world_from_depth(view, q, dq), &plane);
                        if wt.is_nan() || wt <= 0.0 {
                            continue;
                        }
                        let o = Vec2::from_array(input.normal_oct[j]);
                        if !o.is_finite() {
                            continue;
                        }
                        wt *= s.normal.dot(octahedral::decode(o)).max(0.0);
                        if wt.is_nan() || wt <= 0.0 {
                            continue;
                        }
                        let (vq, uq) = (acc.visibility[j], input.unshadowed[j]);
                        if !finite4(vq) || !finite4(uq) {
                            continue;
                        }
                        for c in 0..4 {
                            if uq[c] > VISIBILITY_EPS {
                                sum[c] += wt * vq[c];
                                sum_w[c] += wt;
                            }
                        }
                    }
                }
                f = std::array::from_fn(|c| {
                    if sum_w[c] > 0.0 {
                        sum[c] / sum_w[c].max(1e-30)
                    } else {
                        v0[c]
                    }
                });
            }
            filtered.push(f);
            light.push(std::array::from_fn(|c| {
                let v = if u0[c] > VISIBILITY_EPS {
                    u0[c] * f[c]
                } else {
                    s0[c]
                };
                if v >= 0.0 { v.min(65000.0) } else { 0.0 }
            }));
        }
    }
    (filtered, light)
}
