// tonemap.apply: HDR radiance (nits) to the display image, per pixel:
// Purkinje shift at absolute luminance -> exposure and local gain -> Rec.709 to the
// tonemapping space with the white balance folded in -> Uchimura's curve per channel ->
// Rec.709 -> sRGB -> 3D LUT grade -> dither. CPU twin: `tonemap::reference::apply`.
// The local gain is either evaluated here from the local tonemap's blurred grid and wide
// Gaussian (the frame: no full-resolution gain image is written or read) or read from a gain
// image (tests and tools).

#import hikari::local_tonemap::{LocalTonemapParams, grid_log2, local_gain}

struct TonemapParams {
    // Rows L, M, S, R of the talk's shader matrix (w unused).
    lmsr_from_rgb: array<vec4<f32>, 4>,
    // Rows of the gain -> RGB change matrix, already scaled by the strength.
    rgb_from_lms_gain: array<vec4<f32>, 3>,
    // x: rod response (cd/m²) at which the shift is halved; 0: no fade.
    purkinje_fade: vec4<f32>,
    tonemap_from_rec709: array<vec4<f32>, 3>,
    rec709_from_tonemap: array<vec4<f32>, 3>,
    // P (max), a (contrast), m (linear start), c (toe exponent).
    curve: vec4<f32>,
    // b (black), S0 (shoulder start), S1 (its value there), CP (shoulder rate).
    curve_shoulder: vec4<f32>,
    // xyz: the LUT's domain; w: its size.
    lut_domain_min: vec4<f32>,
    lut_domain_max: vec4<f32>,
    // x: switch bits (1 Purkinje, 2 local gain, 4 curve, 8 LUT, 16 dither); y: dither seed.
    switches: vec4<u32>,
    // The local tonemap's uniforms, when LOCAL_GRID is set.
    local: LocalTonemapParams,
}

@group(0) @binding(0) var<uniform> params: TonemapParams;
@group(0) @binding(1) var hdr: texture_2d<f32>;
// The exposure technique's `exposure.value`: (scale, ev100, metered lux, highlight).
@group(0) @binding(2) var<storage, read> exposure: vec4<f32>;
@group(0) @binding(3) var log2_gain: texture_2d<f32>;
// The local tonemap's blurred grid and upsampled wide Gaussian (LOCAL_GRID).
@group(0) @binding(4) var local_grid: texture_3d<f32>;
@group(0) @binding(5) var local_wide: texture_2d<f32>;
@group(0) @binding(6) var lut: texture_3d<f32>;
@group(0) @binding(7) var lut_sampler: sampler;
@group(0) @binding(8) var ldr: texture_storage_2d<rgba8unorm, write>;

const PURKINJE: u32 = 1u;
const LOCAL_GAIN: u32 = 2u;
const CURVE: u32 = 4u;
const LUT: u32 = 8u;
const DITHER: u32 = 16u;
const LOCAL_GRID: u32 = 32u;

fn rows3(m: array<vec4<f32>, 3>, c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(m[0].xyz, c), dot(m[1].xyz, c), dot(m[2].xyz, c));
}

// The talk's three lines, with the rods fading out as they saturate.
fn purkinje_shift(c: vec3<f32>) -> vec3<f32> {
    let m = params.lmsr_from_rgb;
    let lmsr = vec4<f32>(dot(m[0].xyz, c), dot(m[1].xyz, c), dot(m[2].xyz, c), dot(m[3].xyz, c));
    let gain = inverseSqrt(1.0 + max(lmsr.xyz, vec3<f32>(0.0)));
    let sat = params.purkinje_fade.x;
    var fade = 1.0;
    if sat > 0.0 {
        fade = sat / (sat + max(lmsr.w, 0.0));
    }
    return c + rows3(params.rgb_from_lms_gain, gain) * (lmsr.w * fade);
}

// Uchimura 2017 ("HDR theory and practice", CEDEC): toe, linear section, exponential shoulder.
fn curve(x_in: f32) -> f32 {
    let x = max(x_in, 0.0);
    let p = params.curve.x;
    let a = params.curve.y;
    let m = params.curve.z;
    let c = params.curve.w;
    let b = params.curve_shoulder.x;
    let s0 = params.curve_shoulder.y;
    let s1 = params.curve_shoulder.z;
    let cp = params.curve_shoulder.w;
    let t = clamp(x / m, 0.0, 1.0);
    let w0 = 1.0 - t * t * (3.0 - 2.0 * t);
    let w2 = select(0.0, 1.0, x >= s0);
    let w1 = 1.0 - w0 - w2;
    var toe = b;
    if x > 0.0 {
        toe = m * pow(x / m, c) + b;
    }
    let lin = m + a * (x - m);
    let shoulder = p - (p - s1) * exp(cp * (x - s0));
    return toe * w0 + lin * w1 + shoulder * w2;
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Triangular noise in [-0.5, 0.5] / 255, the same for the three channels.
fn dither(p: vec2<u32>, seed: u32) -> f32 {
    let h1 = pcg(p.x + pcg(p.y + pcg(seed)));
    let h2 = pcg(h1);
    let u1 = f32(h1 >> 8u) / 16777216.0;
    let u2 = f32(h2 >> 8u) / 16777216.0;
    return (u1 + u2 - 1.0) * (0.5 / 255.0);
}

// 256-thread workgroups, as the placeholder it replaces (2.2x faster than 8x8 on the H200).
@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(ldr);
    if any(id.xy >= size) {
        return;
    }
    let flags = params.switches.x;
    let raw = textureLoad(hdr, id.xy, 0).rgb;
    var c = raw;
    // `!(x >= 0)` also catches NaN.
    c = select(vec3<f32>(0.0), c, c >= vec3<f32>(0.0));
    c = min(c, vec3<f32>(6.0e4));
    if (flags & PURKINJE) != 0u {
        c = max(purkinje_shift(c), vec3<f32>(0.0));
    }
    var scale = exposure.x;
    if (flags & LOCAL_GRID) != 0u {
        // From the radiance as it came, as `local_tonemap.apply` computes it.
        let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
        let v = grid_log2(raw, exposure.x, params.local);
        scale = scale * exp2(local_gain(v, uv, params.local, exposure.w, local_grid, local_wide));
    } else if (flags & LOCAL_GAIN) != 0u {
        scale = scale * exp2(textureLoad(log2_gain, id.xy, 0).r);
    }
    c = c * scale;
    var t = rows3(params.tonemap_from_rec709, c);
    if (flags & CURVE) != 0u {
        t = vec3<f32>(curve(t.x), curve(t.y), curve(t.z));
    } else {
        t = clamp(t, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    c = clamp(rows3(params.rec709_from_tonemap, t), vec3<f32>(0.0), vec3<f32>(1.0));
    // A NaN exposure or gain must not reach the image.
    c = select(vec3<f32>(0.0), c, c == c);
    var e = srgb_encode(c);
    if (flags & LUT) != 0u {
        let n = params.lut_domain_min.w;
        let u = clamp(
            (e - params.lut_domain_min.xyz) / (params.lut_domain_max.xyz - params.lut_domain_min.xyz),
            vec3<f32>(0.0),
            vec3<f32>(1.0),
        );
        e = textureSampleLevel(lut, lut_sampler, u * ((n - 1.0) / n) + 0.5 / n, 0.0).rgb;
    }
    if (flags & DITHER) != 0u {
        e = e + dither(id.xy, params.switches.y);
    }
    textureStore(ldr, id.xy, vec4<f32>(clamp(e, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0));
}
