// Temporal anti-aliasing resolve: this frame's radiance blended into the reprojected history,
// the history clipped to the current 3x3 neighbourhood in YCoCg. Twin: taa/reference.rs.

struct TaaParams {
    history_valid: u32,
    clip: u32,
    max_history: f32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: TaaParams;
@group(0) @binding(1) var current: texture_2d<f32>;
@group(0) @binding(2) var motion: texture_2d<f32>;
@group(0) @binding(3) var history_prev: texture_2d<f32>;
@group(0) @binding(4) var history_cur: texture_storage_2d<rgba16float, write>;
@group(0) @binding(5) var out_radiance: texture_storage_2d<rgba16float, write>;

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

fn load_current(p: vec2<i32>, size: vec2<i32>) -> vec3<f32> {
    return sanitize(textureLoad(current, clamp(p, vec2<i32>(0), size - 1), 0).rgb);
}

fn load_history(p: vec2<i32>, size: vec2<i32>) -> vec4<f32> {
    return textureLoad(history_prev, clamp(p, vec2<i32>(0), size - 1), 0);
}

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(current));
    let px = vec2<i32>(id.xy);
    if any(px >= size) {
        return;
    }
    let cur = load_current(px, size);
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let v = rgb_to_ycocg(load_current(px + vec2<i32>(dx, dy), size));
            lo = min(lo, v);
            hi = max(hi, v);
        }
    }

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
    textureStore(out_radiance, px, vec4<f32>(resolved.rgb, 1.0));
}
