#define_import_path hikari::local_tonemap

// What the local tonemap's passes share. CPU twin: `techniques/local_tonemap/reference.rs`.

struct LocalTonemapParams {
    // x: exposed log2 luminance at the grid's lower end, y: slices per EV, z: the range in EV,
    // w: largest |gain|, EV.
    grid: vec4<f32>,
    // x: contrast above the midpoint, y: below it, z: detail, w: midpoint (exposed log2).
    tone: vec4<f32>,
    // x: the bilateral grid's share of the base layer, y: the highlight fit's target (exposed
    // log2), z: the least contrast it may choose, w: unused.
    blend: vec4<f32>,
}

struct BlurParams {
    // x: sigma in texels of the blurred axis, yzw: unused.
    sigma: vec4<f32>,
    // x: axis (0 x, 1 y, 2 z), y: radius in taps, zw: unused.
    config: vec4<u32>,
}

const GRID_W: u32 = 64u;
const GRID_H: u32 = 32u;
const GRID_D: u32 = 64u;
// The wide Gaussian's upsampled image.
const WIDE_W: u32 = 256u;
const WIDE_H: u32 = 128u;

const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Exposed log2 luminance, relative to the grid's lower end and clamped to its range: black
// and NaN land on the lowest slice.
fn grid_log2(rgb: vec3<f32>, scale: f32, p: LocalTonemapParams) -> f32 {
    let y = dot(rgb, LUMA) * scale;
    let l = log2(max(select(0.0, y, y >= 0.0), 1e-30));
    return clamp(l - p.grid.x, 0.0, p.grid.z);
}

fn gaussian(i: i32, sigma: f32) -> f32 {
    let x = f32(i) / sigma;
    return exp(-0.5 * x * x);
}

// Texel coordinates of a sample at `pos` (texel centres at +0.5), edges clamped: the lower
// texel, the upper one, and the weight of the upper one.
fn taps(pos: f32, n: u32) -> vec3<f32> {
    let p = clamp(pos, 0.0, f32(n - 1u));
    let a = min(floor(p), f32(n - 1u));
    return vec3<f32>(a, min(a + 1.0, f32(n - 1u)), p - a);
}

// The contrast above the midpoint: the look's, lowered where the frame's highlight (exposed
// log2, `exposure.value.w`) lies above the target to the contrast that brings a base layer at
// the highlight to the target, (T - M) / (H - M), but not below the least contrast.
fn contrast_above(p: LocalTonemapParams, highlight: f32) -> f32 {
    let m = p.tone.w;
    let t = p.blend.y;
    var c = p.tone.x;
    if highlight > t && t > m {
        c = min(c, max((t - m) / (highlight - m), p.blend.z));
    }
    return c;
}

// The log2 gain at normalised position `uv` of a pixel whose grid log2 is `v` (`grid_log2`):
// the blurred grid sampled trilinearly and normalised, blended with the wide Gaussian, then the
// talk's detail-preserving contrast I_o = c (B - M) + d (I_i - B) + M with c per side of the
// midpoint; the gain is I_o - I_i, clamped. Shared by `local_tonemap.apply` (the dumpable gain
// image) and `tonemap.apply` (which evaluates it per pixel instead of reading that image).
fn local_gain(
    v: f32,
    uv: vec2<f32>,
    p: LocalTonemapParams,
    highlight: f32,
    grid: texture_3d<f32>,
    wide: texture_2d<f32>,
) -> f32 {
    let tx = taps(uv.x * f32(GRID_W) - 0.5, GRID_W);
    let ty = taps(uv.y * f32(GRID_H) - 0.5, GRID_H);
    let tz = taps(v * p.grid.y - 0.5, GRID_D);
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
    let b = mix(wide_v, bilateral, p.blend.x) + p.grid.x;
    let i = v + p.grid.x;
    let m = p.tone.w;
    let c = select(p.tone.y, contrast_above(p, highlight), b > m);
    let o = c * (b - m) + p.tone.z * (i - b) + m;
    return clamp(o - i, -p.grid.w, p.grid.w);
}
