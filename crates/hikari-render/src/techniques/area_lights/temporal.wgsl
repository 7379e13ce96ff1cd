// Shadow denoiser, temporal pass: this frame's visibility (the area-light pass's shadowed light
// over its unshadowed light, per channel) blended into its history reprojected by the
// G-buffer's motion vector, bilinearly (hikari::view's reprojection: each of the 2x2 taps
// counts where it is on screen, finite, has history and its view depth agrees with where this
// point was seen last frame within the tolerance; the valid weights renormalised). Where they
// weigh under REPROJECTION_MIN_WEIGHT, the texels of the 3x3 about the nearest one that pass the
// same tests stand in, equally weighted (SVGF's fallback, as the GI's accumulation: at a
// silhouette under TAA's jitter the pixel's own texel saw the other surface); with none, and on
// a reset, the history is dropped. Its length grows while it stays valid, up to the cap, and
// the blend is 1 / length. Non-finite input is replaced where it enters (raw_visibility), so it
// never reaches the history. CPU twin: area_lights::reference::denoise_temporal.

#import hikari::view::{View, world_from_depth, reprojection, reprojection_tap, history_depth_agrees, REPROJECTION_MIN_WEIGHT}
#import hikari::finite::{is_finite_f, is_finite4}
#import hikari::area_lights_denoise::{ShadowDenoiseParams, SHADOW_DENOISE_RESET, raw_visibility}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: ShadowDenoiseParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_motion: texture_2d<f32>;
@group(0) @binding(4) var shadowed: texture_2d<f32>;
@group(0) @binding(5) var unshadowed: texture_2d<f32>;
@group(0) @binding(6) var prev_visibility: texture_2d<f32>;
@group(0) @binding(7) var prev_length: texture_2d<f32>;
@group(0) @binding(8) var prev_depth: texture_2d<f32>;
@group(0) @binding(9) var out_raw: texture_storage_2d<rgba16float, write>;
@group(0) @binding(10) var out_visibility: texture_storage_2d<rgba16float, write>;
@group(0) @binding(11) var out_length: texture_storage_2d<r16float, write>;
@group(0) @binding(12) var out_depth: texture_storage_2d<r32float, write>;

// Last frame's visibility (xyzw) and history length (w of the second) at texel q, where it lies
// on screen, is finite, has history and saw the surface at `world`; length 0 where not.
struct HistoryTexel {
    v: vec4<f32>,
    len: f32,
}

fn history_texel(q: vec2<i32>, size: vec2<u32>, world: vec3<f32>) -> HistoryTexel {
    var h: HistoryTexel;
    h.len = 0.0;
    if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size)) {
        return h;
    }
    let tv = textureLoad(prev_visibility, q, 0);
    let tl = textureLoad(prev_length, q, 0).x;
    let tz = textureLoad(prev_depth, q, 0).x;
    if !is_finite4(tv) || !is_finite_f(tl) || !(tl >= 1.0) || !is_finite_f(tz)
        || !history_depth_agrees(view, world, tz, params.values.x) {
        return h;
    }
    h.v = tv;
    h.len = tl;
    return h;
}

fn store(p: vec2<u32>, v: vec4<f32>, len: f32, z: f32) {
    textureStore(out_visibility, p, v);
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
    let raw = raw_visibility(textureLoad(shadowed, pixel, 0), textureLoad(unshadowed, pixel, 0));
    textureStore(out_raw, pixel, raw);
    let d = textureLoad(depth, pixel, 0).r;
    if !(d > 0.0) || !is_finite_f(d) {
        store(pixel, vec4<f32>(1.0), 0.0, 0.0);
        return;
    }
    let motion = textureLoad(gbuffer_motion, pixel, 0).xyz;
    let z = select(0.0, motion.z, is_finite_f(motion.z));
    let world = world_from_depth(view, pixel, d);
    let r = reprojection(pixel, motion, world, size);
    if (params.config.x & SHADOW_DENOISE_RESET) != 0u || !r.valid {
        store(pixel, raw, 1.0, z);
        return;
    }
    var hv = vec4<f32>(0.0);
    var hl = 0.0;
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let tap = reprojection_tap(r, k, size);
        let w = tap.weight;
        if !(w > 0.0) {
            continue;
        }
        let h = history_texel(vec2<i32>(tap.texel), size, world);
        if h.len >= 1.0 {
            hv += w * h.v;
            hl += w * h.len;
            weight += w;
        }
    }
    if weight < REPROJECTION_MIN_WEIGHT {
        hv = vec4<f32>(0.0);
        hl = 0.0;
        weight = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let h = history_texel(r.nearest + vec2<i32>(dx, dy), size, world);
                if h.len >= 1.0 {
                    hv += h.v;
                    hl += h.len;
                    weight += 1.0;
                }
            }
        }
        if weight == 0.0 {
            store(pixel, raw, 1.0, z);
            return;
        }
    }
    hv /= weight;
    hl /= weight;
    let len = min(hl + 1.0, f32(max(params.config.y, 1u)));
    store(pixel, mix(hv, raw, 1.0 / len), len, z);
}
