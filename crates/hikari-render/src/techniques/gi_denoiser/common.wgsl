#define_import_path hikari::gi_denoiser_common

// What the GI passes and the AO denoiser share: their constants, the surface a
// pixel holds, the radius scale and the geometry weight. CPU twin: gi_denoiser/reference.rs.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::finite::{is_finite_f, is_finite4}

struct GiDenoiserParams {
    // x: base radius in metres; y, z: smallest and largest radius in pixels; w: distance to the
    // tangent plane at which the geometry weight reaches 0, as a fraction of view depth.
    radius: vec4<f32>,
    // x, y: cos and sin of this frame's disk rotation; z: metres one pixel spans per metre of
    // view depth; w: view depth in metres at which F(viewZ) = 1/2.
    rotation: vec4<f32>,
    // x: coefficient of variation at which F(variance) reaches 1; y: floor of F(variance) and
    // F(AO); z: largest accumulation speed; w: AO radius cap over the harmonic mean hit
    // distance (0: no cap).
    scales: vec4<f32>,
    // x: samples at most; y: 1 = normal weight; z: bit 0 step geometry falloff, bit 1
    // recurrent history (FLAG_RECURRENT); w: largest step.
    flags: vec4<u32>,
    // Poisson-disk points in the unit disk, two an entry (xy, zw).
    disk: array<vec4<f32>, 32>,
}

struct Surface {
    valid: bool,
    position: vec3<f32>,
    normal: vec3<f32>,
    // Metres along the camera's forward axis.
    view_z: f32,
}

// E[x] and E[x^2] of the red channel over the 3x3 neighbourhood of `pixel`, finite texels
// inside the image only (the variance input of F(variance)).
fn moments_3x3(tex: texture_2d<f32>, pixel: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    var sum = 0.0;
    var sum_sq = 0.0;
    var count = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = vec2<i32>(pixel) + vec2<i32>(dx, dy);
            if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size)) {
                continue;
            }
            let v = textureLoad(tex, q, 0).x;
            if is_finite_f(v) {
                sum += v;
                sum_sq += v * v;
                count += 1.0;
            }
        }
    }
    return vec2<f32>(sum, sum_sq) / max(count, 1.0);
}

// The helpers take the fields of GiDenoiserParams they need, not the struct: a copy of the
// struct with its disk array could be spilled to local memory where the disk is indexed.

// The surface at `pixel` from the G-buffer's reverse-Z depth and octahedral normal; invalid
// for the sky (depth 0) and for any non-finite G-buffer texel.
fn make_surface(view: View, pixel: vec2<u32>, depth: f32, oct: vec2<f32>) -> Surface {
    var s: Surface;
    s.valid = depth > 0.0 && is_finite_f(depth) && is_finite4(vec4<f32>(oct, 0.0, 0.0));
    if !s.valid {
        return s;
    }
    s.position = world_from_depth(view, pixel, depth);
    s.normal = oct_decode(oct);
    s.view_z = dot(s.position - view.position.xyz, view.forward_near.xyz);
    s.valid = s.view_z > 0.0 && is_finite4(vec4<f32>(s.position, s.view_z));
    return s;
}

// F(viewZ) = z / (z + z_half): near the camera a metre spans many pixels, so the world
// radius shrinks there; far away it tends to the base radius.
fn radius_scale_z(view_z: f32, z_half: f32) -> f32 {
    return view_z / (view_z + z_half);
}

// F(variance): the 3x3 coefficient of variation over its reference, floored, at most 1.
// `mean` and `mean_sq` are E[x] and E[x^2] over the 3x3 neighbourhood.
// `scales` is GiDenoiserParams::scales.
fn radius_scale_variance(mean: f32, mean_sq: f32, scales: vec4<f32>) -> f32 {
    let sigma = sqrt(max(mean_sq - mean * mean, 0.0));
    let cv = sigma / (abs(mean) + 1e-4);
    return min(max(cv / scales.x, scales.y), 1.0);
}

// Blur radius in pixels of a world radius `radius_m` at view depth `view_z`; `radius` and
// `rotation` are those of GiDenoiserParams.
fn radius_pixels(radius_m: f32, view_z: f32, radius: vec4<f32>, rotation: vec4<f32>) -> f32 {
    let px = radius_m / (view_z * rotation.z);
    return min(max(px, radius.y), radius.z);
}

// The talk's combiner weight: 0.5 * accumulation speed, with the speed 1 - 1 / history
// length (0 for a fresh pixel, rising as its history grows), capped.
fn combine_weight(history_length: f32, scales: vec4<f32>) -> f32 {
    let speed = 1.0 - 1.0 / max(history_length, 1.0);
    return 0.5 * min(max(speed, 0.0), scales.z);
}

// Weight of a sample at `p` by its distance to the centre's tangent plane (absolute value, so
// that both sides of a curved surface count): linear falloff or a step.
fn geometry_weight(centre: Surface, p: vec3<f32>, radius: vec4<f32>, flags: vec4<u32>) -> f32 {
    let d = abs(dot(centre.normal, p - centre.position));
    return plane_falloff(d, max(radius.w * centre.view_z, 1e-6), flags);
}

