// haze.light: the light every froxel scatters towards the camera per unit scattering (the
// talk's L_i): the sun or moon through the shadow maps and the HG phase, the sky's SH convolved
// with the phase times the sky visibility the irradiance probes give there, and the point and
// spot lights, times the albedo and the storage scale. Sampled at this frame's jittered point in
// the froxel (the centre on the cycle's first frame) and blended with last frame's grid read
// where the froxel's centre was (the talk's temporal filtering of jittered samples). Twin:
// `haze::reference::light_grid_jittered` and `temporal`.

#import hikari::view::{View, view_ray_uv}
#import hikari::haze::{HazeParams, HAZE_SUN_SHADOWS, HAZE_SKY, HAZE_SKY_OCCLUSION, HAZE_LOCAL_LIGHTS, HAZE_MAX_HALF, slice_depth, slice_of_depth, froxel_ray}
#import hikari::phase::hg_phase
#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}
#import hikari::sun_shadows::sun_visibility
#import hikari::sky_ambient::{sky_ambient_eval, sky_ambient_average_irradiance}
#import hikari::irradiance_probes::probe_irradiance_at
#import hikari::clouds::cloud_shadow

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: HazeParams;
@group(0) @binding(2) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(3) var light_out: texture_storage_3d<rgba16float, write>;
// xyz: the sample's offset in the froxel (x, y in froxels about its centre, z the fraction of
// the slice's depth); w: the history's weight (0: none, the first frame or a cut).
struct HazeTemporal {
    jitter_blend: vec4<f32>,
    // x: this frame's storage scale over last frame's.
    rescale: vec4<f32>,
}
@group(0) @binding(4) var<uniform> temporal: HazeTemporal;
@group(0) @binding(5) var history: texture_3d<f32>;
@group(0) @binding(6) var history_sampler: sampler;

const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);
// The probes' interior mask for a point in the air: none, each probe weighs by its
// barycentric or grid weight alone.
const AIR_INTERIOR_MASK: f32 = 0.5;

// The talk's haze AO: the average sky visibility at x, from the irradiance probes. Their
// irradiance averaged over every normal (the SH's constant term, n = 0) over the open sky's
// (`open`, the luminance of sky_ambient_average_irradiance), by luminance, at most 1; 1 where
// no probe covers x. Twin: reference::probe_sky_visibility.
fn sky_visibility_at(x: vec3<f32>, open: f32) -> f32 {
    let probe = probe_irradiance_at(x, vec3<f32>(0.0), AIR_INTERIOR_MASK);
    if !(probe.w > 0.0) || !(open > 0.0) {
        return 1.0;
    }
    return clamp(dot(probe.rgb, LUMA) / open, 0.0, 1.0);
}

// The sky visibility averaged over `params.lights.y` points spread evenly along the depth of
// froxel slice k on the ray v. Twin: reference::froxel_sky_visibility.
fn froxel_sky_visibility(v: vec3<f32>, k: f32) -> f32 {
    let z0 = slice_depth(params, k);
    let z1 = slice_depth(params, k + 1.0);
    let inv_cos = 1.0 / max(dot(v, view.forward_near.xyz), 1e-4);
    let n = max(params.lights.y, 1u);
    let open = dot(sky_ambient_average_irradiance(), LUMA);
    var sum = 0.0;
    for (var i = 0u; i < n; i++) {
        let z = mix(z0, z1, (f32(i) + 0.5) / f32(n));
        sum += sky_visibility_at(view.position.xyz + v * (z * inv_cos), open);
    }
    return sum / f32(n);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id >= params.grid.xyz) {
        return;
    }
    let jitter = temporal.jitter_blend.xyz;
    let v = view_ray_uv(view, (vec2<f32>(id.xy) + 0.5 + jitter.xy) / vec2<f32>(params.grid.xy));
    let k = f32(id.z);
    let z = mix(slice_depth(params, k), slice_depth(params, k + 1.0), jitter.z);
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
        var sky = max(sky_ambient_eval(v, vec3<f32>(1.0, g, g * g)), vec3<f32>(0.0));
        if (flags & HAZE_SKY_OCCLUSION) != 0u {
            sky *= froxel_sky_visibility(v, k);
        }
        l += sky;
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
    let blend = temporal.jitter_blend.w;
    if blend > 0.0 {
        // The froxel's centre in last frame's grid.
        let c = froxel_ray(params, view, id.xy);
        let zc = 0.5 * (slice_depth(params, k) + slice_depth(params, k + 1.0));
        let xc = view.position.xyz + c * (zc / max(dot(c, view.forward_near.xyz), 1e-4));
        let clip = view.prev_view_proj * vec4<f32>(xc, 1.0);
        if clip.w > 1e-4 {
            let uvw = vec3<f32>(0.5 + 0.5 * clip.x / clip.w, 0.5 - 0.5 * clip.y / clip.w, slice_of_depth(params, clip.w) / f32(params.grid.z));
            if all(uvw >= vec3<f32>(0.0)) && all(uvw <= vec3<f32>(1.0)) {
                let old = textureSampleLevel(history, history_sampler, uvw, 0.0).rgb * temporal.rescale.x;
                let blended = mix(out, old, blend);
                out = select(out, min(blended, vec3<f32>(HAZE_MAX_HALF)), blended >= vec3<f32>(0.0));
            }
        }
    }
    textureStore(light_out, id, vec4<f32>(out, 0.0));
}
