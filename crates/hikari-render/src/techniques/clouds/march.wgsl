// clouds.march: the paraboloid cloud map, a texel a thread, in time slices of rows. Per
// texel: r = Mie light scattered to the eye per unit sun illuminance (the talk's phase: HG
// lerped from backward, scaled for multiple scattering, to forward by the product of the
// light's and the segment's transmittance), g = light scattered per unit ambient sky radiance,
// b = transmittance. Twin: `clouds::reference::march_texel`.

#import hikari::cloud_density::{CloudParams, CLOUDS_MULTIPLE, CLOUD_PI, cloud_density, cloud_map_dir, cloud_sphere_exit}
#import hikari::phase::hg_phase

@group(0) @binding(0) var<uniform> params: CloudParams;
@group(0) @binding(1) var map_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = params.march.z;
    // This frame's rows: slice, slice + slices, ... (the dispatch covers only them).
    let texel = vec2<u32>(id.x, id.y * params.slice.x + params.slice.y);
    if any(texel >= vec2<u32>(size)) {
        return;
    }
    let uv = (vec2<f32>(texel) + 0.5) / f32(size);
    let q = uv * 2.0 - 1.0;
    if dot(q, q) > 1.0 {
        // Outside the hemisphere's disc: clear sky.
        textureStore(map_out, texel, vec4<f32>(0.0, 0.0, 1.0, 1.0));
        return;
    }
    let d = cloud_map_dir(uv);
    let re = params.layer.z;
    let r0 = re + params.layer.w;
    let t_in = max(cloud_sphere_exit(r0, d.y, re + params.layer.x), 0.0);
    let t_out = min(cloud_sphere_exit(r0, d.y, re + params.layer.y), t_in + params.offset.z);
    let steps = params.march.x;
    let light_steps = params.march.y;
    let dt = max(t_out - t_in, 0.0) / f32(steps);
    // The texel's angular size is (1 + cos zenith) * 2 / size radians.
    let texel_angle = (1.0 + d.y) * 2.0 / f32(size);
    let s = params.sun.xyz;
    let cos_theta = dot(d, s);
    let albedo = params.shape.w;
    let fwd = hg_phase(cos_theta, params.phase.x);
    let back = hg_phase(cos_theta, params.phase.y) * params.phase.z;
    var transmittance = 1.0;
    var mie = 0.0;
    var ambient = 0.0;
    for (var i = 0u; i < steps; i++) {
        let t = t_in + (f32(i) + 0.5) * dt;
        let pos = d * t + vec3<f32>(0.0, r0, 0.0);
        let r = length(pos);
        let height = r - re;
        let sigma = cloud_density(params, pos.xz, height, max(texel_angle * t, dt));
        if sigma <= 0.0 {
            continue;
        }
        let seg = exp(-sigma * dt);
        var light = 0.0;
        var tau_l = 0.0;
        if params.sun.w > 0.0 {
            // To the light: up to the layer's top along the sun, in light_steps samples.
            let up = dot(pos, s) / r;
            let l_len = min(max(cloud_sphere_exit(r, up, re + params.layer.y), 0.0), 4.0 * (params.layer.y - params.layer.x));
            let dl = l_len / f32(light_steps);
            for (var j = 0u; j < light_steps; j++) {
                let lp = pos + s * ((f32(j) + 0.5) * dl);
                tau_l += cloud_density(params, lp.xz, length(lp) - re, dl) * dl;
            }
            light = exp(-tau_l);
        }
        let phase = mix(back, fwd, light * seg);
        // Each segment's scattering integrated against its own extinction (1 - seg) / sigma.
        let weight = transmittance * albedo * (1.0 - seg);
        var sun = light * phase;
        if (params.march.w & CLOUDS_MULTIPLE) != 0u && params.sun.w > 0.0 {
            // Light scattered more than once, as octaves of ever weaker extinction (Wrenninge
            // 2013, as Hillaire 2016): 1/2 e^(-tau/4) + 1/4 e^(-tau/16), isotropic.
            sun += (0.5 * exp(-0.25 * tau_l) + 0.25 * exp(-0.0625 * tau_l)) / (4.0 * CLOUD_PI);
        }
        mie += weight * sun;
        let h = clamp((height - params.layer.x) / (params.layer.y - params.layer.x), 0.0, 1.0);
        // Sky light reaches the tops more than the bases.
        ambient += weight * mix(0.3, 1.0, h);
        transmittance *= seg;
        if transmittance < 1e-3 {
            break;
        }
    }
    textureStore(map_out, texel, vec4<f32>(mie, ambient, transmittance, 1.0));
}
