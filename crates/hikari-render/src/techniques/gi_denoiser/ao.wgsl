// The RTAO denoiser (Metro Exodus, GDC 2019): adaptive sampling, up to 64 Poisson-disk samples
// rotated once a frame, the count scaled by the AO's 3x3 variance; two horizontally adjacent
// pixels a thread, which share one set of samples when no edge lies between them (same
// tangent plane within the tolerance, normals within EDGE_NORMAL_COS). Weights: geometry
// (distance to the tangent plane) times the normal's dot product. The world radius is capped
// at a multiple of the harmonic mean hit distance of the 5x5 neighbourhood's rays (AO varies
// over about the distance to the occluders). Output:
// lerp(denoised, input, 0.5 * accumulation speed). CPU twin: gi_denoiser/reference.rs `ao_pass`.

#import hikari::view::View
#import hikari::octahedral::oct_decode
#import hikari::finite::{is_finite_f, is_finite4}
#import hikari::gi_denoiser_common::{GiDenoiserParams, Surface, make_surface, radius_scale_z, radius_scale_variance, radius_pixels, combine_weight, geometry_weight, disk_point, moments_3x3, hit_radius_cap, TangentPlane, tangent_plane, sample_weight}

@group(0) @binding(0) var<uniform> params: GiDenoiserParams;
@group(0) @binding(1) var<uniform> view: View;
@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var normal_tex: texture_2d<f32>;
@group(0) @binding(4) var ao_tex: texture_2d<f32>;
@group(0) @binding(5) var history_tex: texture_2d<f32>;
// The 5x5 harmonic mean hit distance in metres (hit_mean.wgsl; 0: no hit).
@group(0) @binding(6) var hit_mean_tex: texture_2d<f32>;
@group(0) @binding(7) var out_ao: texture_storage_2d<r16float, write>;

// Two pixels whose normals differ by more than about 25 degrees do not share samples.
const EDGE_NORMAL_COS: f32 = 0.9;
// The fewest samples a pixel takes, however flat its AO.
const MIN_SAMPLES: u32 = 8u;
struct AoPixel {
    surface: Surface,
    // Input AO, 1 (open) where the input was not finite.
    ao: f32,
    ao_ok: bool,
    // 0.5 * accumulation speed.
    keep: f32,
    // F(variance) of the AO over 3x3.
    variance_scale: f32,
    // Largest world radius in metres from the neighbourhood's hit distances (NO_CAP: none).
    radius_cap: f32,
}

fn load_pixel(pixel: vec2<u32>, size: vec2<u32>) -> AoPixel {
    var p: AoPixel;
    p.surface = make_surface(
        view,
        pixel,
        textureLoad(depth_tex, pixel, 0).x,
        textureLoad(normal_tex, pixel, 0).xy
    );
    let raw = textureLoad(ao_tex, pixel, 0).x;
    p.ao_ok = is_finite_f(raw);
    p.ao = select(1.0, raw, p.ao_ok);
    let raw_history = textureLoad(history_tex, pixel, 0).x;
    let history = select(1.0, raw_history, is_finite_f(raw_history));
    p.keep = combine_weight(history, params.scales);
    let moments = moments_3x3(ao_tex, pixel, size);
    p.variance_scale = radius_scale_variance(moments.x, moments.y, params.scales);
    p.radius_cap = hit_radius_cap(textureLoad(hit_mean_tex, pixel, 0).x, params.scales.w, history, params.flags);
    return p;
}

// Weighted sum of the AO samples around `centre_px` (pixel units) against the surface `s`,
// starting from the centre sum `acc_in` and weight `acc_w_in`. `checked`: drop every sample
// whose texels are not finite (see filter_ao).
fn gather_ao(centre_px: vec2<f32>, s: Surface, plane: TangentPlane, radius: f32, count: u32, acc_in: f32, acc_w_in: f32, size: vec2<u32>, checked: bool) -> vec2<f32> {
    var acc = acc_in;
    var acc_w = acc_w_in;
    for (var i = 0u; i < count; i++) {
        let q = vec2<i32>(floor(centre_px + disk_point(i, params.disk[i / 2u], params.rotation) * radius));
        // The geometry weight here, the normal weight below: the AO's fetch then goes out
        // beside the normal's (15 % faster in the temple than both weights first).
        var w = sample_weight(depth_tex, normal_tex, view, plane, s, q, size, params.flags, false, checked);
        if !(w > 0.0) {
            continue;
        }
        let oct = textureLoad(normal_tex, q, 0).xy;
        if checked && !is_finite4(vec4<f32>(oct, 0.0, 0.0)) {
            continue;
        }
        w *= max(dot(s.normal, oct_decode(oct)), 0.0);
        let v = textureLoad(ao_tex, q, 0).x;
        if !(w > 0.0) || (checked && !is_finite_f(v)) {
            continue;
        }
        acc += w * v;
        acc_w += w;
    }
    return vec2<f32>(acc, acc_w);
}

