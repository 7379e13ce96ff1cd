// Temporal anti-aliasing resolve: this frame's radiance blended into the reprojected history,
// the history clipped to the current 3x3 neighbourhood in YCoCg. Twin: taa/reference.rs.
//
// Bytes a pixel: the current radiance once (a 16x16 tile and its 1-pixel apron go through
// workgroup memory, converted to YCoCg once per texel, so that the nine neighbours cost no
// texture reads), the motion vector, the bilinear history (mostly hits in cache: neighbours
// share texels) and one 8-byte store. The history is the output: the passes after TAA read it
// (its alpha is the number of frames it averages, not coverage).

struct TaaParams {
    history_valid: u32,
    clip: u32,
    max_history: f32,
    _pad: u32,
    // Upsampling only: this frame's jitter in render pixels (x right, y down), and render
    // pixels per output pixel along each axis.
    jitter: vec2<f32>,
    ratio: vec2<f32>,
}

@group(0) @binding(0) var<uniform> params: TaaParams;
@group(0) @binding(1) var current: texture_2d<f32>;
@group(0) @binding(2) var motion: texture_2d<f32>;
@group(0) @binding(3) var history_prev: texture_2d<f32>;
@group(0) @binding(4) var history_cur: texture_storage_2d<rgba16float, write>;

const TILE: i32 = 16;
const APRON: i32 = TILE + 2;
// This frame's radiance around the workgroup's tile, sanitised, in YCoCg.
var<workgroup> tile: array<vec3<f32>, 324>;

const MAX_HALF: f32 = 65504.0;

fn sanitize(c: vec3<f32>) -> vec3<f32> {
    // NaN fails every comparison and becomes 0, like negatives.
    return select(vec3<f32>(0.0), min(c, vec3<f32>(MAX_HALF)), c >= vec3<f32>(0.0));
}

fn rgb_to_ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        0.25 * c.x + 0.5 * c.y + 0.25 * c.z,
        0.5 * c.x - 0.5 * c.z,
        -0.25 * c.x + 0.5 * c.y - 0.25 * c.z,
    );
}

fn ycocg_to_rgb(v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(v.x + v.y - v.z, v.x + v.z, v.x - v.y - v.z);
}

fn clip_to_box(p: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec3<f32> {
    let centre = 0.5 * (lo + hi);
    let extent = max(0.5 * (hi - lo), vec3<f32>(1e-6));
    let d = p - centre;
    let r = abs(d / extent);
    let ratio = max(max(r.x, r.y), r.z);
    return select(p, centre + d / ratio, ratio > 1.0);
}

fn load_history(p: vec2<i32>, size: vec2<i32>) -> vec4<f32> {
    return textureLoad(history_prev, clamp(p, vec2<i32>(0), size - 1), 0);
}

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let size = vec2<i32>(textureDimensions(current));
    // The tile and its apron: 18x18 texels, edges clamped, two loads a thread at most.
    let origin = vec2<i32>(wg.xy) * TILE - 1;
    for (var k = i32(lid); k < APRON * APRON; k += TILE * TILE) {
        let q = clamp(origin + vec2<i32>(k % APRON, k / APRON), vec2<i32>(0), size - 1);
        tile[k] = rgb_to_ycocg(sanitize(textureLoad(current, q, 0).rgb));
    }
    workgroupBarrier();
    let px = vec2<i32>(id.xy);
    if any(px >= size) {
        return;
    }
    let t = px - origin;
    let cur_y = tile[t.y * APRON + t.x];
    var lo = cur_y;
    var hi = cur_y;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let v = tile[(t.y + dy) * APRON + t.x + dx];
            lo = min(lo, v);
            hi = max(hi, v);
        }
    }
    // The pixel's own radiance as loaded, not back from YCoCg: a frame without history is then
    // its input to the bit (the texel is in cache from the tile's load).
    let cur = sanitize(textureLoad(current, px, 0).rgb);

    var resolved = vec4<f32>(cur, 1.0);
    let prev_pos = vec2<f32>(px) + 0.5 + textureLoad(motion, px, 0).xy;
    let inside = all(prev_pos >= vec2<f32>(0.0)) && all(prev_pos <= vec2<f32>(size));
    if params.history_valid != 0u && inside {
        // Bilinear by hand, so that the twin matches to the bit pattern of the weights.
        let q = prev_pos - 0.5;
        let base = floor(q);
        let f = q - base;
        let b = vec2<i32>(base);
        let top = mix(load_history(b, size), load_history(b + vec2<i32>(1, 0), size), f.x);
        let bottom = mix(load_history(b + vec2<i32>(0, 1), size), load_history(b + vec2<i32>(1, 1), size), f.x);
        let prev = mix(top, bottom, f.y);
        var p = prev.rgb;
        if params.clip != 0u {
            p = ycocg_to_rgb(clip_to_box(rgb_to_ycocg(p), lo, hi));
        }
        let n = max(prev.w, 1.0);
        let alpha = max(1.0 / (n + 1.0), 1.0 / params.max_history);
        resolved = vec4<f32>(sanitize(mix(p, cur, alpha)), min(n + 1.0, params.max_history));
    }
    textureStore(history_cur, px, resolved);
}

