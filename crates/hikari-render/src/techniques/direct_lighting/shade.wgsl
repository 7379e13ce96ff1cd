// Deferred direct lighting: the sun (or moon) with its cascaded shadows, point and spot
// lights culled per 16x16 tile, emissive surfaces, and the clearly named placeholders for sky
// and ambient light that the atmosphere and probe issues replace. BRDF: hikari::brdf (GGX with
// anisotropy, height-correlated Smith, Schlick Fresnel, multiple-scattering compensation,
// albedo-scaled Lambert).
// Output: radiance in nits. CPU twin: reference::direct_lighting.

#import hikari::view::{View, view_ray, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::brdf::{BrdfMaterial, brdf_view, brdf_light_weights, brdf_apply_weights, brdf_material_fresnel, brdf_material_f0, brdf_material_f90}
#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}
#import hikari::sun_shadows::sun_visibility
#import hikari::sky::sky_background
#import hikari::clouds::{clouds_over_sky, cloud_shadow}
#import hikari::sky_ambient::{sky_ambient_eval, sky_ambient_irradiance, sky_ambient_specular}
#import hikari::irradiance_probes::probe_irradiance_at
#import hikari::rtgi_resolve::{rtgi_signal, rtgi_resolve_diffuse, rtgi_resolve_specular}
#import hikari::reflection_probe_math::{ReflectionProbeGpu, RP_ON, RP_HORIZON, RP_PARALLAX_ROUGHNESS, RP_NORMALIZE, rp_box_weight, rp_lookup_direction, rp_normalization, rp_horizon_occlusion, rp_box_light_irradiance}
#import hikari::tile_bounds::{tile_bounds, tile_bounds_distance2, TILE_BOUNDS_FAR}

struct LightingParams {
    // xyz: unit vector towards the sun; w: illuminance in lux.
    direction_lux: vec4<f32>,
    // rgb: sun colour with luminance 1.
    color: vec4<f32>,
    // rgb: placeholder sky radiance at the zenith, in nits.
    sky_zenith: vec4<f32>,
    // rgb: placeholder sky radiance at the horizon, in nits.
    sky_horizon: vec4<f32>,
    // x: number of lights; y: LIGHTING_* flags.
    config: vec4<u32>,
    // x: illuminance in lux below which a punctual light is cut off this frame.
    cutoff: vec4<f32>,
    // The reflection probes: x probes, y roughness levels, z RP_* flags.
    reflection: vec4<u32>,
    // x: their normalisation's largest ratio.
    reflection_values: vec4<f32>,
}

const LIGHTING_SUN: u32 = 1u;
const LIGHTING_PUNCTUAL: u32 = 2u;
const LIGHTING_EMISSIVE: u32 = 4u;
const LIGHTING_PLACEHOLDER_AMBIENT: u32 = 8u;
const LIGHTING_SKY: u32 = 16u;
const LIGHTING_PROBES: u32 = 32u;
const LIGHTING_RTGI: u32 = 64u;
const LIGHTING_REFLECTION_PROBES: u32 = 128u;

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: LightingParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_emissive: texture_2d<f32>;
@group(0) @binding(7) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(8) var out_radiance: texture_storage_2d<rgba16float, write>;
// Illuminance in lux arriving at the surface (sun, lights, ambient; not its own emission), the
// exposure's meter; -1 on the sky.
@group(0) @binding(9) var out_illuminance: texture_storage_2d<r32float, write>;
// Radiance of the area lights and shadowed point and spot lights (area_lights.shade), nits;
// alpha: the lux they bring to the surface.
@group(0) @binding(10) var area_light_radiance: texture_2d<f32>;
// The ray-traced GI (LIGHTING_RTGI): luminance L1 SH, CoCg, AO.
@group(0) @binding(11) var gi_y: texture_2d<f32>;
@group(0) @binding(12) var gi_cocg: texture_2d<f32>;
@group(0) @binding(13) var gi_ao: texture_2d<f32>;
// The vertex normal before the normal map (the reflection probes' horizon occlusion).
@group(0) @binding(14) var gbuffer_vertex_normal: texture_2d<f32>;
// The relit reflection probes (`ReflectionProbesFrame::lookup`), in this pass's own group and
// uniform: a binding set of their own would be its eighth uniform buffer, one more than
// lavapipe takes in a stage without corrupting its heap.
// Sorted by the boxes' volume, smallest first.
@group(0) @binding(15) var<storage, read> rp_probes: array<ReflectionProbeGpu>;
@group(0) @binding(16) var rp_radiance: texture_cube_array<f32>;
@group(0) @binding(17) var rp_sampler: sampler;
// Per probe: luminance of the irradiance at its capture point, mean and x, y, z slopes (lux).
@group(0) @binding(18) var<storage, read> rp_capture_light: array<vec4<f32>>;

