// Shadow denoiser, temporal pass: this frame's visibility (the area-light pass's shadowed light
// over its unshadowed light, per channel) blended into its history reprojected by the
// G-buffer's motion vector (nearest texel). The history is dropped off screen, where it is not
// finite, where its view depth differs from where this point was seen last frame by more than
// the tolerance, and on a reset; its length grows while it stays valid, up to the cap, and the
// blend is 1 / length. Non-finite input is replaced where it enters (raw_visibility), so it
// never reaches the history. CPU twin: area_lights::reference::denoise_temporal.

#import hikari::view::{View, world_from_depth, reprojected_texel, history_depth_agrees}
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
    let t = reprojected_texel(pixel, motion, world, size);
    if (params.config.x & SHADOW_DENOISE_RESET) != 0u || t.x < 0 {
        store(pixel, raw, 1.0, z);
        return;
    }
    let q = vec2<u32>(t);
    let hv = textureLoad(prev_visibility, q, 0);
    let hl = textureLoad(prev_length, q, 0).x;
    let hz = textureLoad(prev_depth, q, 0).x;
    if !is_finite4(hv) || !is_finite_f(hl) || !(hl >= 1.0) || !is_finite_f(hz)
        || !history_depth_agrees(view, world, hz, params.values.x) {
        store(pixel, raw, 1.0, z);
        return;
    }
    let len = min(hl + 1.0, f32(max(params.config.y, 1u)));
    store(pixel, mix(hv, raw, 1.0 / len), len, z);
}
