//! CPU twins of the ray-traced GI passes: ray generation, the hit word's packing, the sample
//! weight, the per-instance albedo, and reprojection with temporal accumulation. The WGSL
//! twins are in `rtgi.wgsl` (`hikari::ray_traced_gi`) and `accumulate.wgsl`.

use glam::{Mat4, Vec2, Vec3, Vec4};

pub use crate::reference::reprojection::{
    REPROJECTION_MIN_WEIGHT, REPROJECTION_SNAP, bilinear_taps,
};
use hikari_math::sampling::blue_noise::{BLUE_NOISE_SIZE, blue_noise_slice};
use hikari_math::sh::ShL1;
use hikari_math::sh::ycocg::ShL1YCoCg;
use hikari_scene::{Scene, Texture};

/// Hit word of a pixel that traced nothing (sky pixel, bad G-buffer, technique stage off).
pub const HIT_NOT_TRACED: u32 = 0;
/// Hit word the pre-trace leaves for the BVH to resolve.
pub const HIT_UNRESOLVED: u32 = u32::MAX;
/// Distance bits (f16 +inf) of a ray that hit nothing within its length.
pub const DISTANCE_MISS_BITS: u32 = 0x7c00;
/// Shortest distance a hit keeps, so that distance bits 0 stay "not traced", in metres.
pub const MIN_HIT_DISTANCE: f32 = 1.0e-3;

/// The two blue-noise numbers of `pixel` in `frame`, in (0, 1): the talk's lookup, pixel
/// offset by 32 on odd frames, slice `frame & 63`; the second number is slice
/// `(frame + 32) & 63` at the same texel (the committed set is one scalar per texel).
pub fn blue_noise_2d(pixel: [u32; 2], frame: u32) -> Vec2 {
    let n = BLUE_NOISE_SIZE as u32;
    let shift = 32 * (frame & 1);
    let x = (pixel[0] + shift) & (n - 1);
    let y = (pixel[1] + shift) & (n - 1);
    let i = (y * n + x) as usize;
    let a = blue_noise_slice((frame & 63) as usize)[i];
    let b = blue_noise_slice(((frame + 32) & 63) as usize)[i];
    Vec2::new((a as f32 + 0.5) / 256.0, (b as f32 + 0.5) / 256.0)
}

/// Tangent and bitangent around unit `n` (Duff et al. 2017, branch-free, continuous except at
/// n.z = 0 where the sign flips).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// Cosine-distributed unit direction around `n` from `u` in (0,1)², and its cosine with `n`.
pub fn cosine_direction(n: Vec3, u: Vec2) -> (Vec3, f32) {
    let r = u.x.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    let z = (1.0 - u.x).max(0.0).sqrt();
    let (t, b) = basis(n);
    let d = t * (r * phi.cos()) + b * (r * phi.sin()) + n * z;
    (d.normalize(), z)
}

/// The GI ray of `pixel` in `frame` around unit normal `n`: direction and cosine.
pub fn ray_direction(pixel: [u32; 2], frame: u32, n: Vec3) -> (Vec3, f32) {
    cosine_direction(n, blue_noise_2d(pixel, frame))
}

/// Weight that turns a cosine-distributed sample into one of a uniform-hemisphere estimator,
/// which is how `ShL1YCoCg` is normalised: the pdf ratio `(1/2π) / (cos/π) = 1 / (2 cos)`,
/// averaged over the bin of the 8-bit noise value `u1` (`cos² = 1 − u1`):
/// `256 (√(1 − k/256) − √(1 − (k+1)/256))`, `k = ⌊256 u1⌋`. Its mean over the 256 values is
/// exactly 1 and it stays at most 16; at the bin's midpoint instead the grazing bins would be
/// under-weighted (mean 0.98), which biased a sky brighter at the horizon by 3 %.
pub fn uniform_weight(u1: f32) -> f32 {
    let k = (u1 * 256.0).floor().clamp(0.0, 255.0);
    256.0 * ((1.0 - k / 256.0).sqrt() - (1.0 - (k + 1.0) / 256.0).max(0.0).sqrt())
}

/// The GI ray of `pixel` in `frame` around `n`: direction and [`uniform_weight`].
pub fn ray(pixel: [u32; 2], frame: u32, n: Vec3) -> (Vec3, f32) {
    let u = blue_noise_2d(pixel, frame);
    (cosine_direction(n, u).0, uniform_weight(u.x))
}

/// Ray origin above the surface point `world` with normal `n`, seen from `camera`: pushed out
/// by 1 mm plus 0.1 % of the distance, which covers depth-reconstruction error.
pub fn ray_origin(world: Vec3, n: Vec3, camera: Vec3) -> Vec3 {
    world + n * (1.0e-3 + 1.0e-3 * (world - camera).length())
}

