// Frame-graph checks: writes a constant into a texture.

struct FillParams {
    value: vec4<f32>,
}

@group(0) @binding(0) var target_tex: texture_storage_2d<rgba16float, write>;
@group(0) @binding(1) var<uniform> params: FillParams;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(target_tex)) {
        textureStore(target_tex, id.xy, params.value);
    }
}
