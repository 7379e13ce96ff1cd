// Temporal accumulation of the raw GI and AO before denoising: the history is reprojected by
// the G-buffer's motion vector, bilinearly over the 2x2 texels about the position; a tap counts
// where it is on screen, finite, has history and its view depth agrees with where this point
// was seen last frame within the tolerance, the valid taps' weights renormalised. Where they
// sum to under REPROJECTION_MIN_WEIGHT, the 3x3 texels about the nearest one that pass the
// same tests stand in, equally weighted (a silhouette under TAA's jitter: the pixel's own texel
// saw the other surface last frame, its neighbours on this side did not); with none, the
// history is dropped. The speed is 1 / length, the length growing while the history stays
// valid, up to a cap. A sample far brighter than the history it joins is scaled down first
// (the firefly clamp, reference::FireflyClamp). Non-finite input is replaced where it enters. CPU twin:
// reference::accumulate_pixel.

#import hikari::view::{View, world_from_depth, reprojection, reprojection_tap, history_depth_agrees, REPROJECTION_MIN_WEIGHT}
#import hikari::ray_traced_gi::{RtGiParams, RTGI_ACCUMULATE, RTGI_RESET}
#import hikari::finite::is_finite4

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: RtGiParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_motion: texture_2d<f32>;
@group(0) @binding(4) var raw_y: texture_2d<f32>;
@group(0) @binding(5) var raw_cocg_ao: texture_2d<f32>;
@group(0) @binding(6) var prev_y: texture_2d<f32>;
@group(0) @binding(7) var prev_cocg: texture_2d<f32>;
@group(0) @binding(8) var prev_ao: texture_2d<f32>;
@group(0) @binding(9) var prev_length: texture_2d<f32>;
@group(0) @binding(10) var prev_depth: texture_2d<f32>;
@group(0) @binding(11) var out_y: texture_storage_2d<rgba16float, write>;
@group(0) @binding(12) var out_cocg: texture_storage_2d<rg16float, write>;
@group(0) @binding(13) var out_ao: texture_storage_2d<r16float, write>;
@group(0) @binding(14) var out_length: texture_storage_2d<r16float, write>;
@group(0) @binding(15) var out_depth: texture_storage_2d<r32float, write>;

struct HistoryTexel {
    ok: bool,
    y: vec4<f32>,
    cocg: vec2<f32>,
    ao: f32,
    length: f32,
}

// Last frame's accumulation at texel `q`, ok where it is inside the image, finite, has
// history and saw the surface at `world`.
fn history_texel(q: vec2<i32>, size: vec2<u32>, world: vec3<f32>) -> HistoryTexel {
    var h: HistoryTexel;
    if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size)) {
        return h;
    }
    h.y = textureLoad(prev_y, q, 0);
    h.cocg = textureLoad(prev_cocg, q, 0).xy;
    h.ao = textureLoad(prev_ao, q, 0).x;
    h.length = textureLoad(prev_length, q, 0).x;
    let z = textureLoad(prev_depth, q, 0).x;
    h.ok = is_finite4(h.y) && is_finite4(vec4<f32>(h.cocg, h.ao, h.length)) && is_finite4(vec4<f32>(z))
        && h.length >= 1.0 && history_depth_agrees(view, world, z, params.distances.z);
    return h;
}

fn store(p: vec2<u32>, y: vec4<f32>, cocg: vec2<f32>, ao: f32, len: f32, z: f32) {
    textureStore(out_y, p, y);
    textureStore(out_cocg, p, vec4<f32>(cocg, 0.0, 0.0));
    textureStore(out_ao, p, vec4<f32>(ao, 0.0, 0.0, 0.0));
    textureStore(out_length, p, vec4<f32>(len, 0.0, 0.0, 0.0));
    textureStore(out_depth, p, vec4<f32>(z, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(depth);
    if any(gid.xy >= size) {
        return;
    }
    let pixel = gid.xy;
    let d = textureLoad(depth, pixel, 0).r;
    if !(d > 0.0) {
        store(pixel, vec4<f32>(0.0), vec2<f32>(0.0), 1.0, 0.0, 0.0);
        return;
    }
    var y = textureLoad(raw_y, pixel, 0);
    var cocg_ao = textureLoad(raw_cocg_ao, pixel, 0);
    if !is_finite4(y) || !is_finite4(vec4<f32>(cocg_ao.xy, 0.0, 0.0)) {
        y = vec4<f32>(0.0);
        cocg_ao = vec4<f32>(0.0, 0.0, cocg_ao.zw);
    }
    var ao = select(1.0, clamp(cocg_ao.z, 0.0, 1.0), is_finite4(vec4<f32>(cocg_ao.z)));
    let motion = textureLoad(gbuffer_motion, pixel, 0).xyz;
    let z = select(0.0, motion.z, is_finite4(vec4<f32>(motion.z)));
    let world = world_from_depth(view, pixel, d);
    let flags = params.config.y;
    let r = reprojection(pixel, motion, world, size);
    if (flags & RTGI_ACCUMULATE) == 0u || (flags & RTGI_RESET) != 0u || !r.valid {
        store(pixel, y, cocg_ao.xy, ao, 1.0, z);
        return;
    }
    var hy = vec4<f32>(0.0);
    var hc = vec2<f32>(0.0);
    var ha = 0.0;
    var hl = 0.0;
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let tap = reprojection_tap(r, k, size);
        let w = tap.weight;
        if !(w > 0.0) {
            continue;
        }
        let h = history_texel(vec2<i32>(tap.texel), size, world);
        if h.ok {
            hy += w * h.y;
            hc += w * h.cocg;
            ha += w * h.ao;
            hl += w * h.length;
            weight += w;
        }
    }
    if weight < REPROJECTION_MIN_WEIGHT {
        hy = vec4<f32>(0.0);
        hc = vec2<f32>(0.0);
        ha = 0.0;
        hl = 0.0;
        weight = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let h = history_texel(r.nearest + vec2<i32>(dx, dy), size, world);
                if h.ok {
                    hy += h.y;
                    hc += h.cocg;
                    ha += h.ao;
                    hl += h.length;
                    weight += 1.0;
                }
            }
        }
        if weight == 0.0 {
            store(pixel, y, cocg_ao.xy, ao, 1.0, z);
            return;
        }
    }
    hy /= weight;
    hc /= weight;
    ha /= weight;
    hl /= weight;
    // Firefly clamp: the whole sample scaled so that its c0 stays within k times the
    // history's local scale (the brightest c0 of its 3x3: a pixel whose few samples all came
    // out dark must not cut what its neighbours see) plus the floor; chroma and direction
    // stay the sample's.
    var cocg = cocg_ao.xy;
    let ff = params.firefly;
    if ff.x > 0.0 && hl >= ff.z {
        var scale = max(hy.x, 0.0);
        let qi = r.nearest;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let t = clamp(qi + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(size) - 1);
                let c = textureLoad(prev_y, t, 0).x;
                if is_finite4(vec4<f32>(c)) {
                    scale = max(scale, c);
                }
            }
        }
        let limit = ff.x * scale + ff.y;
        if y.x > limit {
            let s = limit / y.x;
            y *= s;
            cocg *= s;
        }
    }
    let len = min(hl + 1.0, f32(params.config.z));
    let speed = 1.0 / len;
    store(pixel, mix(hy, y, speed), mix(hc, cocg, speed), mix(ha, ao, speed), len, z);
}
