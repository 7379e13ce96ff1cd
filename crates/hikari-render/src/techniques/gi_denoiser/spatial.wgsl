// One spatial pass of the two-pass GI denoiser (Metro Exodus, GDC 2019, "denoiser block"):
// variance of the input over 3x3 -> radius scale F(viewZ) * F(variance) * F(AO) -> adaptive
// step -> every Nth of up to 32 Poisson-disk samples, rotated once a frame; weights: geometry
// (distance to the tangent plane), and in the second pass the normal (a plain dot product).
// Y SH and CoCg share the weights. Output: lerp(denoised, input, 0.5 * accumulation speed).
// A non-finite input texel is dropped where it is read, so it never reaches the output: the
// samples are summed first without finite tests (the loop is bound by arithmetic; 2 % of the
// pass on the H200), and only a pixel whose sum came out non-finite sums them again,
// dropping each non-finite texel; with finite texels both give the same sum.
// CPU twin: gi_denoiser/reference.rs `spatial_pass`.

#import hikari::view::View
#import hikari::finite::{is_finite_f, is_finite4}
#import hikari::gi_denoiser_common::{GiDenoiserParams, Surface, make_surface, radius_scale_z, radius_scale_variance, radius_pixels, combine_weight, disk_point, moments_3x3, hit_radius_cap, TangentPlane, tangent_plane, sample_weight}

@group(0) @binding(0) var<uniform> params: GiDenoiserParams;
@group(0) @binding(1) var<uniform> view: View;
@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var normal_tex: texture_2d<f32>;
@group(0) @binding(4) var in_y: texture_2d<f32>;
@group(0) @binding(5) var in_cocg: texture_2d<f32>;
@group(0) @binding(6) var history_tex: texture_2d<f32>;
@group(0) @binding(7) var ao_tex: texture_2d<f32>;
@group(0) @binding(8) var out_y: texture_storage_2d<rgba16float, write>;
@group(0) @binding(9) var out_cocg: texture_storage_2d<rg16float, write>;
// The 5x5 harmonic mean hit distance in metres (hit_mean.wgsl; 0: no hit).
@group(0) @binding(10) var hit_mean_tex: texture_2d<f32>;

// This frame's Poisson points, rotated, for the workgroup: the lanes of a warp take
// different steps through them, and a uniform buffer indexed differently by each lane is
// read one address at a time.
var<workgroup> disk: array<vec2<f32>, 32>;

struct Sums {
    y: vec4<f32>,
    c: vec2<f32>,
    w: f32,
}

// The weighted sum of the centre's samples, starting from the centre's own. `checked`: drop
// every sample whose texels are not finite (the GPU then tests each texel it reads).
fn gather(s: Surface, plane: TangentPlane, centre_px: vec2<f32>, radius: f32, step: u32, centre: Sums, size: vec2<u32>, checked: bool) -> Sums {
    var sum = centre;
    for (var i = 0u; i < params.flags.x; i += step) {
        let q = vec2<i32>(floor(centre_px + disk[i] * radius));
        let w = sample_weight(depth_tex, normal_tex, view, plane, s, q, size, params.flags, params.flags.y != 0u, checked);
        if !(w > 0.0) {
            continue;
        }
        // The heavy data, only for samples that count.
        let y = textureLoad(in_y, q, 0);
        let c = textureLoad(in_cocg, q, 0).xy;
        if checked && (!is_finite4(y) || !is_finite4(vec4<f32>(c, 0.0, 0.0))) {
            continue;
        }
        sum.y += w * y;
        sum.c += w * c;
        sum.w += w;
    }
    return sum;
}

@compute @workgroup_size(16, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if local < 32u {
        disk[local] = disk_point(local, params.disk[local / 2u], params.rotation);
    }
    workgroupBarrier();
    let size = textureDimensions(out_y);
    if any(id.xy >= size) {
        return;
    }
    let pixel = id.xy;
    let raw_y = textureLoad(in_y, pixel, 0);
    let raw_c = textureLoad(in_cocg, pixel, 0).xy;
    let centre_ok = is_finite4(raw_y) && is_finite4(vec4<f32>(raw_c, 0.0, 0.0));
    let centre_y = select(vec4<f32>(0.0), raw_y, centre_ok);
    let centre_c = select(vec2<f32>(0.0), raw_c, centre_ok);

    let s = make_surface(
        view,
        pixel,
        textureLoad(depth_tex, pixel, 0).x,
        textureLoad(normal_tex, pixel, 0).xy
    );
    if !s.valid {
        textureStore(out_y, pixel, centre_y);
        textureStore(out_cocg, pixel, vec4<f32>(centre_c, 0.0, 0.0));
        return;
    }

    // Variance of the luminance (the SH's c0) over 3x3, finite texels only.
    let moments = moments_3x3(in_y, pixel, size);

    let raw_ao = textureLoad(ao_tex, pixel, 0).x;
    let ao = select(1.0, clamp(raw_ao, 0.0, 1.0), is_finite_f(raw_ao));
    let raw_history = textureLoad(history_tex, pixel, 0).x;
    let history = select(1.0, raw_history, is_finite_f(raw_history));

    let scale = radius_scale_z(s.view_z, params.rotation.w)
        * radius_scale_variance(moments.x, moments.y, params.scales)
        * max(ao, params.scales.y);
    let radius_m = min(params.radius.x * scale, hit_radius_cap(textureLoad(hit_mean_tex, pixel, 0).x, params.scales.w, history, params.flags));
    let radius = radius_pixels(radius_m, s.view_z, params.radius, params.rotation);
    // Small radius, bigger step: fewer taps where the kernel covers fewer pixels.
    let step = min(max(u32(min(params.radius.z / max(radius, 1e-3), 64.0)), 1u), params.flags.w);

    let plane = tangent_plane(view, s, params.radius);
    let centre = Sums(centre_y, centre_c, select(0.0, 1.0, centre_ok));
    let centre_px = vec2<f32>(pixel) + 0.5;
    var sum = gather(s, plane, centre_px, radius, step, centre, size, false);
    if !is_finite4(sum.y) || !is_finite4(vec4<f32>(sum.c, sum.w, 0.0)) {
        sum = gather(s, plane, centre_px, radius, step, centre, size, true);
    }
    var out_sh = centre_y;
    var out_c = centre_c;
    if sum.w > 0.0 {
        let k = select(0.0, combine_weight(history, params.scales), centre_ok);
        out_sh = mix(sum.y / sum.w, centre_y, k);
        out_c = mix(sum.c / sum.w, centre_c, k);
    }
    textureStore(out_y, pixel, out_sh);
    textureStore(out_cocg, pixel, vec4<f32>(out_c, 0.0, 0.0));
}