/// World position of the centre of `pixel` at reverse-Z depth `depth` (`hikari::view`'s
/// `world_from_depth`).
pub fn world_from_depth(inv_view_proj: Mat4, size: [u32; 2], pixel: [u32; 2], depth: f32) -> Vec3 {
    let uv = (Vec2::new(pixel[0] as f32, pixel[1] as f32) + 0.5)
        / Vec2::new(size[0] as f32, size[1] as f32);
    let w = inv_view_proj * Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    w.truncate() / w.w
}

/// f32 → f16 bits, round to nearest even (the WGSL does the same in integer arithmetic).
fn f16_bits(x: f32) -> u32 {
    half::f16::from_f32(x).to_bits() as u32
}

/// Packs a hit into one u32: bits 0-15 the distance as f16 (relative precision 2^-11, up to
/// 65504 m; [`DISTANCE_MISS_BITS`] for a miss), bits 16-31 the albedo as R5G6B5 of its square
/// root (a gamma-2 curve, which keeps dark albedos: steps of 1/31 or 1/63 in √albedo).
/// `distance = None`: a miss (albedo ignored).
pub fn pack_hit(distance: Option<f32>, albedo: Vec3) -> u32 {
    let Some(t) = distance else {
        return DISTANCE_MISS_BITS;
    };
    let t = if t.is_finite() {
        t.max(MIN_HIT_DISTANCE)
    } else {
        6.0e4
    };
    let a = albedo.clamp(Vec3::ZERO, Vec3::ONE);
    let a = if a.is_finite() { a } else { Vec3::ZERO };
    let s = Vec3::new(a.x.sqrt(), a.y.sqrt(), a.z.sqrt());
    let r = (s.x * 31.0).round() as u32;
    let g = (s.y * 63.0).round() as u32;
    let b = (s.z * 31.0).round() as u32;
    let bits = f16_bits(t.min(6.0e4));
    bits | (r << 27) | (g << 21) | (b << 16)
}

/// What a hit word holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HitWord {
    NotTraced,
    Unresolved,
    Miss,
    Hit { distance: f32, albedo: Vec3 },
}

pub fn unpack_hit(word: u32) -> HitWord {
    match word {
        HIT_NOT_TRACED => return HitWord::NotTraced,
        HIT_UNRESOLVED => return HitWord::Unresolved,
        _ => {}
    }
    let bits = word & 0xffff;
    if bits == DISTANCE_MISS_BITS {
        return HitWord::Miss;
    }
    let distance = half::f16::from_bits(bits as u16).to_f32();
    let q = |v: u32, n: f32| {
        let s = v as f32 / n;
        s * s
    };
    HitWord::Hit {
        distance,
        albedo: Vec3::new(
            q((word >> 27) & 31, 31.0),
            q((word >> 21) & 63, 63.0),
            q((word >> 16) & 31, 31.0),
        ),
    }
}

/// Albedo a hit reflects with: the base colour for dielectrics, `albedo (1 - F0) + F0` with
/// F0 = base colour for metals (Metro: metals' diffuse albedo is about zero, yet they do
/// reflect), blended by metalness.
pub fn hit_albedo(base: Vec3, metalness: f32) -> Vec3 {
    let m = metalness.clamp(0.0, 1.0);
    let metal = base * (Vec3::ONE - base) + base;
    base.lerp(metal, m)
}