// Weighted mean AO of the samples around `centre_px` against the surface `s`, starting from
// the centre sum `acc_in` and weight `acc_w_in`. The samples are summed first without finite
// tests (the loop is bound by arithmetic); only a non-finite sum sums them again dropping
// each non-finite texel, which with finite texels gives the same sum.
fn filter_ao(centre_px: vec2<f32>, s: Surface, variance_scale: f32, radius_cap: f32, acc_in: f32, acc_w_in: f32, size: vec2<u32>) -> vec2<f32> {
    let radius_m = min(params.radius.x * radius_scale_z(s.view_z, params.rotation.w) * variance_scale, radius_cap);
    let radius = radius_pixels(radius_m, s.view_z, params.radius, params.rotation);
    let count = min(
        max(u32(ceil(f32(params.flags.x) * variance_scale)), min(MIN_SAMPLES, params.flags.x)),
        params.flags.x
    );
    let plane = tangent_plane(view, s, params.radius);
    let sum = gather_ao(centre_px, s, plane, radius, count, acc_in, acc_w_in, size, false);
    if is_finite4(vec4<f32>(sum, 0.0, 0.0)) {
        return sum;
    }
    return gather_ao(centre_px, s, plane, radius, count, acc_in, acc_w_in, size, true);
}

fn combine(p: AoPixel, acc: vec2<f32>) -> f32 {
    if !(acc.y > 0.0) {
        return p.ao;
    }
    let k = select(0.0, p.keep, p.ao_ok);
    return clamp(mix(acc.x / acc.y, p.ao, k), 0.0, 1.0);
}

fn centre_weight(p: AoPixel) -> f32 {
    return select(0.0, 1.0, p.ao_ok);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(out_ao);
    let pa = vec2<u32>(id.x * 2u, id.y);
    if any(pa >= size) {
        return;
    }
    let pb = pa + vec2<u32>(1u, 0u);
    let has_b = pb.x < size.x;
    let a = load_pixel(pa, size);
    var b: AoPixel;
    if has_b {
        b = load_pixel(pb, size);
    }

    let shared_ok = has_b && a.surface.valid && b.surface.valid
        && geometry_weight(a.surface, b.surface.position, params.radius, params.flags) > 0.0
        && dot(a.surface.normal, b.surface.normal) >= EDGE_NORMAL_COS;
    if shared_ok {
        // One set of samples about the pair's midpoint, against a's tangent plane.
        let acc = filter_ao(
            vec2<f32>(f32(pa.x) + 1.0, f32(pa.y) + 0.5),
            a.surface,
            max(a.variance_scale, b.variance_scale),
            max(a.radius_cap, b.radius_cap),
            centre_weight(a) * a.ao + centre_weight(b) * b.ao,
            centre_weight(a) + centre_weight(b),
            size
        );
        textureStore(out_ao, pa, vec4<f32>(combine(a, acc), 0.0, 0.0, 1.0));
        textureStore(out_ao, pb, vec4<f32>(combine(b, acc), 0.0, 0.0, 1.0));
        return;
    }
    var out_a = a.ao;
    if a.surface.valid {
        out_a = combine(a, filter_ao(vec2<f32>(pa) + 0.5, a.surface, a.variance_scale, a.radius_cap, centre_weight(a) * a.ao, centre_weight(a), size));
    }
    textureStore(out_ao, pa, vec4<f32>(out_a, 0.0, 0.0, 1.0));
    if has_b {
        var out_b = b.ao;
        if b.surface.valid {
            out_b = combine(b, filter_ao(vec2<f32>(pb) + 0.5, b.surface, b.variance_scale, b.radius_cap, centre_weight(b) * b.ao, centre_weight(b), size));
        }
        textureStore(out_ao, pb, vec4<f32>(out_b, 0.0, 0.0, 1.0));
    }
}
