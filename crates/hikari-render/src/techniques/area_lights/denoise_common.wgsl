#define_import_path hikari::area_lights_denoise

// What the shadow denoiser's two passes (temporal.wgsl, spatial.wgsl) share: their constants
// and the visibility's definition. CPU twin: area_lights::reference (denoise part).

#import hikari::finite::is_finite4

struct ShadowDenoiseParams {
    // x: SHADOW_DENOISE_* flags; y: history length cap (frames, >= 1); z, w: 0.
    config: vec4<u32>,
    // x: history depth tolerance (fraction of view depth); y: distance to the tangent plane at
    // which the spatial weight reaches 0 (fraction of view depth); z: spatial radius in pixels
    // on a fresh history; w: 0.
    values: vec4<f32>,
}

// Drop the history (camera cut, resize, first frame).
const SHADOW_DENOISE_RESET: u32 = 1u;
// Light (nits, or lux in the alpha) below which a channel's visibility is undefined: the pixel
// keeps its raw shadowed value there, and the spatial filter ignores the channel.
const VISIBILITY_EPS: f32 = 1e-5;
// Largest visibility kept: a channel's ratio may exceed 1 where the picked light is coloured
// (docs/area-lights.md); this only keeps it within f16.
const MAX_VISIBILITY: f32 = 1024.0;
// Largest spatial radius in pixels (settings::MAX_DENOISE_RADIUS_PX).
const MAX_RADIUS_PX: u32 = 8u;

// Per channel (rgb radiance, a illuminance): shadowed / unshadowed where the unshadowed light is
// defined (finite and above VISIBILITY_EPS) and the shadowed one finite, else 1.
fn raw_visibility(shadowed: vec4<f32>, unshadowed: vec4<f32>) -> vec4<f32> {
    var v = vec4<f32>(1.0);
    let ok = is_finite4(shadowed) && is_finite4(unshadowed);
    for (var c = 0; c < 4; c++) {
        if ok && unshadowed[c] > VISIBILITY_EPS {
            v[c] = clamp(shadowed[c] / unshadowed[c], 0.0, MAX_VISIBILITY);
        }
    }
    return v;
}
