#define_import_path hikari::sun_shadows

// Sun shadow lookup: cascade selection and 3x3 bilinear PCF over the compute-rasterised
// shadow maps (`techniques/sun_shadows/mod.rs`). CPU twin: `sun_shadows::reference`. Its
// bindings are the binding set `sun_shadows` (`SunShadowMaps::lookup`), in a group of their
// own: a pass that imports this module binds them with `.set(shadows.lookup)`. The maps scroll: texel t of cascade c is stored at
// (t + origin[c]) mod resolution.

struct ShadowParams {
    light_view_proj: array<mat4x4<f32>, 4>,
    texel_world: vec4<f32>,
    // cascades, resolution, PCF tap spacing in texels, normal bias in texels.
    config: vec4<f32>,
    depth_bias: vec4<f32>,
    // Per cascade: where its texel (0, 0) is stored, x | y << 16.
    origin: vec4<u32>,
}

@group(#{SUN_SHADOWS_GROUP}) @binding(0) var<uniform> shadow: ShadowParams;
// Depth bits, a layer a cascade.
@group(#{SUN_SHADOWS_GROUP}) @binding(1) var shadow_map: texture_2d_array<u32>;
@group(#{SUN_SHADOWS_GROUP}) @binding(2) var shadow_sampler: sampler;

fn shadow_depth(layer: u32, c: vec2<i32>) -> f32 {
    return bitcast<f32>(textureLoad(shadow_map, c, layer, 0).r);
}

// Which of four texels' casters are no nearer the sun than `receiver`, as 0 or 1.
fn lit4(depth_bits: vec4<u32>, receiver: f32) -> vec4<f32> {
    return select(vec4<f32>(0.0), vec4<f32>(1.0), bitcast<vec4<f32>>(depth_bits) <= vec4<f32>(receiver));
}

// Fraction of a bilinear footprint whose casters are no nearer the sun than `receiver`
// (reverse depth: larger is nearer the sun).
fn bilinear_lit(layer: u32, res: i32, origin: vec2<i32>, st: vec2<f32>, receiver: f32) -> f32 {
    let p = floor(st);
    let f = st - p;
    let i = vec2<i32>(p) + origin;
    var lit = vec4<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let c = (i + vec2<i32>(k & 1, k >> 1)) & vec2<i32>(res - 1);
        lit[k] = select(0.0, 1.0, shadow_depth(layer, c) <= receiver);
    }
    return mix(mix(lit.x, lit.y, f.x), mix(lit.z, lit.w, f.x), f.y);
}

// The nine bilinear taps one texel apart, as the 4x4 texels they touch with tent weights
// (1 - f, 1, 1, f) / 3 along each axis: the same sum from four 2x2 gathers instead of 36
// loads. A gather at the corner shared by texels (x, y) and (x + 1, y + 1) returns them as
// ((x, y + 1), (x + 1, y + 1), (x + 1, y), (x, y)); the repeating sampler wraps the
// coordinates as the twin's indices do.
fn tent_lit(layer: u32, res: f32, origin: vec2<f32>, st: vec2<f32>, receiver: f32) -> f32 {
    let p = floor(st);
    let f = st - p;
    // The block starts at texel p - 1: its first 2x2 share the corner at p.
    let corner = (p + origin) / res;
    let step = 2.0 / res;
    let top_left = lit4(textureGather(0, shadow_map, shadow_sampler, corner, layer), receiver);
    let top_right = lit4(textureGather(0, shadow_map, shadow_sampler, corner + vec2<f32>(step, 0.0), layer), receiver);
    let bottom_left = lit4(textureGather(0, shadow_map, shadow_sampler, corner + vec2<f32>(0.0, step), layer), receiver);
    let bottom_right = lit4(textureGather(0, shadow_map, shadow_sampler, corner + vec2<f32>(step), layer), receiver);
    // Rows 0 and 1 of the block are the gathers' w, z (upper) and x, y (lower) lanes.
    let wx = vec4<f32>(1.0 - f.x, 1.0, 1.0, f.x);
    let row0 = dot(vec4<f32>(top_left.w, top_left.z, top_right.w, top_right.z), wx);
    let row1 = dot(vec4<f32>(top_left.x, top_left.y, top_right.x, top_right.y), wx);
    let row2 = dot(vec4<f32>(bottom_left.w, bottom_left.z, bottom_right.w, bottom_right.z), wx);
    let row3 = dot(vec4<f32>(bottom_left.x, bottom_left.y, bottom_right.x, bottom_right.y), wx);
    return dot(vec4<f32>(row0, row1, row2, row3), vec4<f32>(1.0 - f.y, 1.0, 1.0, f.y)) / 9.0;
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
            let bits = shadow.origin[c];
            let origin = vec2<u32>(bits & 0xffffu, bits >> 16u);
            if spacing == 1.0 {
                return tent_lit(c, res, vec2<f32>(origin), st, receiver);
            }
            var sum = 0.0;
            for (var y = -1; y <= 1; y++) {
                for (var x = -1; x <= 1; x++) {
                    sum += bilinear_lit(c, i32(res), vec2<i32>(origin), st + vec2<f32>(f32(x), f32(y)) * spacing, receiver);
                }
            }
            return sum / 9.0;
        }
    }
    return 1.0;
}
