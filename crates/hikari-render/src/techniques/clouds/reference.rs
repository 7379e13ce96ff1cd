//! CPU twin of the clouds: the density (hash, value noise, fBm, coverage, profile, octave
//! fading), the paraboloid mapping, one map texel's march (`clouds.march`), the shadow and the
//! composite over the sky (`hikari::clouds`). Same names as the WGSL, f32 as the GPU.

use glam::{Vec2, Vec3, Vec4};

use crate::reference::phase::hg_phase;

use super::{CLOUDS_DENSITY_AA, CLOUDS_MULTIPLE, CLOUDS_ON, CLOUDS_SHADOWS, CloudParams};

const OCTAVES: u32 = 4;

pub fn cloud_hash(c: [i32; 3]) -> f32 {
    let u = c.map(|v| v as u32);
    let mut h = u[0].wrapping_mul(0x8da6_b343)
        ^ u[1].wrapping_mul(0xd816_3841)
        ^ u[2].wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / 16_777_216.0
}

pub fn cloud_value_noise(p: Vec3) -> f32 {
    let fl = p.floor();
    let i = [fl.x as i32, fl.y as i32, fl.z as i32];
    let f = p - fl;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let c = |dx: i32, dy: i32, dz: i32| cloud_hash([i[0] + dx, i[1] + dy, i[2] + dz]);
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = mix(c(0, 0, 0), c(1, 0, 0), u.x);
    let x10 = mix(c(0, 1, 0), c(1, 1, 0), u.x);
    let x01 = mix(c(0, 0, 1), c(1, 0, 1), u.x);
    let x11 = mix(c(0, 1, 1), c(1, 1, 1), u.x);
    mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z)
}