/// Mean linear colour of an sRGB RGBA8 texture (alpha ignored).
pub fn texture_mean(t: &Texture) -> Vec3 {
    let n = (t.data.len() / 4).max(1) as f64;
    let mut sum = [0.0f64; 3];
    for px in t.data.chunks_exact(4) {
        for (k, s) in sum.iter_mut().enumerate() {
            let e = px[k] as f64 / 255.0;
            *s += if e <= 0.04045 {
                e / 12.92
            } else {
                ((e + 0.055) / 1.055).powf(2.4)
            };
        }
    }
    Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

/// Per-instance data for hits, two records an instance: `[albedo, 0]` and
/// `[emission, area light]`, the last 1 where the instance is one of the area-light pass's
/// lights (`area_lights::PolygonLights`): that pass lights every surface with it directly, so
/// GI leaves its emission out (of the computed hit light and of the reused lit image), else
/// the direct light would be counted twice.
/// Albedo: the average visible albedo of the instance's mesh-material pair, rendered from six
/// directions, or the material's override ([`super::instance_albedo`]). Emission: the
/// material's emitted luminance (nits) times its emissive texture's mean.
pub fn instance_table(scene: &Scene) -> Vec<[f32; 4]> {
    let albedo = super::instance_albedo::InstanceAlbedo::for_scene(scene).per_instance;
    let means: Vec<Vec3> = scene.textures.iter().map(texture_mean).collect();
    let mean_of = |r: Option<hikari_scene::TextureRef>| {
        r.and_then(|r| means.get(r.texture).copied())
            .unwrap_or(Vec3::ONE)
    };
    let area = crate::lights::PolygonLights::for_scene(scene);
    scene
        .instances
        .iter()
        .enumerate()
        .flat_map(|(k, i)| {
            let m = &scene.materials[i.material];
            let albedo = albedo[k];
            let emission = m.emissive_nits * mean_of(m.emissive_texture);
            // w = 1: a GI hit does not add this emission, because a light already sends it:
            // an area light (the area-light pass), or a lamp's shell around a point or spot
            // light (that light, which lights hits itself). Added too, a lantern's paper was
            // counted twice and, small and bright, hit by few rays: night's white speckle.
            let skipped = area
                .skipped
                .iter()
                .find(|(s, _)| *s == k)
                .map(|(_, why)| *why);
            let is_area_light = emission.max_element() > 0.0
                && (skipped.is_none()
                    || skipped == Some(crate::lights::polygon::SKIPPED_LAMP_SHELL));
            [
                albedo.extend(0.0).to_array(),
                emission
                    .extend(f32::from(u8::from(is_area_light)))
                    .to_array(),
            ]
        })
        .collect()
}

/// `hikari::octahedral`'s `oct_decode`: the unit vector of an octahedral encoding in [-1, 1]².
pub fn oct_decode(e: Vec2) -> Vec3 {
    let mut v = Vec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
    if v.z < 0.0 {
        let s = |x: f32| if x >= 0.0 { 1.0 } else { -1.0 };
        v = Vec3::new((1.0 - v.y.abs()) * s(v.x), (1.0 - v.x.abs()) * s(v.y), v.z);
    }
    v.normalize()
}

/// `hikari::octahedral`'s `oct_encode`: unit vector to [-1, 1]².
pub fn oct_encode(n: Vec3) -> Vec2 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 {
        return p;
    }
    let s = |x: f32| if x >= 0.0 { 1.0 } else { -1.0 };
    Vec2::new((1.0 - p.y.abs()) * s(p.x), (1.0 - p.x.abs()) * s(p.y))
}

/// A hit's normal word: the octahedral encoding `e` as two 16-bit numbers
/// `round(32767 e) + 32768` (steps of 3e-5; 0 cannot come out and means none).
pub fn pack_normal(e: Vec2) -> u32 {
    let q = |v: f32| ((v.clamp(-1.0, 1.0) * 32767.0).round() + 32768.0) as u32;
    q(e.x) | (q(e.y) << 16)
}

/// The octahedral encoding of a normal word, `None` for 0 (no normal).
pub fn unpack_normal(w: u32) -> Option<Vec2> {
    (w != 0).then(|| {
        Vec2::new(
            ((w & 0xffff) as f32 - 32768.0) / 32767.0,
            ((w >> 16) as f32 - 32768.0) / 32767.0,
        )
    })
}

/// The tables from which the BVH trace gives its hits their normal: per scene instance three
/// `[f32; 4]`, the rows of its normal matrix (the inverse transpose of its transform's 3 x 3)
/// with the bits of its mesh's first entry in the second table and of its triangle count in
/// the first two `w`; per mesh triangle, in mesh order (the BVH's primitive index), its
/// geometric normal `(p1 - p0) x (p2 - p0)` in object space as a [`pack_normal`] word (0 for
/// a degenerate one). The rest pose; [`triangle_normals`] rewrites a deforming mesh's entries
/// when its BLAS is refitted.
pub fn normal_tables(scene: &Scene) -> (Vec<[f32; 4]>, Vec<u32>) {
    let mut triangles = Vec::new();
    let mut first = Vec::with_capacity(scene.meshes.len());
    for m in &scene.meshes {
        first.push(triangles.len() as u32);
        triangles.extend(triangle_normals(&m.indices, &m.positions));
    }
    let instances = scene
        .instances
        .iter()
        .flat_map(|i| {
            let m = glam::Mat3::from_mat4(i.transform).inverse().transpose();
            let count = scene.meshes[i.mesh].indices.len() as u32 / 3;
            [
                m.row(0).extend(f32::from_bits(first[i.mesh])).to_array(),
                m.row(1).extend(f32::from_bits(count)).to_array(),
                m.row(2).extend(0.0).to_array(),
            ]
        })
        .collect();
    (instances, triangles)
}

/// Geometric normals `(p1 - p0) x (p2 - p0)` of a mesh's triangles in `positions` (a pose),
/// as [`pack_normal`] words in mesh order (0 for a degenerate triangle or a missing vertex).
pub fn triangle_normals<'a>(
    indices: &'a [u32],
    positions: &'a [Vec3],
) -> impl Iterator<Item = u32> + 'a {
    indices.chunks_exact(3).map(|t| {
        let p = |k: usize| positions.get(t[k] as usize).copied().unwrap_or(Vec3::ZERO);
        let n = (p(1) - p(0)).cross(p(2) - p(0));
        if n.is_finite() && n.length_squared() > 0.0 {
            pack_normal(oct_encode(n.normalize()))
        } else {
            0
        }
    })
}

