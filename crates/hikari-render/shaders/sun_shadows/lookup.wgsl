#define_import_path hikari::sun_shadows

// Sun shadow lookup: cascade selection and 3x3 bilinear PCF over the compute-rasterised
// shadow maps (`passes/sun_shadows.rs`). CPU twin: reference::sun_shadows. A shader that
// imports this module binds the parameters and the maps at bindings 9 and 10, after its own.

struct ShadowParams {
    light_view_proj: array<mat4x4<f32>, 4>,
    texel_world: vec4<f32>,
    // cascades, resolution, PCF tap spacing in texels, normal bias in texels.
    config: vec4<f32>,
    depth_bias: vec4<f32>,
}

@group(0) @binding(9) var<uniform> shadow: ShadowParams;
// Cascade-major u32 depth bits, `resolution^2` a cascade.
@group(0) @binding(10) var<storage, read> shadow_texels: array<u32>;

// Fraction of a bilinear footprint whose casters are no nearer the sun than `receiver`
// (reverse depth: larger is nearer the sun).
fn bilinear_lit(base: u32, res: i32, st: vec2<f32>, receiver: f32) -> f32 {
    let p = floor(st);
    let f = st - p;
    let i = vec2<i32>(p);
    var lit = vec4<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let c = clamp(i + vec2<i32>(k & 1, k >> 1), vec2<i32>(0), vec2<i32>(res - 1));
        let d = bitcast<f32>(shadow_texels[base + u32(c.y * res + c.x)]);
        lit[k] = select(0.0, 1.0, d <= receiver);
    }
    return mix(mix(lit.x, lit.y, f.x), mix(lit.z, lit.w, f.x), f.y);
}

// The nine bilinear taps one texel apart, as the 4x4 texels they touch with tent weights
// (1 - f, 1, 1, f) / 3 along each axis: the same sum with 16 loads instead of 36.
fn tent_lit(base: u32, res: i32, st: vec2<f32>, receiver: f32) -> f32 {
    let p = floor(st);
    let f = st - p;
    let i = vec2<i32>(p) - 1;
    let wx = vec4<f32>(1.0 - f.x, 1.0, 1.0, f.x);
    let wy = vec4<f32>(1.0 - f.y, 1.0, 1.0, f.y);
    var sum = 0.0;
    for (var y = 0; y < 4; y++) {
        let row = clamp(i.y + y, 0, res - 1) * res;
        var line = 0.0;
        for (var x = 0; x < 4; x++) {
            let d = bitcast<f32>(shadow_texels[base + u32(row + clamp(i.x + x, 0, res - 1))]);
            line += select(0.0, wx[x], d <= receiver);
        }
        sum += line * wy[y];
    }
    return sum / 9.0;
}

// Sun visibility in [0, 1] of a surface at `world` with unit normal `n`; 1 outside every
// cascade and when shadows are off.
fn sun_visibility(world: vec3<f32>, n: vec3<f32>) -> f32 {
    let cascades = u32(shadow.config.x);
    let res = shadow.config.y;
    let spacing = shadow.config.z;
    // Taps reach 1 + spacing texels from the centre: keep them inside the map.
    let margin = (spacing + 2.0) / res;
    for (var c = 0u; c < cascades; c++) {
        let p = world + n * (shadow.texel_world[c] * shadow.config.w);
        let s = shadow.light_view_proj[c] * vec4<f32>(p, 1.0);
        let uv = vec2<f32>(s.x * 0.5 + 0.5, 0.5 - s.y * 0.5);
        if all(uv > vec2<f32>(margin)) && all(uv < vec2<f32>(1.0 - margin)) {
            let receiver = s.z + shadow.depth_bias[c];
            let st = uv * res - 0.5;
            let base = c * u32(res) * u32(res);
            if spacing == 1.0 {
                return tent_lit(base, i32(res), st, receiver);
            }
            var sum = 0.0;
            for (var y = -1; y <= 1; y++) {
                for (var x = -1; x <= 1; x++) {
                    sum += bilinear_lit(base, i32(res), st + vec2<f32>(f32(x), f32(y)) * spacing, receiver);
                }
            }
            return sum / 9.0;
        }
    }
    return 1.0;
}
