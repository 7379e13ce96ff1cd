// Pure functions of the relit reflection probes, shared by their passes and the lookup: cube
// texel directions (the Vulkan / D3D face order and orientation, which `texture_cube_array`
// samples), the probe box, and the talk's horizon occlusion and roughness compensation.
// CPU twin: `reflection_probes::reference`.
#define_import_path hikari::reflection_probe_math

#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}

// One probe (`reflection_probes::ReflectionProbeGpu`).
struct ReflectionProbeGpu {
    // World to the box's cube [-1, 1]^3.
    to_box: mat4x4<f32>,
    // xyz: capture point (world); w: metres over which the probe fades inside its faces.
    capture: vec4<f32>,
    // xyz: half the box's size along its axes, metres; w: 1 while the probe is resident
    // (captured and near enough to the camera), else 0.
    half_m: vec4<f32>,
}

const RP_ON: u32 = 1u;
const RP_HORIZON: u32 = 2u;
const RP_PARALLAX_ROUGHNESS: u32 = 4u;
const RP_NORMALIZE: u32 = 8u;

const RP_PI: f32 = 3.14159265358979;
// The fraction of the GGX lobe's energy its reflection cone holds (the talk: 0.95).
const RP_CONE_ENERGY: f32 = 0.95;

// Unit direction through the centre of texel `xy` of `face` (n texels a side).
fn rp_texel_direction(face: u32, xy: vec2<u32>, n: u32) -> vec3<f32> {
    let st = (vec2<f32>(xy) + 0.5) / f32(n) * 2.0 - 1.0;
    let s = st.x;
    let t = st.y;
    var d: vec3<f32>;
    switch face {
        case 0u: { d = vec3<f32>(1.0, -t, -s); }
        case 1u: { d = vec3<f32>(-1.0, -t, s); }
        case 2u: { d = vec3<f32>(s, 1.0, t); }
        case 3u: { d = vec3<f32>(s, -1.0, -t); }
        case 4u: { d = vec3<f32>(s, -t, 1.0); }
        default: { d = vec3<f32>(-s, -t, -1.0); }
    }
    return normalize(d);
}

// The face a direction falls on and its [0, 1]^2 coordinates there: (u, v, face).
fn rp_face_uv(d: vec3<f32>) -> vec3<f32> {
    let a = abs(d);
    var face: u32;
    var sc: f32;
    var tc: f32;
    var ma: f32;
    if a.x >= a.y && a.x >= a.z {
        ma = a.x;
        face = select(1u, 0u, d.x > 0.0);
        sc = select(d.z, -d.z, d.x > 0.0);
        tc = -d.y;
    } else if a.y >= a.z {
        ma = a.y;
        face = select(3u, 2u, d.y > 0.0);
        sc = d.x;
        tc = select(-d.z, d.z, d.y > 0.0);
    } else {
        ma = a.z;
        face = select(5u, 4u, d.z > 0.0);
        sc = select(-d.x, d.x, d.z > 0.0);
        tc = -d.y;
    }
    let uv = vec2<f32>(sc, tc) / max(ma, 1e-30) * 0.5 + 0.5;
    return vec3<f32>(uv, f32(face));
}

// Where a ray from x along d (any length) leaves the probe's box, as a multiple of d; 0 when x
// lies outside it.
fn rp_box_exit(p: ReflectionProbeGpu, x: vec3<f32>, d: vec3<f32>) -> f32 {
    let o = (p.to_box * vec4<f32>(x, 1.0)).xyz;
    let dl = (p.to_box * vec4<f32>(d, 0.0)).xyz;
    if any(abs(o) > vec3<f32>(1.0)) {
        return 0.0;
    }
    // Each axis's far plane; an axis the ray runs along never bounds it.
    let safe = select(dl, vec3<f32>(1e-30), abs(dl) < vec3<f32>(1e-30));
    let t = (sign(safe) - o) / safe;
    return max(min(t.x, min(t.y, t.z)), 0.0);
}

// The probe's weight at x: 1 deeper than `blend` metres inside every face, falling linearly to
// 0 at the faces; 0 outside, and 0 for a probe that is not resident.
fn rp_box_weight(p: ReflectionProbeGpu, x: vec3<f32>) -> f32 {
    if p.half_m.w <= 0.0 {
        return 0.0;
    }
    let o = (p.to_box * vec4<f32>(x, 1.0)).xyz;
    let inside_m = (1.0 - abs(o)) * p.half_m.xyz;
    let m = min(inside_m.x, min(inside_m.y, inside_m.z));
    if m < 0.0 {
        return 0.0;
    }
    if p.capture.w <= 0.0 {
        return 1.0;
    }
    return clamp(m / p.capture.w, 0.0, 1.0);
}