/// Irradiance (lux) from one point or spot light at `x` on a surface facing `n`, as the
/// shade pass lights hits: inverse square held below 1e4, windowed to 0 at the light's range
/// (its own, or where it falls below `cutoff_lux`), the spot cone, Lambert's cosine; no shadow.
pub fn punctual_irradiance(
    x: Vec3,
    n: Vec3,
    light: &crate::scene::upload::LightGpu,
    cutoff_lux: f32,
) -> Vec3 {
    let pos = Vec3::from_slice(&light.position_range[..3]);
    let intensity = Vec3::from_slice(&light.intensity[..3]);
    let to_light = pos - x;
    let d2 = to_light.length_squared().max(1e-8);
    let peak = intensity.max_element();
    let range = light.position_range[3]
        .min((peak / cutoff_lux).sqrt())
        .max(1e-3);
    let r = d2 / (range * range);
    let window = (1.0 - r * r).max(0.0);
    let dir = to_light / d2.sqrt();
    let mut a = window * window * (1.0 / d2).min(1e4) * n.dot(dir).max(0.0);
    if light.direction_kind[3] > 0.5 {
        let axis = Vec3::from_slice(&light.direction_kind[..3]);
        let s = ((-dir).dot(axis) * light.spot[0] + light.spot[1]).clamp(0.0, 1.0);
        a *= s * s;
    }
    intensity * a
}

/// `hikari::ray_traced_gi`'s PCG hash (Jarzynski and Olano 2020).
pub fn hash(v: u32) -> u32 {
    let s = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
    (w >> 22) ^ w
}

/// Number `k` in [0, 1) of `pixel` in `frame` for the light samples of its hit (white noise).
/// Where the shade pass aims a hit's shadow ray at point or spot light `light` from `x`: a
/// point on a disc of the light's radius facing `x` (its own, else `default_radius_m`), from
/// random numbers 6 and 7 of the pixel and frame.
pub fn punctual_shadow_target(
    light: &crate::scene::upload::LightGpu,
    x: Vec3,
    default_radius_m: f32,
    pixel: [u32; 2],
    frame: u32,
) -> Vec3 {
    let centre = Vec3::from_slice(&light.position_range[..3]);
    let radius = if light.spot[2] >= 0.0 {
        light.spot[2]
    } else {
        default_radius_m
    };
    let (t, b) = basis((centre - x).normalize());
    let rho = radius * random(pixel, frame, 6).sqrt();
    let phi = 2.0 * std::f32::consts::PI * random(pixel, frame, 7);
    centre + t * (rho * phi.cos()) + b * (rho * phi.sin())
}

pub fn random(pixel: [u32; 2], frame: u32, k: u32) -> f32 {
    let h = hash(pixel[0] ^ hash(pixel[1] ^ hash(frame.wrapping_mul(8).wrapping_add(k))));
    (h >> 8) as f32 / 16_777_216.0
}

fn luminance(c: Vec3) -> f32 {
    hikari_math::color::luminance(c)
}

/// One of `scores` picked in proportion to its value, as the shade pass picks lights: in order,
/// by a running choice on the one number `u` (rescaled after each). Returns the chosen index,
/// its score and the scores' sum; `None` when none is above 0.
pub fn pick_weighted(scores: impl IntoIterator<Item = f32>, u: f32) -> Option<(usize, f32, f32)> {
    let (mut u, mut total, mut chosen) = (u, 0.0f32, None);
    for (i, s) in scores.into_iter().enumerate() {
        if s.is_nan() || s <= 0.0 {
            continue;
        }
        total += s;
        let p = s / total;
        if u < p {
            chosen = Some((i, s));
            u /= p;
        } else {
            u = (u - p) / (1.0 - p).max(1e-7);
        }
        u = u.min(0.999_999_94);
    }
    chosen.map(|(i, s)| (i, s, total))
}

/// The point or spot light a hit's shadow ray goes to, as the shade pass picks it: each
/// light's unshadowed irradiance `e` (lux), one chosen in proportion to its luminance
/// ([`pick_weighted`]). Returns the chosen index, its irradiance and the luminance of the sum;
/// `None` when nothing lights the point.
pub fn pick_light(e: impl IntoIterator<Item = Vec3>, u: f32) -> Option<(usize, Vec3, f32)> {
    let e: Vec<Vec3> = e.into_iter().collect();
    pick_weighted(e.iter().map(|&e| luminance(e)), u).map(|(i, _, total)| (i, e[i], total))
}

