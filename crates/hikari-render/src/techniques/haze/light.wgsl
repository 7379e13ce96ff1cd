// haze.light: the light every froxel scatters towards the camera per unit scattering (the
// talk's L_i) at its slice's middle: the sun or moon through the shadow maps and the HG phase,
// the sky's SH convolved with the phase, and the point and spot lights, times the albedo and
// the storage scale. Twin: `haze::reference::light_grid`.

#import hikari::view::View
#import hikari::haze::{HazeParams, HAZE_SUN_SHADOWS, HAZE_SKY, HAZE_LOCAL_LIGHTS, HAZE_MAX_HALF, slice_depth, froxel_ray}
#import hikari::phase::hg_phase
#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}
#import hikari::sun_shadows::sun_visibility
#import hikari::sky_ambient::sky_ambient_eval
#import hikari::clouds::cloud_shadow

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: HazeParams;
@group(0) @binding(2) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(3) var light_out: texture_storage_3d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id >= params.grid.xyz) {
        return;
    }
    let v = froxel_ray(params, view, id.xy);
    let k = f32(id.z);
    let z = 0.5 * (slice_depth(params, k) + slice_depth(params, k + 1.0));
    let x = view.position.xyz + v * (z / max(dot(v, view.forward_near.xyz), 1e-4));
    let g = params.scatter.y;
    let flags = params.grid.w;
    var l = vec3<f32>(0.0);
    if max(params.sun_lux.x, max(params.sun_lux.y, params.sun_lux.z)) > 0.0 {
        var vis = 1.0;
        if (flags & HAZE_SUN_SHADOWS) != 0u {
            vis = sun_visibility(x, vec3<f32>(0.0));
        }
        vis *= cloud_shadow(x);
        l += params.sun_lux.xyz * vis * hg_phase(dot(params.sun.xyz, v), g);
    }
    if (flags & HAZE_SKY) != 0u {
        // HG's zonal harmonics are g^l: the phase convolution scales SH band l by g^l.
        l += max(sky_ambient_eval(v, vec3<f32>(1.0, g, g * g)), vec3<f32>(0.0));
    }
    if (flags & HAZE_LOCAL_LIGHTS) != 0u {
        let cutoff = params.sun.w;
        for (var i = 0u; i < params.lights.x; i++) {
            let light = lights[i];
            let range = light_range(light, cutoff);
            let to_light = light.position_range.xyz - x;
            let d2 = max(dot(to_light, to_light), 1e-8);
            let xr = d2 / (range * range);
            if xr < 1.0 {
                let dir = to_light * inverseSqrt(d2);
                let a = light_attenuation(light, dir, 1.0 / d2, xr);
                l += light.intensity.rgb * a * hg_phase(dot(dir, v), g);
            }
        }
    }
    var out = l * (params.scatter.x * params.scatter.z);
    // NaN fails the comparison and becomes 0.
    out = select(vec3<f32>(0.0), min(out, vec3<f32>(HAZE_MAX_HALF)), out >= vec3<f32>(0.0));
    textureStore(light_out, id, vec4<f32>(out, 0.0));
}
