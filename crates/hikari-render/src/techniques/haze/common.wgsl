#define_import_path hikari::haze

// Volumetric haze (Ghost of Tsushima): two analytic density layers with their optical depth
// in closed form, and the froxel grid's slicing. CPU twin: `haze::reference` (same names).

#import hikari::view::{View, view_ray_uv}
#import hikari::phase::hg_phase

struct HazeParams {
    // Froxels across, down, slices; HAZE_* flags.
    grid: vec4<u32>,
    // Near depth (m), first slice's thickness (m), growth per slice, ln(growth).
    slicing: vec4<f32>,
    // Exponential layer: extinction at its height (1/m), 1 / scale height (1/m), height (m).
    exponential: vec4<f32>,
    // Sigmoidal layer: extinction below (d0) and above (d1), middle height (m), half-width (m).
    layer: vec4<f32>,
    // Albedo, HG asymmetry, storage scale (grid = radiance * scale), far distance (m).
    scatter: vec4<f32>,
    // xyz: unit vector towards the sun or moon; w: the local lights' cut-off illuminance (lux).
    sun: vec4<f32>,
    // rgb: the sun's or moon's illuminance (lux), 0 when it does not light the haze.
    sun_lux: vec4<f32>,
    // x: point and spot lights to read; y: sky-visibility lookups along a froxel's depth.
    lights: vec4<u32>,
}

const HAZE_SUN_SHADOWS: u32 = 1u;
const HAZE_SKY: u32 = 2u;
const HAZE_LOCAL_LIGHTS: u32 = 4u;
const HAZE_DENSITY_AA: u32 = 8u;
const HAZE_TRICUBIC: u32 = 16u;
const HAZE_SKY_OCCLUSION: u32 = 32u;
const HAZE_MAX_HALF: f32 = 65504.0;

// (1 - e^-x) / x, accurate near 0.
fn one_minus_exp_over(x: f32) -> f32 {
    if abs(x) < 1e-3 {
        return 1.0 - 0.5 * x + x * x / 6.0;
    }
    return (1.0 - exp(-x)) / x;
}

// 1 - e^-tau, accurate for small tau.
fn opacity(tau: f32) -> f32 {
    let t = max(tau, 0.0);
    if t < 1e-3 {
        return t * (1.0 - 0.5 * t + t * t / 6.0);
    }
    return 1.0 - exp(-t);
}

// Optical depth from `o` along unit `d` over `len` metres (see the twin for the closed forms).
fn optical_depth(p: HazeParams, o: vec3<f32>, d: vec3<f32>, len_in: f32) -> f32 {
    let len = max(len_in, 0.0);
    let x = clamp(len * d.y * p.exponential.y, -80.0, 80.0);
    let e0 = p.exponential.x * exp(clamp(-(o.y - p.exponential.z) * p.exponential.y, -80.0, 80.0));
    let exponential = e0 * len * one_minus_exp_over(x);
    let z0 = o.y - p.layer.z;
    let z1 = z0 + len * d.y;
    let ks2 = p.layer.w * p.layer.w;
    let s0 = sqrt(z0 * z0 + ks2);
    let s1 = sqrt(z1 * z1 + ks2);
    let mean_t = 0.5 + 0.5 * (z0 + z1) / max(s0 + s1, 1e-6);
    let layer = len * (p.layer.x + (p.layer.y - p.layer.x) * mean_t);
    return max(exponential + layer, 0.0);
}

fn slice_depth(p: HazeParams, s: f32) -> f32 {
    return p.slicing.x + p.slicing.y * (exp(s * p.slicing.w) - 1.0) / (p.slicing.z - 1.0);
}

fn slice_of_depth(p: HazeParams, z: f32) -> f32 {
    let x = max((z - p.slicing.x) * (p.slicing.z - 1.0) / p.slicing.y, 0.0);
    // ln(1 + x), accurate near 0.
    var l = log(1.0 + x);
    if x < 1e-3 {
        l = x * (1.0 - 0.5 * x + x * x / 3.0);
    }
    return l / p.slicing.w;
}

fn froxel_ray(p: HazeParams, view: View, c: vec2<u32>) -> vec3<f32> {
    return view_ray_uv(view, (vec2<f32>(c) + 0.5) / vec2<f32>(p.grid.xy));
}

// A cubic B-spline along one axis as two linear taps (Sigg and Hadwiger 2005): the composite's
// tricubic grid and the particles' bicubic light read it.
// The two trilinear positions (normalised) and weights along one axis.
struct Axis {
    pos: vec2<f32>,
    weight: vec2<f32>,
}

fn bspline_axis(u: f32, size: f32) -> Axis {
    let c = u * size - 0.5;
    let i = floor(c);
    let f = c - i;
    let f2 = f * f;
    let f3 = f2 * f;
    let w0 = (1.0 - f) * (1.0 - f) * (1.0 - f) / 6.0;
    let w1 = (3.0 * f3 - 6.0 * f2 + 4.0) / 6.0;
    let w2 = (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) / 6.0;
    let w3 = f3 / 6.0;
    let g0 = w0 + w1;
    let g1 = w2 + w3;
    // Texel i - 1 + w1 / g0 blends texels i - 1 and i as w0 : w1; likewise i + 1 and i + 2.
    let h0 = i - 1.0 + w1 / g0;
    let h1 = i + 1.0 + w3 / g1;
    var a: Axis;
    a.pos = (vec2<f32>(h0, h1) + 0.5) / size;
    a.weight = vec2<f32>(g0, g1);
    return a;
}