/// Whether area light `i` may light `x` on a surface facing `n`, as the shade pass culls: not a
/// light under `min_flux_lm` (unless flagged), not beyond where it falls below `cutoff_lux`,
/// not wholly behind its one-sided plane or below the horizon.
pub fn area_light_reaches(
    lights: &crate::lights::PolygonLights,
    i: usize,
    x: Vec3,
    n: Vec3,
    min_flux_lm: f32,
    cutoff_lux: f32,
) -> bool {
    use crate::lights::polygon::{AREA_LIGHT_DOUBLE_SIDED, AREA_LIGHT_FORCED};
    let l = &lights.lights[i];
    let forced = l.range[2] & AREA_LIGHT_FORCED != 0;
    let double_sided = l.range[2] & AREA_LIGHT_DOUBLE_SIDED != 0;
    if l.radiance_flux[3] < min_flux_lm && !forced {
        return false;
    }
    let radiance = Vec3::from_slice(&l.radiance_flux[..3]);
    let c = Vec3::from_slice(&l.centroid_radius[..3]);
    let r = l.centroid_radius[3];
    let reach = r + ((luminance(radiance) * l.normal_area[3]).max(0.0) / cutoff_lux).sqrt();
    let nl = Vec3::from_slice(&l.normal_area[..3]);
    !((c - x).length_squared() >= reach * reach
        || (c - x).dot(n) < -r
        || (!double_sided && nl.length() > 0.99 && (x - c).dot(nl) < -r))
}

/// What a hit picks area light `i` by, as the shade pass: its flux over the squared distance
/// to its centroid, 0 where it cannot reach `x` ([`area_light_reaches`]).
pub fn area_light_score(
    lights: &crate::lights::PolygonLights,
    i: usize,
    x: Vec3,
    n: Vec3,
    min_flux_lm: f32,
    cutoff_lux: f32,
) -> f32 {
    if !area_light_reaches(lights, i, x, n, min_flux_lm, cutoff_lux) {
        return 0.0;
    }
    let l = &lights.lights[i];
    let c = Vec3::from_slice(&l.centroid_radius[..3]);
    let r = l.centroid_radius[3];
    l.radiance_flux[3] / (c - x).length_squared().max((r * r).max(1e-6))
}

/// Unshadowed irradiance (lux) of area light `i` at `x` on a surface facing `n`, as the shade
/// pass lights hits: 0 where it cannot reach `x` ([`area_light_reaches`]), else the light's
/// radiance times the polygon integration (`area_lights::reference`).
pub fn area_light_irradiance(
    lights: &crate::lights::PolygonLights,
    i: usize,
    x: Vec3,
    n: Vec3,
    min_flux_lm: f32,
    cutoff_lux: f32,
) -> Vec3 {
    use crate::lights::polygon::AREA_LIGHT_DOUBLE_SIDED;
    if !area_light_reaches(lights, i, x, n, min_flux_lm, cutoff_lux) {
        return Vec3::ZERO;
    }
    let l = &lights.lights[i];
    let double_sided = l.range[2] & AREA_LIGHT_DOUBLE_SIDED != 0;
    let radiance = Vec3::from_slice(&l.radiance_flux[..3]);
    let f = crate::lights::reference::light_vector_irradiance(
        lights.triangles_of(i),
        double_sided,
        x.as_dvec3(),
        n.as_dvec3(),
    );
    radiance * (f.dot(n.as_dvec3()).max(0.0) as f32)
}

/// The point of area light `i` that the hit's shadow ray goes to, from two numbers in [0, 1):
/// a triangle by area (the first number, rescaled within it), then uniform on it.
pub fn area_light_point(lights: &crate::lights::PolygonLights, i: usize, u: Vec2) -> Vec3 {
    let tris = lights.triangles_of(i);
    let (mut k, mut lo) = (0, 0.0);
    while u.x > tris[k].p0_cdf[3] && k + 1 < tris.len() {
        lo = tris[k].p0_cdf[3];
        k += 1;
    }
    let t = &tris[k];
    let ux = ((u.x - lo) / (t.p0_cdf[3] - lo).max(1e-12)).clamp(0.0, 1.0);
    let su = ux.sqrt();
    Vec3::from_slice(&t.p0_cdf[..3]) * (1.0 - su)
        + Vec3::from_slice(&t.p1[..3]) * (su * (1.0 - u.y))
        + Vec3::from_slice(&t.p2[..3]) * (su * u.y)
}

/// The encoded sample of one ray: radiance `l` arriving along `dir` with weight `weight`
/// ([`ray`]). Non-finite radiance gives a zero sample.
pub fn encode_sample(l: Vec3, dir: Vec3, weight: f32) -> ShL1YCoCg {
    if !l.is_finite() || !dir.is_finite() {
        return ShL1YCoCg::default();
    }
    ShL1YCoCg::encode(l, dir).scale(weight)
}

