// Shadow denoiser, spatial pass: the accumulated visibility averaged over a disc of radius
// r = base / sqrt(history length) pixels (wide on a fresh history, down to the pixel alone
// once r < 1/2), each tap weighted by its distance to the centre's tangent plane and by the
// normals' dot product (gi_denoiser_common's weights), per channel only where the tap's
// unshadowed light is defined. Then the pixel's light: unshadowed x filtered visibility per
// channel, or the raw shadowed light where the unshadowed one is below VISIBILITY_EPS. A
// non-finite tap is dropped where it is read. CPU twin: area_lights::reference::denoise_spatial.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::finite::{is_finite_f, is_finite4}
#import hikari::gi_denoiser_common::{make_surface, geometry_weight}
#import hikari::area_lights_denoise::{ShadowDenoiseParams, VISIBILITY_EPS, MAX_RADIUS_PX}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: ShadowDenoiseParams;
@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var normal_tex: texture_2d<f32>;
@group(0) @binding(4) var visibility: texture_2d<f32>;
@group(0) @binding(5) var history_length: texture_2d<f32>;
@group(0) @binding(6) var shadowed: texture_2d<f32>;
@group(0) @binding(7) var unshadowed: texture_2d<f32>;
@group(0) @binding(8) var out_filtered: texture_storage_2d<rgba16float, write>;
@group(0) @binding(9) var out_radiance: texture_storage_2d<rgba16float, write>;

const MAX_RADIANCE: f32 = 65000.0;

fn finite_or(v: vec4<f32>, fallback: vec4<f32>) -> vec4<f32> {
    return select(fallback, v, is_finite4(v));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_filtered);
    if any(gid.xy >= size) {
        return;
    }
    let pixel = gid.xy;
    let v0 = finite_or(textureLoad(visibility, pixel, 0), vec4<f32>(1.0));
    let s0 = finite_or(textureLoad(shadowed, pixel, 0), vec4<f32>(0.0));
    let u0 = finite_or(textureLoad(unshadowed, pixel, 0), vec4<f32>(0.0));
    var filtered = v0;
    let surface = make_surface(view, pixel, textureLoad(depth_tex, pixel, 0).x, textureLoad(normal_tex, pixel, 0).xy);
    let raw_len = textureLoad(history_length, pixel, 0).x;
    let len = select(1.0, max(raw_len, 1.0), is_finite_f(raw_len));
    let r = params.values.z / sqrt(len);
    if surface.valid && r >= 0.5 {
        let reach = i32(min(u32(ceil(r)), MAX_RADIUS_PX));
        let plane = vec4<f32>(0.0, 0.0, 0.0, params.values.y);
        var acc = vec4<f32>(0.0);
        var acc_w = vec4<f32>(0.0);
        for (var dy = -reach; dy <= reach; dy++) {
            for (var dx = -reach; dx <= reach; dx++) {
                if f32(dx * dx + dy * dy) > r * r {
                    continue;
                }
                let q = vec2<i32>(pixel) + vec2<i32>(dx, dy);
                if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size)) {
                    continue;
                }
                let dq = textureLoad(depth_tex, q, 0).x;
                if !(dq > 0.0) || !is_finite_f(dq) {
                    continue;
                }
                var w = geometry_weight(surface, world_from_depth(view, vec2<u32>(q), dq), plane, vec4<u32>(0u));
                if !(w > 0.0) {
                    continue;
                }
                let oct = textureLoad(normal_tex, q, 0).xy;
                if !is_finite4(vec4<f32>(oct, 0.0, 0.0)) {
                    continue;
                }
                w *= max(dot(surface.normal, oct_decode(oct)), 0.0);
                if !(w > 0.0) {
                    continue;
                }
                // The heavy data, only for taps that count.
                let vq = textureLoad(visibility, q, 0);
                let uq = textureLoad(unshadowed, q, 0);
                if !is_finite4(vq) || !is_finite4(uq) {
                    continue;
                }
                let wc = select(vec4<f32>(0.0), vec4<f32>(w), uq > vec4<f32>(VISIBILITY_EPS));
                acc += wc * vq;
                acc_w += wc;
            }
        }
        filtered = select(v0, acc / max(acc_w, vec4<f32>(1e-30)), acc_w > vec4<f32>(0.0));
    }
    textureStore(out_filtered, pixel, filtered);
    let light = select(s0, u0 * filtered, u0 > vec4<f32>(VISIBILITY_EPS));
    // NaN fails every comparison, so this also turns NaN into 0.
    textureStore(out_radiance, pixel, select(vec4<f32>(0.0), min(light, vec4<f32>(MAX_RADIANCE)), light >= vec4<f32>(0.0)));
}
