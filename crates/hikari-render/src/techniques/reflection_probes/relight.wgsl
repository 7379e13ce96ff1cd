// reflection_probes.relight: the captured texels of this frame's probes lit by today's light
// (the talk's relighting), into level 0 of `reflection_probes.relit`. A texel is
//   emission + albedo / pi * (E_sun max(n.l, 0) shadow cloud_shadow + E_probes + E_lights)
// where the shadow is the talk's cube-map shadow tracing (the sun's ray from the texel leaves
// the probe's box at q; the texel is lit where the capture point sees sky towards q, in a PCF
// footprint), E_probes the irradiance probes at the texel (the sky's SH where none cover it),
// and E_lights the point and spot lights inside the probe's box, unshadowed. Sky texels take
// the sky and its clouds, without the sun's disk (the sun's specular is direct light).
// Thread (0, 0) of a probe's first face also stores the light at its capture point (the
// lookup's luminance normalisation): the probes' and the lights' inside the box, as the texels
// have it. Twin: `reflection_probes::reference::relight_texel`.

#import hikari::octahedral::oct_decode
#import hikari::reflection_probe_math::{ReflectionProbeGpu, rp_texel_direction, rp_face_uv, rp_box_exit, rp_box_light_irradiance}
#import hikari::scene_gpu::LightGpu
#import hikari::sky::sky_background_no_disks
#import hikari::sky_ambient::{sky_ambient_eval, sky_ambient_irradiance}
#import hikari::irradiance_probes::probe_irradiance_at
#import hikari::clouds::{clouds_over_sky, cloud_shadow}

struct RelightParams {
    // xyz: unit vector towards the sun or moon; w: its illuminance, lux.
    sun: vec4<f32>,
    // rgb: its colour, luminance 1.
    sun_color: vec4<f32>,
    // x: unused; y: probes in all; z: probes relit (listed in `relit_list`); w: RELIGHT_* flags.
    probes: vec4<u32>,
    // x: lights; y: texels a side; z: PCF radius in texels; w: unused.
    config: vec4<u32>,
    // x: lux below which a light is cut off.
    cutoff: vec4<f32>,
}

const RELIGHT_SHADOWS: u32 = 1u;
const RELIGHT_SKY: u32 = 2u;
const RELIGHT_PROBES: u32 = 4u;
const PI: f32 = 3.14159265358979;
const MAX_HALF: f32 = 65000.0;

@group(0) @binding(0) var<uniform> params: RelightParams;
@group(0) @binding(1) var<storage, read> probes: array<ReflectionProbeGpu>;
@group(0) @binding(2) var capture_albedo: texture_2d_array<f32>;
@group(0) @binding(3) var capture_normal_depth: texture_2d_array<f32>;
@group(0) @binding(4) var capture_emission: texture_2d_array<f32>;
@group(0) @binding(5) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(6) var relit: texture_storage_2d_array<rgba16float, write>;
// Per probe: the luminance of the irradiance at its capture point as an L1 function of the
// normal (mean, then x, y, z slopes), lux.
@group(0) @binding(7) var<storage, read_write> capture_light: array<vec4<f32>>;
// The probes relit this frame.
@group(0) @binding(8) var<storage, read> relit_list: array<u32>;

const EXPOSURE_LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Irradiance at x (normal n, interior mask): the probes, else the sky's SH.
fn ambient(x: vec3<f32>, n: vec3<f32>, interior: f32) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    if (params.probes.w & RELIGHT_SKY) != 0u {
        e = sky_ambient_irradiance(n);
    }
    if (params.probes.w & RELIGHT_PROBES) != 0u {
        let p = probe_irradiance_at(x, n, interior);
        e = select(e, p.rgb, p.w > 0.0);
    }
    return e;
}

// The talk's cube-map shadow: the fraction of a PCF footprint round the direction of q (where
// the sun's ray from x leaves the box) in which the capture point sees sky.
fn cube_map_shadow(probe: u32, p: ReflectionProbeGpu, x: vec3<f32>, l: vec3<f32>) -> f32 {
    let t = rp_box_exit(p, x, l);
    if t <= 0.0 {
        // Outside the box: the cube map knows nothing of its light.
        return 1.0;
    }
    let q = x + l * t - p.capture.xyz;
    let f = rp_face_uv(q);
    let n = params.config.y;
    let r = i32(params.config.z);
    let centre = vec2<i32>(floor(f.xy * f32(n) - 0.5));
    var lit = 0.0;
    var total = 0.0;
    let layer = probe * 6u + u32(f.z);
    for (var j = 1 - max(r, 1); j <= r; j++) {
        for (var i = 1 - max(r, 1); i <= r; i++) {
            let c = clamp(centre + vec2<i32>(i, j), vec2<i32>(0), vec2<i32>(i32(n) - 1));
            let d = textureLoad(capture_normal_depth, c, layer, 0).z;
            lit += select(0.0, 1.0, d <= 0.0);
            total += 1.0;
        }
    }
    return lit / total;
}

