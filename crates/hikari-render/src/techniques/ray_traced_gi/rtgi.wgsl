#define_import_path hikari::ray_traced_gi

// What every ray-traced GI pass shares: the repeatable ray of a pixel and frame, and the hit
// word (distance and albedo in one u32). Binding set `rtgi_noise`: the committed 64x64x64
// blue-noise set of hikari-math, u8 ranks packed four to a u32, slice-major then row-major.
// CPU twin: ray_traced_gi::reference.

@group(#{RTGI_NOISE_GROUP}) @binding(0) var<storage, read> rtgi_blue_noise: array<u32>;

const RTGI_PI: f32 = 3.14159265358979;
const RTGI_HIT_NOT_TRACED: u32 = 0u;
const RTGI_HIT_UNRESOLVED: u32 = 0xffffffffu;
// f16 +inf in the distance bits: nothing hit within the ray's length.
const RTGI_DISTANCE_MISS: u32 = 0x7c00u;
const RTGI_MIN_HIT_DISTANCE: f32 = 1.0e-3;

fn rtgi_noise_byte(slice: u32, x: u32, y: u32) -> u32 {
    let i = (slice * 64u + y) * 64u + x;
    return (rtgi_blue_noise[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu;
}

// The talk's lookup: pixel offset by 32 on odd frames, slice frame & 63; the second number
// from slice (frame + 32) & 63 at the same texel.
fn rtgi_blue_noise_2d(pixel: vec2<u32>, frame: u32) -> vec2<f32> {
    let p = (pixel + vec2<u32>(32u * (frame & 1u))) & vec2<u32>(63u);
    let a = rtgi_noise_byte(frame & 63u, p.x, p.y);
    let b = rtgi_noise_byte((frame + 32u) & 63u, p.x, p.y);
    return (vec2<f32>(f32(a), f32(b)) + 0.5) / 256.0;
}

// Duff et al. 2017.
fn rtgi_basis(n: vec3<f32>) -> mat2x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3<f32>(b, s + n.y * n.y * a, -n.y));
}

// Cosine-distributed direction around unit n (xyz) and its cosine (w).
fn rtgi_cosine_direction(n: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * RTGI_PI * u.y;
    let z = sqrt(max(1.0 - u.x, 0.0));
    let tb = rtgi_basis(n);
    let d = tb[0] * (r * cos(phi)) + tb[1] * (r * sin(phi)) + n * z;
    return vec4<f32>(normalize(d), z);
}

fn rtgi_ray_direction(pixel: vec2<u32>, frame: u32, n: vec3<f32>) -> vec4<f32> {
    return rtgi_cosine_direction(n, rtgi_blue_noise_2d(pixel, frame));
}

// Cosine sample -> uniform-hemisphere estimator, the normalisation of the SH encoding: the
// pdf ratio (1/2π) / (cos/π) = 1 / (2 cos), averaged over the 8-bit noise value's bin of u1
// (cos² = 1 - u1), 256 (√(1 - k/256) - √(1 - (k+1)/256)). At the bin's midpoint instead the
// grazing bins are under-weighted and the mean weight is 0.98, not 1.
fn rtgi_uniform_weight(u1: f32) -> f32 {
    let k = clamp(floor(u1 * 256.0), 0.0, 255.0);
    return 256.0 * (sqrt(1.0 - k / 256.0) - sqrt(max(1.0 - (k + 1.0) / 256.0, 0.0)));
}

// The pixel's ray: direction (xyz) and its uniform-hemisphere weight (w).
fn rtgi_ray(pixel: vec2<u32>, frame: u32, n: vec3<f32>) -> vec4<f32> {
    let u = rtgi_blue_noise_2d(pixel, frame);
    return vec4<f32>(rtgi_cosine_direction(n, u).xyz, rtgi_uniform_weight(u.x));
}

fn rtgi_ray_origin(world: vec3<f32>, n: vec3<f32>, camera: vec3<f32>) -> vec3<f32> {
    return world + n * (1.0e-3 + 1.0e-3 * length(world - camera));
}

// f16 bits of x in [2^-14, 65504], rounded to nearest even, in integer arithmetic
// (pack2x16float needs a capability not every adapter has).
fn rtgi_f16_bits(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    let e = ((bits >> 23u) & 0xffu) - 112u;
    let m = bits & 0x7fffffu;
    let rem = m & 0x1fffu;
    let up = select(0u, 1u, rem > 0x1000u || (rem == 0x1000u && ((m >> 13u) & 1u) == 1u));
    return (e << 10u) + (m >> 13u) + up;
}

fn rtgi_f16_value(h: u32) -> f32 {
    return bitcast<f32>(((((h >> 10u) & 0x1fu) + 112u) << 23u) | ((h & 0x3ffu) << 13u));
}

// Bits 0-15: distance as f16; bits 16-31: sqrt(albedo) as R5G6B5.
fn rtgi_pack_hit(distance: f32, albedo: vec3<f32>) -> u32 {
    var t = max(distance, RTGI_MIN_HIT_DISTANCE);
    t = select(6.0e4, min(t, 6.0e4), t == t && t <= 6.0e4);
    var a = clamp(albedo, vec3<f32>(0.0), vec3<f32>(1.0));
    a = select(vec3<f32>(0.0), a, a == a);
    let s = sqrt(a);
    let r = u32(round(s.x * 31.0));
    let g = u32(round(s.y * 63.0));
    let b = u32(round(s.z * 31.0));
    return rtgi_f16_bits(t) | (r << 27u) | (g << 21u) | (b << 16u);
}

fn rtgi_pack_miss() -> u32 {
    return RTGI_DISTANCE_MISS;
}

fn rtgi_is_hit(word: u32) -> bool {
    return word != RTGI_HIT_NOT_TRACED && word != RTGI_HIT_UNRESOLVED && (word & 0xffffu) != RTGI_DISTANCE_MISS;
}

fn rtgi_hit_distance(word: u32) -> f32 {
    return rtgi_f16_value(word & 0xffffu);
}

fn rtgi_hit_albedo_of(word: u32) -> vec3<f32> {
    let s = vec3<f32>(f32((word >> 27u) & 31u) / 31.0, f32((word >> 21u) & 63u) / 63.0, f32((word >> 16u) & 31u) / 31.0);
    return s * s;
}

// Metro's albedo for hits: base colour, metals as albedo (1 - F0) + F0 with F0 = base colour.
fn rtgi_hit_albedo(base: vec3<f32>, metalness: f32) -> vec3<f32> {
    let m = clamp(metalness, 0.0, 1.0);
    return mix(base, base * (1.0 - base) + base, m);
}

// The technique's uniform (`ray_traced_gi::RtGiParams`).
struct RtGiParams {
    // x: frame index; y: RTGI_* flags; z: history length cap; w: light count.
    config: vec4<u32>,
    // x: GI ray length (m), y: AO distance (m), z: history depth tolerance (relative),
    // w: illuminance (lux) below which a punctual light is cut off.
    distances: vec4<f32>,
    // x: step (px), y: steps at most, z: thickness (m), w: length (m).
    pretrace: vec4<f32>,
    // xyz: unit vector towards the sun or moon; w: its illuminance in lux.
    sun: vec4<f32>,
    // rgb: its colour (luminance 1).
    sun_color: vec4<f32>,
    // Placeholder sky radiance (nits) at the zenith and the horizon (atmosphere off).
    sky_zenith: vec4<f32>,
    sky_horizon: vec4<f32>,
    // Lights at hits: x area lights (a count, exact in f32), y their minimum flux (lm), z the
    // illuminance (lux) below which a local light's shadow ray plays Russian roulette (0: never),
    // w 0.
    area: vec4<f32>,
    // The accumulation's firefly clamp: x: k (0: off), y: the floor (SH c0), z: the history
    // length from which it applies.
    firefly: vec4<f32>,
    // The cap on each sample's radiance (shade.wgsl): x: times the radiance of display white
    // (0: off), y: the EV100 of a first frame, z: 1 when the exposure state holds last frame's.
    exposure: vec4<f32>,
}

const RTGI_PRETRACE: u32 = 1u;
const RTGI_BVH: u32 = 2u;
const RTGI_SUN: u32 = 4u;
const RTGI_SKY: u32 = 8u;
const RTGI_PLACEHOLDER_SKY: u32 = 16u;
const RTGI_PUNCTUAL: u32 = 32u;
const RTGI_ACCUMULATE: u32 = 64u;
const RTGI_RESET: u32 = 128u;
const RTGI_SKY_AMBIENT: u32 = 256u;
const RTGI_SHADOW_MAPS: u32 = 512u;
const RTGI_REUSE_LIT: u32 = 1024u;
// A hit's normal, oct-encoded (hikari::octahedral) as two 16-bit numbers round(32767 e) +
// 32768, e in [-1, 1]: 0 cannot be produced and means "none". CPU twin: reference::pack_normal.
const RTGI_NO_NORMAL: u32 = 0u;

fn rtgi_pack_normal(e: vec2<f32>) -> u32 {
    let q = vec2<u32>(round(clamp(e, vec2<f32>(-1.0), vec2<f32>(1.0)) * 32767.0) + 32768.0);
    return q.x | (q.y << 16u);
}

fn rtgi_unpack_normal(w: u32) -> vec2<f32> {
    return (vec2<f32>(f32(w & 0xffffu), f32(w >> 16u)) - 32768.0) / 32767.0;
}

const RTGI_AREA: u32 = 2048u;
const RTGI_PUNCTUAL_SHADOWS: u32 = 4096u;

// PCG hash (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering").
fn rtgi_hash(v: u32) -> u32 {
    let s = v * 747796405u + 2891336453u;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

// Number `k` in [0, 1) of a pixel and frame, for the light samples of its hit: white noise, as
// the ray's blue-noise pair already sets its direction and has no third dimension. CPU twin:
// reference::random.
fn rtgi_random(pixel: vec2<u32>, frame: u32, k: u32) -> f32 {
    let h = rtgi_hash(pixel.x ^ rtgi_hash(pixel.y ^ rtgi_hash(frame * 8u + k)));
    return f32(h >> 8u) / 16777216.0;
}
