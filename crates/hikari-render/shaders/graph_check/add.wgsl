// Frame-graph checks: out = a + b, texel by texel. With `a` a history texture's previous
// frame, this counts frames.

@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<f32>;
@group(0) @binding(2) var sum: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if all(id.xy < textureDimensions(sum)) {
        textureStore(sum, id.xy, textureLoad(a, id.xy, 0) + textureLoad(b, id.xy, 0));
    }
}
