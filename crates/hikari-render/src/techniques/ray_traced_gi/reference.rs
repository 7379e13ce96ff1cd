//! CPU twins of the ray-traced GI passes: ray generation, the hit word's packing, the sample
//! weight, the per-instance albedo, and reprojection with temporal accumulation. The WGSL
//! twins are in `rtgi.wgsl` (`hikari::ray_traced_gi`) and `accumulate.wgsl`.

use glam::{Mat4, Vec2, Vec3, Vec4};
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
    let area = crate::techniques::area_lights::PolygonLights::for_scene(scene);
    scene
        .instances
        .iter()
        .enumerate()
        .flat_map(|(k, i)| {
            let m = &scene.materials[i.material];
            let albedo = albedo[k];
            let emission = m.emissive_nits * mean_of(m.emissive_texture);
            let is_area_light =
                emission.max_element() > 0.0 && !area.skipped.iter().any(|(s, _)| *s == k);
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

/// Irradiance (lux) from one point or spot light at `x` on a surface facing `n`, as the
/// shade pass lights hits: inverse square held below 1e4, windowed to 0 at the light's range
/// (its own, or where it falls below `cutoff_lux`), the spot cone, Lambert's cosine; no shadow.
pub fn punctual_irradiance(
    x: Vec3,
    n: Vec3,
    light: &crate::scene_gpu::LightGpu,
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

/// Temporal accumulation of one pixel: reprojects by the motion vector to the nearest texel
/// of the history, accepts it if inside the image, finite, with history, and its view depth
/// within `depth_tolerance` (relative) of where this surface point was seen last frame
/// (`prev_view_proj · world`, w); then blends with speed 1 / length, length growing to
/// `max_history`. Non-finite raw values count as a zero sample (AO: open).
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
    let h = history([prev.x as u32, prev.y as u32]);
    let expected = (prev_view_proj * world.extend(1.0)).w;
    if !h.finite()
        || h.length < 1.0
        || (h.view_depth - expected).abs() > depth_tolerance * expected.abs()
    {
        return fresh;
    }
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
/// `n` (Fresnel F0 `f0`, GGX alpha `material_alpha`), the SH taken as one light from its
/// dominant direction (the mirror direction if it has none) with the lobe widened by its loss
/// of directionality and the irradiance it gives a plane facing that direction.
pub fn resolve_specular(s: &ShL1YCoCg, n: Vec3, v: Vec3, f0: Vec3, material_alpha: f32) -> Vec3 {
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
    let f = fresnel::fresnel_schlick(f0.as_dvec3(), v.dot(h).max(0.0) as f64);
    (f * spec * e * n_l).as_vec3()
}