const PI: f32 = 3.14159265358979;
// Largest finite f16 is 65504; stay below it so no pixel turns into infinity.
const MAX_RADIANCE: f32 = 65000.0;
const MAX_TILE_LIGHTS: u32 = 256u;

var<workgroup> tile_count: atomic<u32>;
// Rec.709 luminance weights, for the illuminance the exposure meters.
const EXPOSURE_LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

var<workgroup> tile_lights: array<u32, MAX_TILE_LIGHTS>;
// 1 / range^2 of each listed light, found once a tile rather than once a pixel.
var<workgroup> tile_inv_range2: array<f32, MAX_TILE_LIGHTS>;

fn sky_placeholder(dir: vec3<f32>) -> vec3<f32> {
    let t = clamp(dir.y, 0.0, 1.0);
    return mix(params.sky_horizon.rgb, params.sky_zenith.rgb, sqrt(t));
}

// Irradiance from the placeholder sky on a surface with normal n: the sky is treated as a
// uniform upper hemisphere of the mean of zenith and horizon, the ground as black, which
// gives E = pi * L * (1 + n.y) / 2.
fn ambient_placeholder(n: vec3<f32>) -> vec3<f32> {
    let l = 0.5 * (params.sky_zenith.rgb + params.sky_horizon.rgb);
    return PI * l * 0.5 * (1.0 + n.y);
}

// Placeholder specular ambient: the placeholder sky seen in the mirror direction, blurred
// towards its mean with roughness, weighted by Fresnel at n.v; black below the horizon.
fn specular_placeholder(m: BrdfMaterial, n: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let r = reflect(-v, n);
    let mean = 0.5 * (params.sky_zenith.rgb + params.sky_horizon.rgb);
    let env = mix(sky_placeholder(r), mean, m.perceptual_roughness) * select(0.0, 1.0, r.y > 0.0);
    return brdf_material_fresnel(m, max(dot(n, v), 0.0)) * env;
}

// The relit reflection probes' reflected radiance (rgb, nits, before Fresnel) at world point x
// of mapped normal nm and vertex normal nv, seen from v (towards the eye), perceptual
// roughness `roughness`, from the probes whose boxes hold x (smallest first, each fading out
// over its blend distance into the next: the talk's nesting); `e_luma`: the luminance of the
// ambient irradiance the surface receives (lux), for the normalisation, to which each probe
// adds the unshadowed light of the tile's lights inside its box (its texels hold that light,
// and so does its capture light). w: the probes' coverage, 0 to 1. Twin:
// `reflection_probes::reference::lookup`.
fn reflection_probe_radiance(x: vec3<f32>, nm: vec3<f32>, nv: vec3<f32>, v: vec3<f32>, roughness: f32, e_luma: f32, tile_lights_n: u32) -> vec4<f32> {
    let flags = params.reflection.z;
    if (flags & RP_ON) == 0u {
        return vec4<f32>(0.0);
    }
    let r = reflect(-v, nm);
    let alpha = roughness * roughness;
    let levels = f32(max(params.reflection.y, 1u) - 1u);
    var sum = vec3<f32>(0.0);
    var covered = 0.0;
    for (var i = 0u; i < params.reflection.x; i++) {
        let p = rp_probes[i];
        let w = rp_box_weight(p, x);
        if w <= 0.0 {
            continue;
        }
        let at = rp_lookup_direction(p, x, r, alpha, levels, (flags & RP_PARALLAX_ROUGHNESS) != 0u);
        var c = textureSampleLevel(rp_radiance, rp_sampler, at.xyz, i, at.w).rgb;
        if (flags & RP_NORMALIZE) != 0u {
            var local = vec3<f32>(0.0);
            for (var k = 0u; k < tile_lights_n; k++) {
                local += rp_box_light_irradiance(p, lights[tile_lights[k]], params.cutoff.x, x, nm);
            }
            c *= rp_normalization(rp_capture_light[i], nm, e_luma + dot(local, EXPOSURE_LUMA), params.reflection_values.x);
        }
        let take = (1.0 - covered) * w;
        sum += c * take;
        covered += take;
        if covered >= 0.999 {
            break;
        }
    }
    if (flags & RP_HORIZON) != 0u {
        sum *= 1.0 - rp_horizon_occlusion(nm, nv, r, alpha);
    }
    return vec4<f32>(sum, covered);
}

