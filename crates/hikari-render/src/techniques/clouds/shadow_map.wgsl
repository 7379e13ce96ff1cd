// clouds.shadow_map: the sun's transmittance through the cloud layer for paths that enter it at
// each texel's centre on the layer's base (`CloudParams::shadow`): `cloud_shadow_at` of that
// point, which is the transmittance of every point below whose path to the sun enters there
// (the march depends only on where the path enters). `cloud_shadow` (lookup.wgsl) blends four
// texels. Twin: `clouds::reference::shadow_map`.

#import hikari::cloud_density::{CloudParams, cloud_shadow_at}

@group(0) @binding(0) var<uniform> params: CloudParams;
@group(0) @binding(1) var map_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = u32(params.shadow.w);
    if any(id.xy >= vec2<u32>(size)) {
        return;
    }
    let xz = params.shadow.xy + (vec2<f32>(id.xy) + 0.5) * params.shadow.z;
    let t = cloud_shadow_at(params, vec3<f32>(xz.x, params.layer.x, xz.y));
    textureStore(map_out, id.xy, vec4<f32>(t, 0.0, 0.0, 1.0));
}