/// One pixel's accumulated state (the history textures).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Accumulated {
    pub gi: ShL1YCoCg,
    pub ao: f32,
    /// Frames in the history, 0 where there is no surface.
    pub length: f32,
    /// View depth of the surface, metres.
    pub view_depth: f32,
}

impl Accumulated {
    fn finite(&self) -> bool {
        self.gi.y.coeffs.iter().all(|c| c.is_finite())
            && self.gi.co_cg.is_finite()
            && self.ao.is_finite()
            && self.length.is_finite()
            && self.view_depth.is_finite()
    }
}

/// What accumulation reads of one pixel this frame.
#[derive(Clone, Copy, Debug)]
pub struct AccumulateInput {
    /// Reverse-Z depth (0: sky).
    pub depth: f32,
    /// G-buffer motion: xy previous minus current pixel position, z view depth.
    pub motion: Vec3,
    pub raw: ShL1YCoCg,
    pub raw_ao: f32,
}

/// The accumulation's firefly clamp. A sample whose luminance (SH c0) exceeds
/// `k · scale + floor`, where `scale` is the history's local scale ([`firefly_scale`]), is
/// scaled down to that, whole (Y SH and CoCg alike, so its chroma and direction stay those of
/// the sample), once the history holds at least `min_history` frames (younger pixels must
/// still converge from their first samples).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FireflyClamp {
    /// Times the history's c0 a sample may reach (0: off). Unitless.
    pub k: f32,
    /// Added to the limit, in SH c0 units (luminance × `C0`): what a dark history may still
    /// take in one frame.
    pub floor: f32,
    /// History length (frames) from which the clamp applies.
    pub min_history: f32,
}

/// History length from which the firefly clamp applies: below it a pixel's history is too
/// young to say what is too bright.
pub const FIREFLY_MIN_HISTORY: f32 = 4.0;

impl FireflyClamp {
    /// The clamp of setting `k` in a frame metered at `metered_lux` (lux): the floor is the c0
    /// of a sample of luminance `metered_lux / π`, a white Lambertian surface under the metered
    /// illuminance, so the clamp scales with the scene's light and not with the camera's
    /// exposure settings. A non-finite or non-positive `k` or a non-finite meter turns it off.
    pub fn new(k: f32, metered_lux: f32) -> Self {
        if !(k.is_finite() && k > 0.0 && metered_lux.is_finite()) {
            return Self::default();
        }
        Self {
            k,
            floor: hikari_math::sh::basis::C0 as f32 * metered_lux.max(0.0) / std::f32::consts::PI,
            min_history: FIREFLY_MIN_HISTORY,
        }
    }

    /// As `RtGiParams::firefly`.
    pub fn to_array(self) -> [f32; 4] {
        [self.k, self.floor, self.min_history, 0.0]
    }

    /// `sample` limited against a history of `history_length` frames whose local scale is
    /// `scale` ([`firefly_scale`]).
    pub fn apply(&self, sample: ShL1YCoCg, scale: f32, history_length: f32) -> ShL1YCoCg {
        let on = self.k > 0.0 && history_length >= self.min_history;
        if !on {
            return sample;
        }
        let limit = self.k * scale.max(0.0) + self.floor;
        let c0 = sample.y.coeffs[0];
        if c0 > limit {
            sample.scale(limit / c0)
        } else {
            sample
        }
    }
}

/// The history's local scale for the firefly clamp, in SH c0: the largest finite c0 of the
/// 3x3 history texels around `q` (clamped to the image), at least 0. The neighbours keep a
/// pixel whose few samples all came out dark (or that a light just reached) from cutting what
/// the surface around it sees.
pub fn firefly_scale(
    history: &dyn Fn([u32; 2]) -> Accumulated,
    q: [u32; 2],
    size: [u32; 2],
) -> f32 {
    let mut scale = 0f32;
    for dy in -1i64..=1 {
        for dx in -1i64..=1 {
            let x = (q[0] as i64 + dx).clamp(0, size[0] as i64 - 1) as u32;
            let y = (q[1] as i64 + dy).clamp(0, size[1] as i64 - 1) as u32;
            let c = history([x, y]).gi.y.coeffs[0];
            if c.is_finite() {
                scale = scale.max(c);
            }
        }
    }
    scale
}