// GGX alpha of the cone the talk fits to the lobe: tan(theta_c) = alpha sqrt(u / (1 - u)).
fn rp_cone_tan(alpha: f32) -> f32 {
    return alpha * sqrt(RP_CONE_ENERGY / (1.0 - RP_CONE_ENERGY));
}

// The talk's horizon occlusion: the fraction of the reflection cone around r (GGX alpha) that
// dips below the surface of vertex normal nv because the mapped normal nm tilts away from it.
fn rp_horizon_occlusion(nm: vec3<f32>, nv: vec3<f32>, r: vec3<f32>, alpha: f32) -> f32 {
    let plane = cross(nv, r);
    let len2 = dot(plane, plane);
    if len2 < 1e-12 {
        return 0.0;
    }
    let b = plane * inverseSqrt(len2);
    let np_raw = nm - b * dot(nm, b);
    let np_len2 = dot(np_raw, np_raw);
    if np_len2 < 1e-12 {
        return 0.0;
    }
    let np = np_raw * inverseSqrt(np_len2);
    let theta_p = acos(clamp(dot(np, nv), -1.0, 1.0));
    let theta_r = acos(clamp(dot(r, nv), -1.0, 1.0));
    let theta_c = atan(rp_cone_tan(alpha));
    let theta_o = min(theta_r + theta_c - 0.5 * RP_PI, 2.0 * theta_p);
    if theta_c < 1e-6 {
        // A mirror's cone is its ray.
        return select(0.0, RP_CONE_ENERGY, theta_o > 0.0);
    }
    return RP_CONE_ENERGY * smoothstep(0.0, 2.0 * theta_c, theta_o);
}

// The talk's roughness parallax compensation: the alpha to read the probe with, for a surface
// `d_eye` metres from the reflected point that the capture point sees `d_capture` away.
fn rp_compensated_alpha(alpha: f32, d_eye: f32, d_capture: f32) -> f32 {
    return clamp(alpha * d_eye / max(d_capture, 1e-4), 0.0, 1.0);
}

// Van der Corput / Hammersley point i of n.
fn rp_hammersley(i: u32, n: u32) -> vec2<f32> {
    return vec2<f32>((f32(i) + 0.5) / f32(n), f32(reverseBits(i)) * 2.3283064365386963e-10);
}

// Where a probe is read for a surface at x reflecting along r (GGX alpha): xyz the direction
// from its capture point to where r leaves its box (parallax correction), w the level of
// detail, with the talk's roughness parallax compensation when `compensate`.
fn rp_lookup_direction(p: ReflectionProbeGpu, x: vec3<f32>, r: vec3<f32>, alpha: f32, levels: f32, compensate: bool) -> vec4<f32> {
    let t = rp_box_exit(p, x, r);
    let dir = x + r * t - p.capture.xyz;
    var a = alpha;
    if compensate {
        a = rp_compensated_alpha(alpha, t, length(dir));
    }
    return vec4<f32>(dir, sqrt(a) * levels);
}

// The talk's luminance normalisation: the luminance of the irradiance a surface of normal n
// receives over that at the probe's capture point (`light`: mean and x, y, z slopes), at most
// `max_ratio`.
fn rp_normalization(light: vec4<f32>, n: vec3<f32>, e_luma: f32, max_ratio: f32) -> f32 {
    return clamp(e_luma / max(light.x + dot(light.yzw, n), 1e-6), 0.0, max_ratio);
}

// Irradiance (lux) from one point or spot light at x of normal n, unshadowed, if the light lies
// inside probe p's box, else 0: the light the relight gives the probe's texels, so that the
// lookup's normalisation can count the same light at the capture point and at the surface.
fn rp_box_light_irradiance(p: ReflectionProbeGpu, light: LightGpu, cutoff_lux: f32, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let o = (p.to_box * vec4<f32>(light.position_range.xyz, 1.0)).xyz;
    if any(abs(o) > vec3<f32>(1.0)) {
        return vec3<f32>(0.0);
    }
    let to_light = light.position_range.xyz - x;
    let d2 = dot(to_light, to_light);
    let range = light_range(light, cutoff_lux);
    let inv_d = inverseSqrt(max(d2, 1e-8));
    let l = to_light * inv_d;
    return light.intensity.rgb * (light_attenuation(light, l, inv_d * inv_d, d2 / (range * range)) * max(dot(n, l), 0.0));
}
