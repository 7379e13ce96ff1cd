// BC6H_UF16 encoding, one thread a 4x4 block of a layer (z) of one mip level of a texture
// array (twin: bc6h/reference.rs, integer for integer).
// The single-subset 10-bit mode: endpoints from the block's bounding box in half-float bit
// space, each channel's diagonal turned to follow the block's brightness, each texel's index
// the nearest of the 16 interpolated colours; with `quality` 1 also the box inset by 1/32 and
// 1/16 of its extent, keeping the block with the least error.

struct Bc6hParams {
    blocks_x: u32,
    blocks_y: u32,
    layer: u32,
    quality: u32,
    // The mip level's size in texels.
    width: u32,
    height: u32,
    // Where the first layer's blocks start in `blocks`; each layer's follow (z: the layer).
    first_block: u32,
    level: u32,
    // Blocks from one row to the next and from one layer to the next in `blocks` (rows padded
    // where the blocks are copied into a texture, whose rows start every 256 bytes).
    row_stride: u32,
    layer_stride: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: Bc6hParams;
@group(0) @binding(1) var source: texture_2d_array<f32>;
@group(0) @binding(2) var<storage, read_write> blocks: array<vec4<u32>>;

const MAX_HALF_BITS: u32 = 0x7bffu;
const WEIGHTS = array<u32, 16>(0u, 4u, 9u, 13u, 17u, 21u, 26u, 30u, 34u, 38u, 43u, 47u, 51u, 55u, 60u, 64u);

var<private> texels: array<vec3<u32>, 16>;

// f32 to half bits, rounding to nearest even as the twin's `half` crate does (WGSL's
// pack2x16float needs a capability not every adapter has, and leaves the rounding open).
fn half_bits(x: f32) -> u32 {
    // NaN fails the comparison and becomes 0, like negatives.
    if !(x > 0.0) {
        return 0u;
    }
    let b = bitcast<u32>(min(x, 65504.0));
    let e = i32((b >> 23u) & 0xffu) - 112;
    let m = b & 0x7fffffu;
    if e <= 0 {
        // A subnormal half: the value in units of 2^-24 is the full mantissa >> (14 - e).
        if e < -10 {
            return 0u;
        }
        let full = m | 0x800000u;
        let shift = u32(14 - e);
        var h = full >> shift;
        let rest = full & ((1u << shift) - 1u);
        let halfway = 1u << (shift - 1u);
        if rest > halfway || (rest == halfway && (h & 1u) == 1u) {
            h += 1u;
        }
        return h;
    }
    var h = (u32(e) << 10u) | (m >> 13u);
    let rest = m & 0x1fffu;
    if rest > 0x1000u || (rest == 0x1000u && (h & 1u) == 1u) {
        h += 1u;
    }
    return min(h, MAX_HALF_BITS);
}

fn unquantize(q: u32) -> u32 {
    if q == 0u {
        return 0u;
    }
    if q == 1023u {
        return 0xffffu;
    }
    return q * 64u + 32u;
}

// The nearest 10-bit endpoint: h / 31, or a neighbour at the ends (0 and 1023 stand for 0
// and 0xffff), compared exactly in the space scaled by 31; a tie keeps the lower.
fn quantize1(h: u32) -> u32 {
    let q = min(h / 31u, 1023u);
    var best = q;
    var best_d = distance_to(q, h);
    let lo = select(q, q - 1u, q > 0u);
    let hi = min(q + 1u, 1023u);
    let d_lo = distance_to(lo, h);
    if d_lo < best_d || (d_lo == best_d && lo < best) {
        best = lo;
        best_d = d_lo;
    }
    let d_hi = distance_to(hi, h);
    if d_hi < best_d || (d_hi == best_d && hi < best) {
        best = hi;
    }
    return best;
}

fn distance_to(q: u32, h: u32) -> u32 {
    let a = unquantize(q) * 31u;
    let b = h * 64u;
    return max(a, b) - min(a, b);
}

fn quantize(h: vec3<u32>) -> vec3<u32> {
    return vec3<u32>(quantize1(h.x), quantize1(h.y), quantize1(h.z));
}

fn palette(q0: vec3<u32>, q1: vec3<u32>, i: u32) -> vec3<u32> {
    let w = WEIGHTS[i];
    let u0 = vec3<u32>(unquantize(q0.x), unquantize(q0.y), unquantize(q0.z));
    let u1 = vec3<u32>(unquantize(q1.x), unquantize(q1.y), unquantize(q1.z));
    let v = (u0 * (64u - w) + u1 * w + 32u) >> vec3<u32>(6u);
    return (v * 31u) >> vec3<u32>(6u);
}

fn add_saturating(a: u32, b: u32) -> u32 {
    if a > 0xffffffffu - b {
        return 0xffffffffu;
    }
    return a + b;
}

fn error(a: vec3<u32>, b: vec3<u32>) -> u32 {
    let d = max(a, b) - min(a, b);
    return add_saturating(add_saturating(d.x * d.x, d.y * d.y), d.z * d.z);
}

struct Fit {
    q0: vec3<u32>,
    q1: vec3<u32>,
    indices: array<u32, 16>,
    error: u32,
}

fn fit(e0: vec3<u32>, e1: vec3<u32>) -> Fit {
    var f: Fit;
    f.q0 = quantize(e0);
    f.q1 = quantize(e1);
    var colours: array<vec3<u32>, 16>;
    for (var i = 0u; i < 16u; i++) {
        colours[i] = palette(f.q0, f.q1, i);
    }
    f.error = 0u;
    for (var t = 0u; t < 16u; t++) {
        var best = 0xffffffffu;
        var index = 0u;
        for (var i = 0u; i < 16u; i++) {
            let e = error(colours[i], texels[t]);
            if e < best {
                best = e;
                index = i;
            }
        }
        f.indices[t] = index;
        f.error = add_saturating(f.error, best);
    }
    // The first index has 3 bits: swap the endpoints and read the palette backwards.
    if f.indices[0] >= 8u {
        let q = f.q0;
        f.q0 = f.q1;
        f.q1 = q;
        for (var t = 0u; t < 16u; t++) {
            f.indices[t] = 15u - f.indices[t];
        }
    }
    return f;
}

// ORs the low `n` bits of `v` into the 128-bit block at bit `pos`.
fn put(words: ptr<function, vec4<u32>>, pos: u32, n: u32, v: u32) {
    let value = v & ((1u << n) - 1u);
    let w = pos / 32u;
    let s = pos % 32u;
    (*words)[w] |= value << s;
    if s + n > 32u {
        (*words)[w + 1u] |= value >> (32u - s);
    }
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.blocks_x || id.y >= params.blocks_y {
        return;
    }
    var lo = vec3<u32>(0xffffffffu);
    var hi = vec3<u32>(0u);
    for (var t = 0u; t < 16u; t++) {
        let x = min(id.x * 4u + t % 4u, params.width - 1u);
        let y = min(id.y * 4u + t / 4u, params.height - 1u);
        let c = textureLoad(source, vec2<u32>(x, y), params.layer + id.z, params.level).rgb;
        texels[t] = vec3<u32>(half_bits(c.r), half_bits(c.g), half_bits(c.b));
        lo = min(lo, texels[t]);
        hi = max(hi, texels[t]);
    }
    // Each channel's diagonal follows the brightness (integer covariance, as the twin).
    var sums = vec3<i32>(0);
    var s_sum = 0;
    var xs = vec3<i32>(0);
    for (var t = 0u; t < 16u; t++) {
        let v = vec3<i32>(texels[t] >> vec3<u32>(5u));
        let s = i32((texels[t].x + texels[t].y + texels[t].z) >> 5u);
        sums += v;
        s_sum += s;
        xs += v * s;
    }
    let flip = 16 * xs - sums * s_sum < vec3<i32>(0);
    var best: Fit;
    let passes = select(1u, 3u, params.quality == 1u);
    for (var p = 0u; p < passes; p++) {
        // 0: the box; 1: inset by 1/32 of its extent; 2: by 1/16.
        let d = select(vec3<u32>(0u), (hi - lo) >> vec3<u32>(6u - p), p > 0u);
        let a = lo + d;
        let b = hi - d;
        let f = fit(select(a, b, flip), select(b, a, flip));
        if p == 0u || f.error < best.error {
            best = f;
        }
    }
    var words = vec4<u32>(0u);
    put(&words, 0u, 5u, 3u);
    put(&words, 5u, 10u, best.q0.x);
    put(&words, 15u, 10u, best.q0.y);
    put(&words, 25u, 10u, best.q0.z);
    put(&words, 35u, 10u, best.q1.x);
    put(&words, 45u, 10u, best.q1.y);
    put(&words, 55u, 10u, best.q1.z);
    put(&words, 65u, 3u, best.indices[0]);
    for (var t = 1u; t < 16u; t++) {
        put(&words, 68u + 4u * (t - 1u), 4u, best.indices[t]);
    }
    blocks[params.first_block + id.z * params.layer_stride + id.y * params.row_stride + id.x] =
        words;
}