// Specular occlusion from ambient occlusion (Lagarde and de Rousiers 2014): a smooth lobe
// looking out of a crease is occluded less than the cosine-weighted AO says.
fn specular_occlusion(n_dot_v: f32, ao: f32, perceptual_roughness: f32) -> f32 {
    let alpha = perceptual_roughness * perceptual_roughness;
    return clamp(pow(n_dot_v + ao, exp2(-16.0 * alpha - 1.0)) - 1.0 + ao, 0.0, 1.0);
}

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let size = textureDimensions(out_radiance);
    let pixel = gid.xy;
    let inside = all(pixel < size);
    if lid == 0u {
        atomicStore(&tile_count, 0u);
    }
    var d = 0.0;
    var world = vec3<f32>(0.0);
    var lo = vec3<f32>(TILE_BOUNDS_FAR);
    var hi = vec3<f32>(-TILE_BOUNDS_FAR);
    if inside {
        d = textureLoad(depth, pixel, 0).r;
        if d > 0.0 {
            world = world_from_depth(view, pixel, d);
            lo = world;
            hi = world;
        }
    }
    let bounds = tile_bounds(lid, lo, hi);

    // Cull the lights against the bounds of the tile's visible surfaces: to shade them, and for
    // the reflection probes' normalisation (whose texels they light).
    let rp_lights = (params.reflection.z & (RP_ON | RP_NORMALIZE)) == (RP_ON | RP_NORMALIZE);
    let light_count = select(0u, params.config.x, (params.config.y & LIGHTING_PUNCTUAL) != 0u || rp_lights);
    if bounds.lo.x <= bounds.hi.x {
        for (var i = lid; i < light_count; i += 256u) {
            let range = light_range(lights[i], params.cutoff.x);
            if tile_bounds_distance2(bounds, lights[i].position_range.xyz) < range * range {
                let slot = atomicAdd(&tile_count, 1u);
                if slot < MAX_TILE_LIGHTS {
                    tile_lights[slot] = i;
                    tile_inv_range2[slot] = 1.0 / (range * range);
                }
            }
        }
    }
    let tile_lights_n = min(workgroupUniformLoad(&tile_count), MAX_TILE_LIGHTS);

    if !inside {
        return;
    }
    var radiance: vec3<f32>;
    var illuminance = -1.0;
    let flags = params.config.y;
    // Towards the camera: from the surface point where there is one (no second unprojection).
    let v = select(-view_ray(view, pixel), normalize(view.position.xyz - world), d > 0.0);
    if d <= 0.0 {
        radiance = select(vec3<f32>(0.0), sky_placeholder(-v), (flags & LIGHTING_PLACEHOLDER_AMBIENT) != 0u);
        if (flags & LIGHTING_SKY) != 0u {
            let sun_lux = params.color.rgb * params.direction_lux.w;
            radiance = clouds_over_sky(-v, sky_background(-v), sun_lux, sky_ambient_eval(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0)));
        }
    } else {
        let nt = textureLoad(gbuffer_normal, pixel, 0);
        let n = oct_decode(nt.xy);
        let ta = oct_decode(nt.zw);
        let t = normalize(ta - n * dot(n, ta));
        let b = cross(n, t);
        let albedo = textureLoad(gbuffer_albedo, pixel, 0);
        let mat = textureLoad(gbuffer_material, pixel, 0);
        let emissive = textureLoad(gbuffer_emissive, pixel, 0);
        let m = BrdfMaterial(albedo.rgb, mat.x, mat.y, mat.z, emissive.a);
        let brdf = brdf_view(m, n, t, b, v);
        // Every light's colour times its four BRDF weights, summed; the material's colours
        // are applied once after the loop.
        var sum_a = vec3<f32>(0.0);
        var sum_b = vec3<f32>(0.0);
        var sum_c = vec3<f32>(0.0);
        var sum_d = vec3<f32>(0.0);
        illuminance = 0.0;
        if (flags & LIGHTING_SUN) != 0u && params.direction_lux.w > 0.0 {
            let l = params.direction_lux.xyz;
            let e = params.color.rgb * (params.direction_lux.w * sun_visibility(world, n) * cloud_shadow(world));
            let w = brdf_light_weights(brdf, l);
            sum_a += e * w.x;
            sum_b += e * w.y;
            sum_c += e * w.z;
            sum_d += e * w.w;
            illuminance += dot(e, EXPOSURE_LUMA) * max(dot(n, l), 0.0);
        }
        let shaded_lights_n = select(0u, tile_lights_n, (flags & LIGHTING_PUNCTUAL) != 0u);
        for (var k = 0u; k < shaded_lights_n; k++) {
            let light = lights[tile_lights[k]];
            let to_light = light.position_range.xyz - world;
            let d2 = dot(to_light, to_light);
            // No branch for pixels out of range or facing away (the window and the BRDF give
            // them 0): lanes of a warp diverging there cost more than the lighting they skip.
            let x = d2 * tile_inv_range2[k];
            let inv_d = inverseSqrt(max(d2, 1e-8));
            let l = to_light * inv_d;
            let e = light.intensity.rgb * light_attenuation(light, l, inv_d * inv_d, x);
            let w = brdf_light_weights(brdf, l);
            sum_a += e * w.x;
            sum_b += e * w.y;
            sum_c += e * w.z;
            sum_d += e * w.w;
            illuminance += dot(e, EXPOSURE_LUMA) * max(dot(n, l), 0.0);
        }
        radiance = brdf_apply_weights(brdf, sum_a, sum_b, sum_c, sum_d);
        // Image-based light of the far field: irradiance (for the diffuse) and reflected
        // radiance (specular).
        var ambient = vec3<f32>(0.0);
        var ambient_specular = vec3<f32>(0.0);
        if (flags & LIGHTING_PLACEHOLDER_AMBIENT) != 0u {
            ambient += ambient_placeholder(n);
            ambient_specular += specular_placeholder(m, n, v);
        }
        if (flags & LIGHTING_SKY) != 0u {
            // The irradiance probes where they cover the surface (occluded sky, bounce, sun
            // bounce; interior mask in albedo.a), else the sky's SH unoccluded.
            var sky_e = sky_ambient_irradiance(n);
            if (flags & LIGHTING_PROBES) != 0u {
                let probe = probe_irradiance_at(world, n, albedo.a);
                sky_e = select(sky_e, probe.rgb, probe.w > 0.0);
            }
            ambient += sky_e;
            let r = reflect(-v, n);
            let f = brdf_material_fresnel(m, max(dot(n, v), 0.0));
            ambient_specular += f * sky_ambient_specular(r, m.perceptual_roughness);
        }
        var ao = 1.0;
        if (flags & LIGHTING_RTGI) != 0u {
            // Near field: the ray-traced GI (whose misses see the sky) replaces the far field's
            // light, which AO darkens where the two blend.
            let far = smoothstep(params.cutoff.y * (1.0 - params.cutoff.z), params.cutoff.y, length(world - view.position.xyz));
            ao = textureLoad(gi_ao, pixel, 0).x;
            let signal = rtgi_signal(textureLoad(gi_y, pixel, 0), textureLoad(gi_cocg, pixel, 0).xy);
            let near_e = rtgi_resolve_diffuse(signal, n) * PI;
            let alpha = m.perceptual_roughness * m.perceptual_roughness;
            let near_specular = rtgi_resolve_specular(signal, n, v, brdf_material_f0(m), brdf_material_f90(m), alpha);
            ambient = mix(near_e, ambient * ao, far);
            ambient_specular = mix(near_specular, ambient_specular * ao, far);
        }
        if (flags & LIGHTING_REFLECTION_PROBES) != 0u {
            // The relit reflection probes where their boxes hold the surface; the GI's SH
            // specular (near) or the sky's (far) where they do not, and where they fade out.
            let nv_raw = textureLoad(gbuffer_vertex_normal, pixel, 0).xyz;
            let nv = select(n, normalize(nv_raw), dot(nv_raw, nv_raw) > 0.25);
            let probe = reflection_probe_radiance(world, n, nv, v, m.perceptual_roughness, dot(ambient, EXPOSURE_LUMA), tile_lights_n);
            if probe.w > 0.0 {
                let n_dot_v = max(dot(n, v), 0.0);
                let f = brdf_material_fresnel(m, n_dot_v);
                ambient_specular = mix(ambient_specular, f * probe.rgb * specular_occlusion(n_dot_v, ao, m.perceptual_roughness), probe.w);
            }
        }
        radiance += (albedo.rgb * (1.0 - m.metalness) / PI * ambient + ambient_specular) * mat.w;
        illuminance += dot(ambient, EXPOSURE_LUMA) * mat.w;
        if (flags & LIGHTING_EMISSIVE) != 0u {
            radiance += emissive.rgb;
        }
        let area = textureLoad(area_light_radiance, pixel, 0);
        radiance += area.rgb;
        illuminance += area.a;
    }
    // NaN fails every comparison, so this also turns NaN into 0.
    radiance = select(vec3<f32>(0.0), min(radiance, vec3<f32>(MAX_RADIANCE)), radiance >= vec3<f32>(0.0));
    textureStore(out_radiance, pixel, vec4<f32>(radiance, 1.0));
    textureStore(out_illuminance, pixel, vec4<f32>(select(0.0, illuminance, illuminance >= -1.0), 0.0, 0.0, 0.0));
}