/// Temporal accumulation of one pixel: reprojects by the motion vector, bilinearly over the
/// 2x2 history texels about `pixel + 0.5 + motion`; a tap counts if inside the image, finite,
/// with history, and its view depth within `depth_tolerance` (relative) of where this surface
/// point was seen last frame (`prev_view_proj · world`, w); the valid taps' weights are
/// renormalised. Where they weigh under [`REPROJECTION_MIN_WEIGHT`], the texels of the 3x3
/// about the nearest one that pass the same tests stand in, equally weighted (a silhouette
/// under TAA's jitter: the pixel's own texel saw the other surface last frame, its neighbours
/// on this side did not); with none, the history is dropped. Then blends with
/// speed 1 / length, length growing to `max_history`, the raw sample held by `firefly`
/// against the history it joins (its 3x3 about the nearest texel). Non-finite raw values
/// count as a zero sample (AO: open).
#[allow(clippy::too_many_arguments)]
pub fn accumulate_pixel(
    pixel: [u32; 2],
    size: [u32; 2],
    input: &AccumulateInput,
    world: Vec3,
    prev_view_proj: Mat4,
    history: &dyn Fn([u32; 2]) -> Accumulated,
    history_valid: bool,
    max_history: f32,
    depth_tolerance: f32,
    firefly: &FireflyClamp,
) -> Accumulated {
    if input.depth.is_nan() || input.depth <= 0.0 {
        return Accumulated {
            ao: 1.0,
            ..Accumulated::default()
        };
    }
    let raw_ok = input.raw.y.coeffs.iter().all(|c| c.is_finite()) && input.raw.co_cg.is_finite();
    let raw = if raw_ok {
        input.raw
    } else {
        ShL1YCoCg::default()
    };
    let raw_ao = if input.raw_ao.is_finite() {
        input.raw_ao.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let view_depth = if input.motion.z.is_finite() {
        input.motion.z
    } else {
        0.0
    };
    let fresh = Accumulated {
        gi: raw,
        ao: raw_ao,
        length: 1.0,
        view_depth,
    };
    if !history_valid || !input.motion.is_finite() || !world.is_finite() {
        return fresh;
    }
    let prev = Vec2::new(pixel[0] as f32 + 0.5, pixel[1] as f32 + 0.5) + input.motion.truncate();
    if prev.x < 0.0 || prev.y < 0.0 || prev.x >= size[0] as f32 || prev.y >= size[1] as f32 {
        return fresh;
    }
    let expected = (prev_view_proj * world.extend(1.0)).w;
    // The history texel at (tx, ty) where it is inside, finite, has history and saw this
    // surface.
    let agreeing = |tx: i64, ty: i64| {
        if tx < 0 || ty < 0 || tx >= size[0] as i64 || ty >= size[1] as i64 {
            return None;
        }
        let h = history([tx as u32, ty as u32]);
        (h.finite()
            && h.length >= 1.0
            && (h.view_depth - expected).abs() <= depth_tolerance * expected.abs())
        .then_some(h)
    };
    let mut taps: Vec<(Accumulated, f32)> = bilinear_taps(prev)
        .into_iter()
        .filter(|(_, w)| *w > 0.0)
        .filter_map(|([tx, ty], w)| agreeing(tx, ty).map(|h| (h, w)))
        .collect();
    if taps.iter().map(|(_, w)| w).sum::<f32>() < REPROJECTION_MIN_WEIGHT {
        let (qx, qy) = (prev.x as i64, prev.y as i64);
        taps = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (qx + dx, qy + dy)))
            .filter_map(|(tx, ty)| agreeing(tx, ty).map(|h| (h, 1.0)))
            .collect();
        if taps.is_empty() {
            return fresh;
        }
    }
    let (mut gi, mut ao, mut length, mut weight) = (ShL1YCoCg::default(), 0.0, 0.0, 0.0);
    for (h, w) in taps {
        gi = gi.add(&h.gi.scale(w));
        ao += w * h.ao;
        length += w * h.length;
        weight += w;
    }
    let h = Accumulated {
        gi: gi.scale(1.0 / weight),
        ao: ao / weight,
        length: length / weight,
        view_depth,
    };
    let q = [prev.x as u32, prev.y as u32];
    let raw = if firefly.k > 0.0 && h.length >= firefly.min_history {
        firefly.apply(raw, firefly_scale(history, q, size), h.length)
    } else {
        raw
    };
    let length = (h.length + 1.0).min(max_history);
    let speed = 1.0 / length;
    Accumulated {
        gi: h.gi.lerp(&raw, speed),
        ao: h.ao + (raw_ao - h.ao) * speed,
        length,
        view_depth,
    }
}

/// The SH of a sample, as a 6-float record (gi_y's 4, gi_cocg's 2), for tests.
pub fn to_floats(s: &ShL1YCoCg) -> [f32; 6] {
    let c = s.y.coeffs;
    [c[0], c[1], c[2], c[3], s.co_cg.x, s.co_cg.y]
}

/// The inverse of [`to_floats`].
pub fn from_floats(f: [f32; 6]) -> ShL1YCoCg {
    ShL1YCoCg {
        y: ShL1 {
            coeffs: [f[0], f[1], f[2], f[3]],
        },
        co_cg: Vec2::new(f[4], f[5]),
    }
}

