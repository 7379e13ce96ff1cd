#define_import_path hikari::scene_gpu

// The scene as uploaded by `scene_gpu.rs`; field meanings are documented there.

struct VertexAttr {
    uv: vec2<f32>,
    normal: u32,
    tangent: u32,
    color: vec2<u32>,
    extra: u32,
    pad: u32,
}

struct InstanceGpu {
    model: mat4x4<f32>,
    normal_model: mat4x4<f32>,
    prev_model: mat4x4<f32>,
    material: u32,
    flags: u32,
    pad: vec2<u32>,
}

struct MaterialGpu {
    base_color: vec4<f32>,
    emissive: vec4<f32>,
    params: vec4<f32>,
    extra: vec4<f32>,
    textures: vec4<u32>,
    more_textures: vec4<u32>,
}

struct Chunk {
    instance: u32,
    first_triangle: u32,
    count: u32,
    pad: u32,
    bounds_lo: vec4<f32>,
    bounds_hi: vec4<f32>,
}

struct LightGpu {
    position_range: vec4<f32>,
    direction_kind: vec4<f32>,
    intensity: vec4<f32>,
    // xy: the spot cone's scale and offset; z: radius (m) for shadow rays, negative where the
    // scene gives none (the setting's); w unused.
    spot: vec4<f32>,
}

// Where a punctual light's illuminance falls to `cutoff_lux`, or its own range if nearer.
fn light_range(light: LightGpu, cutoff_lux: f32) -> f32 {
    let peak = max(light.intensity.r, max(light.intensity.g, light.intensity.b));
    return max(min(light.position_range.w, sqrt(peak / cutoff_lux)), 1e-3);
}

// Illuminance factor of a punctual light at 1 / distance^2 `inv_d2`, `x` = distance^2 /
// range^2: inverse square (held below 1e4, a light 1 cm away), windowed to 0 at the range (the
// smooth window glTF's KHR_lights_punctual recommends), times the spot cone; `l` is the unit
// direction from the surface to the light.
fn light_attenuation(light: LightGpu, l: vec3<f32>, inv_d2: f32, x: f32) -> f32 {
    let window = clamp(1.0 - x * x, 0.0, 1.0);
    var a = window * window * min(inv_d2, 1e4);
    if light.direction_kind.w > 0.5 {
        let s = clamp(dot(-l, light.direction_kind.xyz) * light.spot.x + light.spot.y, 0.0, 1.0);
        a *= s * s;
    }
    return a;
}

const CHUNK_TRIANGLES: u32 = 64u;
const NO_TEXTURE: u32 = 0xffffffffu;
const INSTANCE_DOUBLE_SIDED: u32 = 1u;
const INSTANCE_OWN_NORMAL_MATRIX: u32 = 2u;
const INSTANCE_MOVED: u32 = 4u;
// Bit 8 (INSTANCE_ALPHA_TESTED) is read only on the CPU, by the BVH build.
const EXTRA_BITANGENT_NEGATIVE: u32 = 0x10000u;
const EXTRA_HAS_TANGENT: u32 = 0x20000u;
const EXTRA_HAS_INTERIOR: u32 = 0x40000u;

// Texture addressing the sampler cannot do per texture (`MaterialGpu::more_textures` y):
// 0 repeat, 1 mirrored, 2 clamp. The sampler repeats, so a mirrored or clamped coordinate
// stays half a texel (`half`, of level 0) inside the edge: there both bilinear taps are the
// edge texel, as the modes want, and not the opposite edge's. (Coarser mips still reach
// across in a band 2^level times as wide.)
fn wrap_coord(x: f32, mode: u32, half: f32) -> f32 {
    if mode == 1u {
        let m = x - 2.0 * floor(x * 0.5);
        return clamp(select(m, 2.0 - m, m > 1.0), half, 1.0 - half);
    }
    if mode == 2u {
        return clamp(x, half, 1.0 - half);
    }
    return x;
}

fn wrap_uv(uv: vec2<f32>, bits: u32, size: vec2<u32>) -> vec2<f32> {
    let half = 0.5 / vec2<f32>(size);
    return vec2<f32>(wrap_coord(uv.x, bits & 3u, half.x), wrap_coord(uv.y, (bits >> 2u) & 3u, half.y));
}
