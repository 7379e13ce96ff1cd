// The base layer B (the blurred grid, trilinearly sampled and normalised, blended with the
// wide Gaussian) and the talk's detail-preserving contrast in log2:
// I_o = c (B - M) + d (I_i - B) + M, with c per side of the midpoint. Writes the gain
// I_o - I_i that the tonemap multiplies the exposed colour by, as exp2(gain).

#import hikari::local_tonemap::{LocalTonemapParams, GRID_W, GRID_H, GRID_D, grid_log2}

@group(0) @binding(0) var<uniform> params: LocalTonemapParams;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> exposure: vec4<f32>;
@group(0) @binding(3) var grid: texture_3d<f32>;
@group(0) @binding(4) var wide: texture_2d<f32>;
@group(0) @binding(5) var gain: texture_storage_2d<r16float, write>;

// Texel coordinates of a sample at `pos` (texel centres at +0.5), edges clamped: the lower
// texel, the upper one, and the weight of the upper one.
fn taps(pos: f32, n: u32) -> vec3<f32> {
    let p = clamp(pos, 0.0, f32(n - 1u));
    let a = min(floor(p), f32(n - 1u));
    return vec3<f32>(a, min(a + 1.0, f32(n - 1u)), p - a);
}

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gain);
    if any(id.xy >= size) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let v = grid_log2(textureLoad(radiance, id.xy, 0).rgb, exposure.x, params);

    let tx = taps(uv.x * f32(GRID_W) - 0.5, GRID_W);
    let ty = taps(uv.y * f32(GRID_H) - 0.5, GRID_H);
    let tz = taps(v * params.grid.y - 0.5, GRID_D);
    var g = vec2<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let sx = (k & 1u) != 0u;
        let sy = (k & 2u) != 0u;
        let sz = (k & 4u) != 0u;
        let c = vec3<i32>(
            i32(select(tx.x, tx.y, sx)),
            i32(select(ty.x, ty.y, sy)),
            i32(select(tz.x, tz.y, sz)),
        );
        let w = select(1.0 - tx.z, tx.z, sx) * select(1.0 - ty.z, ty.z, sy)
            * select(1.0 - tz.z, tz.z, sz);
        g += w * textureLoad(grid, c, 0).xy;
    }

    let wsize = textureDimensions(wide);
    let wx = taps(uv.x * f32(wsize.x) - 0.5, wsize.x);
    let wy = taps(uv.y * f32(wsize.y) - 0.5, wsize.y);
    let w00 = textureLoad(wide, vec2<i32>(i32(wx.x), i32(wy.x)), 0).r;
    let w10 = textureLoad(wide, vec2<i32>(i32(wx.y), i32(wy.x)), 0).r;
    let w01 = textureLoad(wide, vec2<i32>(i32(wx.x), i32(wy.y)), 0).r;
    let w11 = textureLoad(wide, vec2<i32>(i32(wx.y), i32(wy.y)), 0).r;
    let wide_v = mix(mix(w00, w10, wx.z), mix(w01, w11, wx.z), wy.z);

    // An empty neighbourhood of the grid (none of its pixels is near this luminance) leaves
    // the wide Gaussian alone.
    let bilateral = select(wide_v, g.x / g.y, g.y > 1e-6);
    let b = mix(wide_v, bilateral, params.blend.x) + params.grid.x;
    let i = v + params.grid.x;
    let m = params.tone.w;
    let c = select(params.tone.y, params.tone.x, b > m);
    let o = c * (b - m) + params.tone.z * (i - b) + m;
    let out = clamp(o - i, -params.grid.w, params.grid.w);
    textureStore(gain, id.xy, vec4<f32>(out, 0.0, 0.0, 0.0));
}