// The geometry weight of a distance `d` to the tangent plane: linear falloff to 0 at
// `tolerance`, or a step there (bit 0 of flags.z).
fn plane_falloff(d: f32, tolerance: f32, flags: vec4<u32>) -> f32 {
    if (flags.z & 1u) != 0u {
        return select(0.0, 1.0, d < tolerance);
    }
    return max(1.0 - d / tolerance, 0.0);
}

// The centre's tangent plane in the form the sample loops use. A sample's world position is
// (R0.x, R1.x, R2.x) / (R3.x), with Ri the rows of the inverse view-projection and
// x = (ndc.x, ndc.y, depth, 1), so its signed distance to the plane is
// (n.x R0 + n.y R1 + n.z R2 - (n.c) R3).x / (R3.x): two dot products and a division a sample
// instead of the matrix product and the subtraction (the loops are bound by arithmetic).
struct TangentPlane {
    numerator: vec4<f32>,
    denominator: vec4<f32>,
    // Distance in metres at which the weight reaches 0.
    tolerance: f32,
}

fn tangent_plane(view: View, centre: Surface, radius: vec4<f32>) -> TangentPlane {
    let rows = transpose(view.inv_view_proj);
    let n = centre.normal;
    return TangentPlane(
        n.x * rows[0] + n.y * rows[1] + n.z * rows[2] - dot(n, centre.position) * rows[3],
        rows[3],
        max(radius.w * centre.view_z, 1e-6)
    );
}

// geometry_weight of the sample at pixel `q` with reverse-Z depth `depth`. A non-finite depth
// gives 0 or NaN, which every caller's `w > 0` test drops.
fn plane_weight(t: TangentPlane, view: View, q: vec2<i32>, depth: f32, flags: vec4<u32>) -> f32 {
    let uv = (vec2<f32>(q) + 0.5) * view.viewport.zw;
    let x = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    // The distance over the tolerance, with one division.
    let relative = abs(dot(t.numerator, x)) / (t.tolerance * abs(dot(t.denominator, x)));
    return plane_falloff(relative, 1.0, flags);
}

// The weight of the sample at pixel `q` for the centre `s` with tangent plane `t`: 0 outside the
// image or on the sky, else the geometry weight, times the normal weight (a plain dot product)
// with `normal_weight`. `checked`: 0 also where a G-buffer texel it reads is not finite (without
// it, such a texel gives a NaN or zero weight, which the caller's `w > 0` test drops).
fn sample_weight(depth_tex: texture_2d<f32>, normal_tex: texture_2d<f32>, view: View, t: TangentPlane, s: Surface, q: vec2<i32>, size: vec2<u32>, flags: vec4<u32>, normal_weight: bool, checked: bool) -> f32 {
    if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size)) {
        return 0.0;
    }
    let depth = textureLoad(depth_tex, q, 0).x;
    if !(depth > 0.0) || (checked && !is_finite_f(depth)) {
        return 0.0;
    }
    let w = plane_weight(t, view, q, depth, flags);
    if !normal_weight || !(w > 0.0) {
        return w;
    }
    let oct = textureLoad(normal_tex, q, 0).xy;
    if checked && !is_finite4(vec4<f32>(oct, 0.0, 0.0)) {
        return 0.0;
    }
    return w * max(dot(s.normal, oct_decode(oct)), 0.0);
}

// Poisson point `i` of the packed disk entry `e` (= disk[i / 2]), rotated by this frame's
// angle (one rotation for every pixel); `rotation` is GiDenoiserParams::rotation.
fn disk_point(i: u32, e: vec4<f32>, rotation: vec4<f32>) -> vec2<f32> {
    let p = select(e.zw, e.xy, (i & 1u) == 0u);
    let c = rotation.x;
    let s = rotation.y;
    return vec2<f32>(c * p.x - s * p.y, s * p.x + c * p.y);
}

// A radius cap that caps nothing: no ray of the neighbourhood hit, or the cap is off.
const NO_CAP: f32 = 1.0e30;

// GiDenoiserParams::flags.z: the history is last frame's denoised output.
const FLAG_RECURRENT: u32 = 2u;

// World radius cap in metres: `scale` times `hit_mean`, the harmonic mean of the 5x5
// neighbourhood's hit distances (hit_mean.wgsl; the split-sphere model of irradiance caching:
// light and occlusion change over about the harmonic mean distance to the surroundings), over
// a power of the history length L. Over sqrt(L): the accumulated mean's noise falls as
// 1 / sqrt(L), so the pixels a kernel must average fall as 1 / L and its radius as 1 / sqrt(L).
// Over L when the history is recurrent: each frame blurs the last one's output again, and
// the blurs' variances add up, which stays bounded only if they fall faster than 1 / L.
// NO_CAP without hits or scale.
fn hit_radius_cap(hit_mean: f32, scale: f32, history_length: f32, flags: vec4<u32>) -> f32 {
    if !(scale > 0.0) || !(hit_mean > 0.0) || !is_finite_f(hit_mean) {
        return NO_CAP;
    }
    let l = max(history_length, 1.0);
    return scale * hit_mean / select(sqrt(l), l, (flags.z & FLAG_RECURRENT) != 0u);
}
