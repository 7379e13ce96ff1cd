// Keeps the frame's lit image (direct lighting's radiance, nits) for the next frame's
// lighting of GI hits (`ray_traced_gi.lit`).

@group(0) @binding(0) var lit: texture_2d<f32>;
@group(0) @binding(1) var out_lit: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_lit);
    if any(gid.xy >= size) {
        return;
    }
    textureStore(out_lit, gid.xy, textureLoad(lit, gid.xy, 0));
}