/// Extinction (1/m) at world `xz`, `height` above the ground, for a footprint of `footprint` m.
pub fn cloud_density(p: &CloudParams, xz: Vec2, height: f32, footprint: f32) -> f32 {
    let h = (height - p.layer[0]) / (p.layer[1] - p.layer[0]);
    if h <= 0.0 || h >= 1.0 {
        return 0.0;
    }
    let profile = (h * 5.0).clamp(0.0, 1.0) * ((1.0 - h) * 2.5).clamp(0.0, 1.0);
    let q = Vec3::new(xz.x - p.offset[0], height, xz.y - p.offset[1]) * p.shape[2];
    let (mut sum, mut norm, mut amp, mut freq) = (0.0f32, 0.0f32, 1.0f32, 1.0f32);
    let aa = p.march[3] & CLOUDS_DENSITY_AA != 0;
    for o in 0..OCTAVES {
        let keep = if aa {
            let period = 1.0 / (p.shape[2] * freq);
            (period / (2.0 * footprint.max(1e-3)) - 0.5).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let v = cloud_value_noise(q * freq + Vec3::splat(o as f32 * 17.0));
        sum += amp * (0.5 + (v - 0.5) * keep);
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    let n = sum / norm;
    let cover = ((n - (1.0 - p.shape[0])) * 4.0).clamp(0.0, 1.0);
    p.shape[1] * cover * profile
}

pub fn cloud_map_uv(d: Vec3) -> Vec2 {
    Vec2::new(d.x, d.z) / (1.0 + d.y.max(0.0)) * 0.5 + 0.5
}

pub fn cloud_map_dir(uv: Vec2) -> Vec3 {
    let q = uv * 2.0 - 1.0;
    let r2 = q.length_squared();
    (Vec3::new(2.0 * q.x, 1.0 - r2, 2.0 * q.y) / (1.0 + r2)).normalize()
}

pub fn cloud_sphere_exit(r0: f32, mu: f32, r: f32) -> f32 {
    let b = r0 * mu;
    let disc = b * b - r0 * r0 + r * r;
    if disc < 0.0 { -1.0 } else { -b + disc.sqrt() }
}

/// `clouds.march` of texel `(x, y)`: (Mie per lux, per unit sky radiance, transmittance, 1).
pub fn march_texel(p: &CloudParams, x: u32, y: u32) -> Vec4 {
    let size = p.march[2];
    let uv = (Vec2::new(x as f32, y as f32) + 0.5) / size as f32;
    let q = uv * 2.0 - 1.0;
    if q.length_squared() > 1.0 {
        return Vec4::new(0.0, 0.0, 1.0, 1.0);
    }
    let d = cloud_map_dir(uv);
    let re = p.layer[2];
    let r0 = re + p.layer[3];
    let t_in = cloud_sphere_exit(r0, d.y, re + p.layer[0]).max(0.0);
    let t_out = cloud_sphere_exit(r0, d.y, re + p.layer[1]).min(t_in + p.offset[2]);
    let (steps, light_steps) = (p.march[0], p.march[1]);
    let dt = (t_out - t_in).max(0.0) / steps as f32;
    let texel_angle = (1.0 + d.y) * 2.0 / size as f32;
    let s = Vec3::from_slice(&p.sun[..3]);
    let cos_theta = d.dot(s);
    let fwd = hg_phase(cos_theta, p.phase[0]);
    let back = hg_phase(cos_theta, p.phase[1]) * p.phase[2];
    let (mut transmittance, mut mie, mut ambient) = (1.0f32, 0.0f32, 0.0f32);
    for i in 0..steps {
        let t = t_in + (i as f32 + 0.5) * dt;
        let pos = d * t + Vec3::new(0.0, r0, 0.0);
        let r = pos.length();
        let height = r - re;
        let sigma = cloud_density(
            p,
            Vec2::new(pos.x, pos.z),
            height,
            (texel_angle * t).max(dt),
        );
        if sigma <= 0.0 {
            continue;
        }
        let seg = (-sigma * dt).exp();
        let mut light = 0.0;
        let mut tau = 0.0f32;
        if p.sun[3] > 0.0 {
            let up = pos.dot(s) / r;
            let l_len = cloud_sphere_exit(r, up, re + p.layer[1])
                .max(0.0)
                .min(4.0 * (p.layer[1] - p.layer[0]));
            let dl = l_len / light_steps as f32;
            for j in 0..light_steps {
                let lp = pos + s * ((j as f32 + 0.5) * dl);
                tau += cloud_density(p, Vec2::new(lp.x, lp.z), lp.length() - re, dl) * dl;
            }
            light = (-tau).exp();
        }
        let phase = back + (fwd - back) * (light * seg);
        let weight = transmittance * p.shape[3] * (1.0 - seg);
        let mut sun = light * phase;
        if p.march[3] & CLOUDS_MULTIPLE != 0 && p.sun[3] > 0.0 {
            sun += (0.5 * (-0.25 * tau).exp() + 0.25 * (-0.0625 * tau).exp())
                / (4.0 * std::f32::consts::PI);
        }
        mie += weight * sun;
        let h = ((height - p.layer[0]) / (p.layer[1] - p.layer[0])).clamp(0.0, 1.0);
        ambient += weight * (0.3 + 0.7 * h);
        transmittance *= seg;
        if transmittance < 1e-3 {
            break;
        }
    }
    Vec4::new(mie, ambient, transmittance, 1.0)
}

/// The whole map, row-major.
pub fn march_map(p: &CloudParams) -> Vec<Vec4> {
    let n = p.march[2];
    (0..n * n).map(|i| march_texel(p, i % n, i / n)).collect()
}

/// Sun transmittance through the layer above world `pos`.
pub fn cloud_shadow_at(p: &CloudParams, pos: Vec3) -> f32 {
    let both = CLOUDS_ON | CLOUDS_SHADOWS;
    if p.march[3] & both != both || p.sun[3] == 0.0 {
        return 1.0;
    }
    let s = Vec3::from_slice(&p.sun[..3]);
    let sy = s.y.max(0.05);
    let t0 = (p.layer[0] - pos.y).max(0.0) / sy;
    let t1 = (p.layer[1] - pos.y).max(0.0) / sy;
    if t1 <= t0 {
        return 1.0;
    }
    let dt = (t1 - t0) / 4.0;
    let mut tau = 0.0;
    for i in 0..4 {
        let t = t0 + (i as f32 + 0.5) * dt;
        let x = pos + s * t;
        tau += cloud_density(p, Vec2::new(x.x, x.z), pos.y + sy * t, dt) * dt;
    }
    (-tau).exp()
}

/// `clouds.shadow_map`: `cloud_shadow_at` at each texel's centre on the layer's base, row-major
/// (`p.shadow` places it; empty without a map).
pub fn shadow_map(p: &CloudParams) -> Vec<f32> {
    let n = p.shadow[3] as u32;
    (0..n * n)
        .map(|i| {
            let c = Vec2::new((i % n) as f32, (i / n) as f32) + 0.5;
            let xz = Vec2::new(p.shadow[0], p.shadow[1]) + c * p.shadow[2];
            cloud_shadow_at(p, Vec3::new(xz.x, p.layer[0], xz.y))
        })
        .collect()
}

/// `cloud_shadow` (lookup.wgsl): the shadow map `map` (of [`shadow_map`]) blended between
/// the four texel centres around where the path from `pos` to the sun enters the layer, or
/// [`cloud_shadow_at`] where that is outside the map or there is none.
pub fn cloud_shadow(p: &CloudParams, map: &[f32], pos: Vec3) -> f32 {
    // `CloudParams::with_shadow_map` places a map only with shadows on and a lit sun.
    let n = p.shadow[3];
    if n > 0.0
        && let Some(entry) = super::shadow_entry(p, pos)
    {
        let c = (entry - Vec2::new(p.shadow[0], p.shadow[1])) / p.shadow[2] - 0.5;
        if c.x >= 0.0 && c.y >= 0.0 && c.x < n - 1.0 && c.y < n - 1.0 {
            let (i, j) = (c.x as usize, c.y as usize);
            let f = c - Vec2::new(i as f32, j as f32);
            let at = |x: usize, y: usize| map[y * n as usize + x];
            let top = at(i, j) + (at(i + 1, j) - at(i, j)) * f.x;
            let bottom = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * f.x;
            return top + (bottom - top) * f.y;
        }
    }
    cloud_shadow_at(p, pos)
}

/// Bilinear, clamped sample of the row-major `map` at `uv`.
pub fn sample_map(p: &CloudParams, map: &[Vec4], uv: Vec2) -> Vec4 {
    let n = p.march[2] as i32;
    let c = uv * n as f32 - 0.5;
    let fl = c.floor();
    let f = c - fl;
    let at = |x: i32, y: i32| map[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
    let (x, y) = (fl.x as i32, fl.y as i32);
    let top = at(x, y).lerp(at(x + 1, y), f.x);
    let bottom = at(x, y + 1).lerp(at(x + 1, y + 1), f.x);
    top.lerp(bottom, f.y)
}

/// `clouds_over_sky`: `background` seen through the clouds towards `dir`.
pub fn clouds_over_sky(
    p: &CloudParams,
    map: &[Vec4],
    dir: Vec3,
    background: Vec3,
    sun_lux: Vec3,
    sky_radiance: Vec3,
) -> Vec3 {
    if p.march[3] & CLOUDS_ON == 0 || dir.y <= 0.0 {
        return background;
    }
    let c = sample_map(p, map, cloud_map_uv(dir));
    let fade = (dir.y / 0.035).clamp(0.0, 1.0);
    let t = 1.0 + (c.z.clamp(0.0, 1.0) - 1.0) * fade;
    background * t + (sun_lux * c.x + sky_radiance * c.y) * fade
}
