// haze.integrate: each froxel column front to back. With density anti-aliasing (the talk's
// L / alpha) a froxel holds the inscattered light up to its far boundary divided by the opacity
// there, and the opacity in alpha; without, the light itself. Twin:
// `haze::reference::integrate`.

#import hikari::view::View
#import hikari::haze::{HazeParams, HAZE_DENSITY_AA, HAZE_MAX_HALF, optical_depth, opacity, slice_depth, froxel_ray}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: HazeParams;
@group(0) @binding(2) var light_in: texture_3d<f32>;
@group(0) @binding(3) var grid_out: texture_storage_3d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= params.grid.xy) {
        return;
    }
    let v = froxel_ray(params, view, id.xy);
    let inv_cos = 1.0 / max(dot(v, view.forward_near.xyz), 1e-4);
    let aa = (params.grid.w & HAZE_DENSITY_AA) != 0u;
    var transmittance = 1.0;
    var weight = 0.0;
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < params.grid.z; k++) {
        let t0 = slice_depth(params, f32(k)) * inv_cos;
        let t1 = slice_depth(params, f32(k) + 1.0) * inv_cos;
        let tau = optical_depth(params, view.position.xyz + v * t0, v, t1 - t0);
        let a = transmittance * opacity(tau);
        let c = vec3<u32>(id.xy, k);
        let li = textureLoad(light_in, c, 0).rgb;
        sum += li * a;
        weight += a;
        transmittance *= exp(-tau);
        var rgb = sum;
        if aa {
            rgb = select(li, sum / weight, weight > 1e-30);
        }
        textureStore(grid_out, c, vec4<f32>(min(rgb, vec3<f32>(HAZE_MAX_HALF)), 1.0 - transmittance));
    }
}