// Temporal upsampling (TAAU): the frame was rendered at a fraction of the output's size, its
// samples jittered over the output's pixels. Each output pixel gathers the 3x3 render pixels
// around it, each weighted by how near its jittered sample fell to the output pixel's centre
// (a Gaussian in output pixels), and blends their weighted mean into the history by their
// summed weight (at most 1): over a jitter cycle the history becomes the Gaussian-weighted mean
// of every sample that fell near the pixel, the supersampled image, not an interpolation of
// interpolations. The history is resampled with Catmull-Rom, which keeps it sharp under
// motion, and clipped to the samples' YCoCg box as in `main`. Its alpha holds the frames'
// summed weight. Twin: reference::resolve_upsampled.

// exp(-SPREAD d^2), d in output pixels: sigma 0.4 of a pixel, near a pixel-wide box's
// sharpness without its aliasing.
const SPREAD: f32 = 3.125;

fn load_history_clamped(p: vec2<i32>, size: vec2<i32>) -> vec4<f32> {
    return textureLoad(history_prev, clamp(p, vec2<i32>(0), size - 1), 0);
}

// Catmull-Rom weights of the four texels around a sample at fraction f past the second.
fn catmull_rom(f: f32) -> vec4<f32> {
    return vec4<f32>(
        f * (-0.5 + f * (1.0 - 0.5 * f)),
        1.0 + f * f * (-2.5 + 1.5 * f),
        f * (0.5 + f * (2.0 - 1.5 * f)),
        f * f * (-0.5 + 0.5 * f),
    );
}

@compute @workgroup_size(8, 8, 1)
fn upsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let out_size = vec2<i32>(textureDimensions(history_cur));
    let in_size = vec2<i32>(textureDimensions(current));
    let o = vec2<i32>(id.xy);
    if any(o >= out_size) {
        return;
    }
    // The output pixel's centre in render pixels, and the render pixel it falls in.
    let x = (vec2<f32>(o) + 0.5) * params.ratio;
    let c = clamp(vec2<i32>(floor(x)), vec2<i32>(0), in_size - 1);
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = c + vec2<i32>(dx, dy);
            let v = sanitize(textureLoad(current, clamp(q, vec2<i32>(0), in_size - 1), 0).rgb);
            let y = rgb_to_ycocg(v);
            lo = min(lo, y);
            hi = max(hi, y);
            // Where this pixel's sample lies (its centre less the jitter the view was drawn
            // with), in output pixels from the output pixel's centre.
            let d = (vec2<f32>(q) + 0.5 - params.jitter - x) / params.ratio;
            let w = exp(-SPREAD * dot(d, d));
            sum += w * v;
            weight += w;
        }
    }
    // The 3x3 always holds a sample within a render pixel: the weight is never 0.
    let cur = sum / max(weight, 1e-30);
    let confidence = min(weight, 1.0);

    var resolved = vec4<f32>(cur, confidence);
    let m = textureLoad(motion, c, 0).xy / params.ratio;
    let prev_pos = vec2<f32>(o) + 0.5 + m;
    let inside = all(prev_pos >= vec2<f32>(0.0)) && all(prev_pos <= vec2<f32>(out_size));
    if params.history_valid != 0u && inside {
        let q = prev_pos - 0.5;
        let base = floor(q);
        let wx = catmull_rom(q.x - base.x);
        let wy = catmull_rom(q.y - base.y);
        let b = vec2<i32>(base) - 1;
        var prev = vec4<f32>(0.0);
        for (var j = 0; j < 4; j++) {
            var row = vec4<f32>(0.0);
            for (var i = 0; i < 4; i++) {
                row += wx[i] * load_history_clamped(b + vec2<i32>(i, j), out_size);
            }
            prev += wy[j] * row;
        }
        // Catmull-Rom overshoots at edges: never below zero.
        var p = max(prev.rgb, vec3<f32>(0.0));
        if params.clip != 0u {
            p = ycocg_to_rgb(clip_to_box(rgb_to_ycocg(p), lo, hi));
        }
        let n = clamp(prev.w, 0.0, params.max_history);
        let alpha = max(confidence / max(n + confidence, 1e-6), confidence / params.max_history);
        resolved = vec4<f32>(sanitize(mix(p, cur, alpha)), min(n + confidence, params.max_history));
    }
    textureStore(history_cur, o, resolved);
}