/// `hikari::rtgi_resolve`'s diffuse: radiance of a white Lambertian surface facing `n`.
pub fn resolve_diffuse(s: &ShL1YCoCg, n: Vec3) -> Vec3 {
    s.resolve_diffuse(n)
}

/// `hikari::rtgi_resolve`'s specular: reflected radiance towards `v` of a GGX surface facing
/// `n` (Fresnel from `f0` to `f90`, GGX alpha `material_alpha`), the SH taken as one light from its
/// dominant direction (the mirror direction if it has none) with the lobe widened by its loss
/// of directionality and the irradiance it gives a plane facing that direction.
pub fn resolve_specular(
    s: &ShL1YCoCg,
    n: Vec3,
    v: Vec3,
    f0: Vec3,
    f90: f32,
    material_alpha: f32,
) -> Vec3 {
    use hikari_math::brdf::{fresnel, ggx, smith};
    let l = s.dominant_direction().unwrap_or_else(|| (-v).reflect(n));
    let alpha = s.specular_alpha(material_alpha) as f64;
    let (n_l, n_v) = (n.dot(l) as f64, n.dot(v) as f64);
    if n_l <= 0.0 || n_v <= 0.0 {
        return Vec3::ZERO;
    }
    let e = (std::f32::consts::PI * s.resolve_diffuse(l)).as_dvec3();
    let h = (v + l).normalize();
    let spec = ggx::ggx_ndf(n.dot(h) as f64, alpha) * smith::visibility(n_v, n_l, alpha);
    let f = fresnel::fresnel_schlick_f90(f0.as_dvec3(), f90 as f64, v.dot(h).max(0.0) as f64);
    (f * spec * e * n_l).as_vec3()
}

/// Largest radiance (nits) in any channel of a sample: what f16 holds, with margin.
pub const MAX_SAMPLE_RADIANCE: f32 = 65_000.0;

/// The CPU meter's EV100 for `metered_lux` (lux): ISO 2720's incident-light rule,
/// EV100 = log2(E · 100 / 250), as `FrameSettings::ev100_with_sky` forms it (a fixed EV100 comes
/// back from its illuminance 2^EV100 · 2.5). The illuminance is held to at least 1e-3 lux.
pub fn cpu_meter_ev100(metered_lux: f32) -> f32 {
    (metered_lux.max(1e-3) * 100.0 / 250.0).log2()
}

/// Radiance (nits) that an exposure of `ev100` maps to display white: the inverse of the
/// exposure's scale 1 / (1.2 · 2^EV100) (exposure/adapt.wgsl).
pub fn display_white_nits(ev100: f32) -> f32 {
    1.2 * ev100.exp2()
}

/// The cap on a GI sample's luminance (nits): `k` times display white under `ev100`; 0 (off)
/// where `k` is not above 0.
pub fn hit_radiance_cap_nits(k: f32, ev100: f32) -> f32 {
    if k > 0.0 {
        k * display_white_nits(ev100)
    } else {
        0.0
    }
}

/// A sample's radiance `l` (nits) as the shade pass stores it: NaN and negative channels 0,
/// each channel at most [`MAX_SAMPLE_RADIANCE`], then the luminance held to `cap_nits` (0: no
/// cap) by scaling the whole colour, which keeps its chromaticity.
pub fn cap_sample_radiance(l: Vec3, cap_nits: f32) -> Vec3 {
    let c = |v: f32| {
        if v >= 0.0 {
            v.min(MAX_SAMPLE_RADIANCE)
        } else {
            0.0
        }
    };
    let l = Vec3::new(c(l.x), c(l.y), c(l.z));
    let y = luminance(l);
    if cap_nits > 0.0 && y > cap_nits {
        l * (cap_nits / y)
    } else {
        l
    }
}

#[cfg(test)]
mod tests {
    use super::pick_weighted;

    /// The hit's one-light estimate `v_k * total / s_k`, averaged over the random number,
    /// is the sum of every light's value whatever the scores (all above 0 where a value is):
    /// the selection is unbiased. A score of 0 drops its light.
    #[test]
    fn picking_by_score_is_unbiased() {
        let scores = [3.0f32, 0.0, 0.5, 10.0, 0.2];
        let values = [2.0f32, 0.0, 7.0, 0.25, 40.0];
        let n = 200_000;
        let mean = (0..n)
            .map(|k| {
                let u = (k as f32 + 0.5) / n as f32;
                let (i, s, total) = pick_weighted(scores, u).expect("some score is above 0");
                (values[i] * total / s) as f64
            })
            .sum::<f64>()
            / n as f64;
        let want: f32 = values.iter().sum();
        assert!(
            (mean - want as f64).abs() < 2e-3 * want as f64,
            "mean {mean}, sum {want}"
        );
        assert_eq!(pick_weighted([0.0, f32::NAN], 0.5), None);
    }
}