// Irradiance from the point and spot lights inside the probe's box, unshadowed (the box's walls
// would shadow the others).
fn box_lights(p: ReflectionProbeGpu, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    for (var i = 0u; i < params.config.x; i++) {
        e += rp_box_light_irradiance(p, lights[i], params.cutoff.x, x, n);
    }
    return e;
}

// The luminance of the irradiance at the capture point c for normal n: the probes' (or the
// sky's) and, as in the texels, the lights inside the box.
fn capture_luma(p: ReflectionProbeGpu, c: vec3<f32>, n: vec3<f32>, mask: f32) -> f32 {
    return dot(ambient(c, n, mask) + box_lights(p, c, n), EXPOSURE_LUMA);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = params.config.y;
    let count = params.probes.y;
    if any(gid.xy >= vec2<u32>(n)) || gid.z >= params.probes.z * 6u || count == 0u {
        return;
    }
    let face = gid.z % 6u;
    let probe = min(relit_list[gid.z / 6u], count - 1u);
    let p = probes[probe];
    let layer = probe * 6u + face;
    let flags = params.probes.w;
    let sun_lux = params.sun_color.rgb * params.sun.w;

    if gid.x == 0u && gid.y == 0u && face == 0u {
        // The interior mask of the floor straight below the capture point stands for the
        // probe's.
        let mask = textureLoad(capture_albedo, vec2<u32>(n / 2u), probe * 6u + 3u, 0).a;
        let c = p.capture.xyz;
        let e_xp = capture_luma(p, c, vec3<f32>(1.0, 0.0, 0.0), mask);
        let e_xn = capture_luma(p, c, vec3<f32>(-1.0, 0.0, 0.0), mask);
        let e_yp = capture_luma(p, c, vec3<f32>(0.0, 1.0, 0.0), mask);
        let e_yn = capture_luma(p, c, vec3<f32>(0.0, -1.0, 0.0), mask);
        let e_zp = capture_luma(p, c, vec3<f32>(0.0, 0.0, 1.0), mask);
        let e_zn = capture_luma(p, c, vec3<f32>(0.0, 0.0, -1.0), mask);
        // The six axes' mean is an L2 SH's band 0 exactly (bands 1 and 2 cancel in pairs).
        capture_light[probe] = vec4<f32>((e_xp + e_xn + e_yp + e_yn + e_zp + e_zn) / 6.0, 0.5 * (e_xp - e_xn), 0.5 * (e_yp - e_yn), 0.5 * (e_zp - e_zn));
    }

    let dir = rp_texel_direction(face, gid.xy, n);
    let nd = textureLoad(capture_normal_depth, gid.xy, layer, 0);
    var radiance = vec3<f32>(0.0);
    if nd.z <= 0.0 {
        if (flags & RELIGHT_SKY) != 0u {
            let up = sky_ambient_eval(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0));
            radiance = clouds_over_sky(dir, sky_background_no_disks(dir), sun_lux, up);
        }
    } else {
        let x = p.capture.xyz + dir * nd.z;
        let nrm = oct_decode(nd.xy);
        let a = textureLoad(capture_albedo, gid.xy, layer, 0);
        var e = ambient(x, nrm, a.a);
        if params.sun.w > 0.0 {
            let l = params.sun.xyz;
            let cos_l = max(dot(nrm, l), 0.0);
            if cos_l > 0.0 {
                var vis = cloud_shadow(x);
                if (flags & RELIGHT_SHADOWS) != 0u {
                    vis *= cube_map_shadow(probe, p, x, l);
                }
                e += sun_lux * (cos_l * vis);
            }
        }
        e += box_lights(p, x, nrm);
        radiance = a.rgb / PI * e + textureLoad(capture_emission, gid.xy, layer, 0).rgb;
    }
    // NaN fails every comparison: it becomes 0, and nothing exceeds f16.
    radiance = select(vec3<f32>(0.0), min(radiance, vec3<f32>(MAX_HALF)), radiance >= vec3<f32>(0.0));
    textureStore(relit, gid.xy, gid.z, vec4<f32>(radiance, 1.0));
}
