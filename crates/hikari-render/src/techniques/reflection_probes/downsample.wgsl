// reflection_probes.downsample: level m + 1 of the relit cube maps as the mean of level m's 2 x 2
// texels (the talk's "generate mipmaps"), which the prefilter samples.

@group(0) @binding(0) var src: texture_2d_array<f32>;
@group(0) @binding(1) var dst: texture_storage_2d_array<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if any(gid.xy >= size) || gid.z >= textureNumLayers(dst) {
        return;
    }
    let s = gid.xy * 2u;
    let sum = textureLoad(src, s, gid.z, 0) + textureLoad(src, s + vec2<u32>(1u, 0u), gid.z, 0)
        + textureLoad(src, s + vec2<u32>(0u, 1u), gid.z, 0) + textureLoad(src, s + vec2<u32>(1u, 1u), gid.z, 0);
    textureStore(dst, gid.xy, gid.z, vec4<f32>(0.25 * sum.rgb, 1.0));
}
