// The window's picture: the final image or any texture of the frame through a display
// mapping suited to what it holds, into an 8-bit display-encoded target. Twin:
// debug_view/reference.rs.

#import hikari::octahedral::oct_decode
#import hikari::color::srgb_encode3

struct DisplayParams {
    // x: mapping (see reference.rs's `Mapping` codes), y: channel for `SCALAR`.
    mode: vec4<u32>,
    // xy: source size, zw: target size.
    sizes: vec4<u32>,
    // x: exposure scale (1 / the luminance that maps to white), y: the scalar that maps to
    // white, z: the log2 luminance at the ramp's bottom, w: EVs the ramp spans.
    values: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: DisplayParams;
@group(0) @binding(1) var source: texture_2d<f32>;
@group(0) @binding(2) var dest: texture_storage_2d<rgba8unorm, write>;

const RAW: u32 = 0u;
const RADIANCE: u32 = 1u;
const NORMAL: u32 = 2u;
const DEPTH: u32 = 3u;
const SCALAR: u32 = 4u;
const LUMINANCE: u32 = 5u;

fn finite_or_zero(v: vec4<f32>) -> vec4<f32> {
    // NaN fails every comparison; infinities exceed the largest float.
    let ok = (v == v) & (abs(v) <= vec4<f32>(3.4e38));
    return select(vec4<f32>(0.0), v, ok);
}

// A blue-to-red ramp for t in [0, 1].
fn ramp(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    return clamp(vec3<f32>(1.5 - abs(4.0 * x - 3.0), 1.5 - abs(4.0 * x - 2.0), 1.5 - abs(4.0 * x - 1.0)), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn display(v: vec4<f32>) -> vec3<f32> {
    let m = params.mode.x;
    if m == RAW {
        return clamp(v.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    if m == RADIANCE {
        let c = max(v.rgb, vec3<f32>(0.0)) * params.values.x;
        return srgb_encode3(c / (vec3<f32>(1.0) + c));
    }
    if m == NORMAL {
        let n = oct_decode(clamp(v.xy, vec2<f32>(-1.0), vec2<f32>(1.0)));
        return n * 0.5 + vec3<f32>(0.5);
    }
    if m == DEPTH {
        // Reverse-Z: 1 at the near plane, 0 at infinity.
        return vec3<f32>(sqrt(sqrt(clamp(v.x, 0.0, 1.0))));
    }
    if m == SCALAR {
        let s = v[min(params.mode.y, 3u)] / max(params.values.y, 1e-20);
        return vec3<f32>(srgb_encode3(vec3<f32>(clamp(s, 0.0, 1.0))));
    }
    // LUMINANCE: log2 of Rec.709 luminance over the ramp.
    let y = dot(max(v.rgb, vec3<f32>(0.0)), vec3<f32>(0.2126, 0.7152, 0.0722));
    let t = (log2(max(y, 1e-20)) - params.values.z) / max(params.values.w, 1e-6);
    return ramp(t);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let dst = params.sizes.zw;
    if id.x >= dst.x || id.y >= dst.y {
        return;
    }
    let src = params.sizes.xy;
    // Nearest source texel of the target pixel's centre.
    let p = min(vec2<u32>((vec2<f32>(id.xy) + 0.5) * vec2<f32>(src) / vec2<f32>(dst)), src - vec2<u32>(1u));
    let v = finite_or_zero(textureLoad(source, vec2<i32>(p), 0));
    textureStore(dest, vec2<i32>(id.xy), vec4<f32>(display(v), 1.0));
}
