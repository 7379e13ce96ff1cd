// A gain of 0 (no change) where local tonemapping is off.

@group(0) @binding(0) var gain: texture_storage_2d<r16float, write>;

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(gain)) {
        textureStore(gain, id.xy, vec4<f32>(0.0));
    }
}
