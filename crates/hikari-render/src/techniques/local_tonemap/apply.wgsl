// The local tonemap's gain as an image, `local_tonemap.log2_gain`: only for dumps and tests.
// The frame's tonemap evaluates the same `local_gain` per pixel instead of reading this image
// (12 bytes a pixel less at 4K: this pass's radiance read and gain write, and the tonemap's
// gain read).

#import hikari::local_tonemap::{LocalTonemapParams, grid_log2, local_gain}

@group(0) @binding(0) var<uniform> params: LocalTonemapParams;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> exposure: vec4<f32>;
@group(0) @binding(3) var grid: texture_3d<f32>;
@group(0) @binding(4) var wide: texture_2d<f32>;
@group(0) @binding(5) var gain: texture_storage_2d<r16float, write>;

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gain);
    if any(id.xy >= size) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let v = grid_log2(textureLoad(radiance, id.xy, 0).rgb, exposure.x, params);
    textureStore(gain, id.xy, vec4<f32>(local_gain(v, uv, params, exposure.w, grid, wide), 0.0, 0.0, 0.0));
}
