//! CPU twin of the GI and AO denoisers (`spatial.wgsl`, `ao.wgsl`), the same arithmetic in
//! f32 over small images, for the tests.

// `!(x > 0.0)` is kept where the shader has it: it is also true for NaN, which must be rejected.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};

use super::params::{FLAG_RECURRENT, GiDenoiserParams};
use crate::reference::octahedral;
use crate::view::View;

/// Two pixels a thread share samples only if their normals are this close (as `ao.wgsl`).
pub const EDGE_NORMAL_COS: f32 = 0.9;
/// The fewest samples the AO denoiser takes a pixel (as `ao.wgsl`).
pub const MIN_AO_SAMPLES: u32 = 8;

/// The G-buffer texels the denoiser reads, row-major.
#[derive(Clone, Debug)]
pub struct GeometryImage {
    pub width: u32,
    pub height: u32,
    /// Reverse-Z depth, 0 for the sky.
    pub depth: Vec<f32>,
    /// Octahedral world-space normal.
    pub normal_oct: Vec<Vec2>,
}

/// The GI signal, row-major: luminance L1 SH (c0, y, z, x) and (Co, Cg).
#[derive(Clone, Debug, PartialEq)]
pub struct GiImage {
    pub y: Vec<Vec4>,
    pub cocg: Vec<Vec2>,
}

/// The surface a pixel shows (`Surface` in `common.wgsl`).
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub position: Vec3,
    pub normal: Vec3,
    /// Metres along the camera's forward axis.
    pub view_z: f32,
}

/// World position of pixel centre `pixel` at reverse-Z `depth` (`hikari::view`).
pub fn world_from_depth(view: &View, pixel: UVec2, depth: f32) -> Vec3 {
    let uv = (pixel.as_vec2() + 0.5) * Vec2::new(view.viewport[2], view.viewport[3]);
    let ndc = Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = Mat4::from_cols_array_2d(&view.inv_view_proj) * ndc;
    w.truncate() / w.w
}

/// The surface at `pixel`; `None` for the sky and non-finite texels.
pub fn make_surface(view: &View, pixel: UVec2, depth: f32, oct: Vec2) -> Option<Surface> {
    if !(depth > 0.0 && depth.is_finite() && oct.is_finite()) {
        return None;
    }
    let position = world_from_depth(view, pixel, depth);
    let forward = Vec3::new(
        view.forward_near[0],
        view.forward_near[1],
        view.forward_near[2],
    );
    let camera = Vec3::new(view.position[0], view.position[1], view.position[2]);
    let view_z = (position - camera).dot(forward);
    (view_z > 0.0 && position.is_finite() && view_z.is_finite()).then(|| Surface {
        position,
        normal: octahedral::decode(oct),
        view_z,
    })
}

/// F(viewZ) = z / (z + z_half).
pub fn radius_scale_z(view_z: f32, z_half: f32) -> f32 {
    view_z / (view_z + z_half)
}

/// F(variance) from E[x] and E[x^2] over 3x3.
pub fn radius_scale_variance(mean: f32, mean_sq: f32, p: &GiDenoiserParams) -> f32 {
    let sigma = (mean_sq - mean * mean).max(0.0).sqrt();
    let cv = sigma / (mean.abs() + 1e-4);
    (cv / p.scales[0]).max(p.scales[1]).min(1.0)
}

/// Blur radius in pixels of `radius_m` at `view_z`, clamped.
pub fn radius_pixels(radius_m: f32, view_z: f32, p: &GiDenoiserParams) -> f32 {
    (radius_m / (view_z * p.rotation[2]))
        .max(p.radius[1])
        .min(p.radius[2])
}

/// 0.5 * accumulation speed, the speed being 1 - 1 / history length, capped.
pub fn combine_weight(history_length: f32, p: &GiDenoiserParams) -> f32 {
    let speed = 1.0 - 1.0 / history_length.max(1.0);
    0.5 * speed.max(0.0).min(p.scales[2])
}

/// Weight by the distance to the centre's tangent plane.
pub fn geometry_weight(centre: &Surface, p: Vec3, params: &GiDenoiserParams) -> f32 {
    let d = centre.normal.dot(p - centre.position).abs();
    let tolerance = (params.radius[3] * centre.view_z).max(1e-6);
    if params.flags[2] & 1 != 0 {
        return if d < tolerance { 1.0 } else { 0.0 };
    }
    (1.0 - d / tolerance).max(0.0)
}

fn finite_or(v: f32, fallback: f32) -> f32 {
    if v.is_finite() { v } else { fallback }
}

/// Mean and mean square of the finite values of `value` over the 3x3 around `pixel`.
fn moments_3x3(w: u32, h: u32, pixel: UVec2, value: impl Fn(usize) -> f32) -> (f32, f32) {
    let (mut sum, mut sum_sq, mut count) = (0.0f32, 0.0f32, 0.0f32);
    for dy in -1i32..=1 {
        for dx in -1i32..=1 {
            let (qx, qy) = (pixel.x as i32 + dx, pixel.y as i32 + dy);
            if qx < 0 || qy < 0 || qx >= w as i32 || qy >= h as i32 {
                continue;
            }
            let v = value((qy as u32 * w + qx as u32) as usize);
            if v.is_finite() {
                sum += v;
                sum_sq += v * v;
                count += 1.0;
            }
        }
    }
    (sum / count.max(1.0), sum_sq / count.max(1.0))
}

/// The pixel `floor(centre_px + offset)` if it lies in the image.
fn tap(centre_px: Vec2, offset: Vec2, w: u32, h: u32) -> Option<UVec2> {
    let q = (centre_px + offset).floor();
    (q.x >= 0.0 && q.y >= 0.0 && q.x < w as f32 && q.y < h as f32)
        .then(|| UVec2::new(q.x as u32, q.y as u32))
}

/// One GI pass (`spatial.wgsl`): `params.flags[1]` selects the normal weight.
/// `hit_mean`: [`hit_mean`] of this frame's hit distances (the radius cap, `params.scales[3]`).
pub fn spatial_pass(
    params: &GiDenoiserParams,
    view: &View,
    geo: &GeometryImage,
    input: &GiImage,
    history_length: &[f32],
    ao: &[f32],
    hit_mean: &[f32],
) -> GiImage {
    let (w, h) = (geo.width, geo.height);
    let n = (w * h) as usize;
    let mut out = GiImage {
        y: vec![Vec4::ZERO; n],
        cocg: vec![Vec2::ZERO; n],
    };
    for i in 0..n {
        let pixel = UVec2::new(i as u32 % w, i as u32 / w);
        let centre_ok = input.y[i].is_finite() && input.cocg[i].is_finite();
        let (centre_y, centre_c) = if centre_ok {
            (input.y[i], input.cocg[i])
        } else {
            (Vec4::ZERO, Vec2::ZERO)
        };
        let Some(s) = make_surface(view, pixel, geo.depth[i], geo.normal_oct[i]) else {
            out.y[i] = centre_y;
            out.cocg[i] = centre_c;
            continue;
        };
        let (mean, mean_sq) = moments_3x3(w, h, pixel, |j| input.y[j].x);
        let a = if ao[i].is_finite() {
            ao[i].clamp(0.0, 1.0)
        } else {
            1.0
        };
        let history = finite_or(history_length[i], 1.0);
        let scale = radius_scale_z(s.view_z, params.rotation[3])
            * radius_scale_variance(mean, mean_sq, params)
            * a.max(params.scales[1]);
        let cap = hit_radius_cap(hit_mean[i], params.scales[3], history, params.flags);
        let radius = radius_pixels((params.radius[0] * scale).min(cap), s.view_z, params);
        let step = ((params.radius[2] / radius.max(1e-3)).min(64.0) as u32)
            .max(1)
            .min(params.flags[3]);

        let mut acc_y = centre_y;
        let mut acc_c = centre_c;
        let mut acc_w = if centre_ok { 1.0 } else { 0.0 };
        let centre_px = pixel.as_vec2() + 0.5;
        let mut k = 0;
        while k < params.flags[0] {
            let idx = k;
            k += step;
            let Some(q) = tap(centre_px, params.disk_point(idx) * radius, w, h) else {
                continue;
            };
            let j = (q.y * w + q.x) as usize;
            let depth = geo.depth[j];
            if !(depth > 0.0) || !depth.is_finite() {
                continue;
            }
            let mut wt = geometry_weight(&s, world_from_depth(view, q, depth), params);
            if !(wt > 0.0) {
                continue;
            }
            if params.flags[1] != 0 {
                let oct = geo.normal_oct[j];
                if !oct.is_finite() {
                    continue;
                }
                wt *= s.normal.dot(octahedral::decode(oct)).max(0.0);
                if !(wt > 0.0) {
                    continue;
                }
            }
            let (y, c) = (input.y[j], input.cocg[j]);
            if !y.is_finite() || !c.is_finite() {
                continue;
            }
            acc_y += wt * y;
            acc_c += wt * c;
            acc_w += wt;
        }
        if acc_w > 0.0 {
            let kw = if centre_ok {
                combine_weight(history, params)
            } else {
                0.0
            };
            out.y[i] = (acc_y / acc_w).lerp(centre_y, kw);
            out.cocg[i] = (acc_c / acc_w).lerp(centre_c, kw);
        } else {
            out.y[i] = centre_y;
            out.cocg[i] = centre_c;
        }
    }
    out
}

/// One pixel as the AO denoiser loads it.
struct AoPixel {
    surface: Option<Surface>,
    ao: f32,
    ao_ok: bool,
    keep: f32,
    variance_scale: f32,
    /// Largest world radius in metres ([`NO_RADIUS_CAP`]: none).
    radius_cap: f32,
}

/// The AO radius cap that caps nothing (as `ao.wgsl`'s `NO_CAP`).
pub const NO_RADIUS_CAP: f32 = 1.0e30;
/// The hit distances of (2 `HIT_WINDOW` + 1)^2 pixels set the AO radius cap (as `ao.wgsl`).
pub const HIT_WINDOW: i32 = 2;

/// The harmonic mean of the finite, positive hit distances over each pixel's 5x5
/// neighbourhood, 0 where none hit (`hit_mean.wgsl`).
pub fn hit_mean(w: u32, h: u32, hit_distance: &[f32]) -> Vec<f32> {
    let reciprocal = |x: i32, y: i32| {
        if x < 0 || y < 0 || x >= w as i32 || y >= h as i32 {
            return Vec2::ZERO;
        }
        let d = hit_distance[(y as u32 * w + x as u32) as usize];
        if d > 0.0 && d.is_finite() {
            Vec2::new(1.0 / d, 1.0)
        } else {
            Vec2::ZERO
        }
    };
    let mut out = vec![0.0; (w * h) as usize];
    for py in 0..h as i32 {
        for px in 0..w as i32 {
            // Five along each row, then the five rows: the shader's order.
            let mut sum = Vec2::ZERO;
            for y in py - HIT_WINDOW..=py + HIT_WINDOW {
                let mut row = Vec2::ZERO;
                for x in px - HIT_WINDOW..=px + HIT_WINDOW {
                    row += reciprocal(x, y);
                }
                sum += row;
            }
            if sum.y > 0.0 {
                out[(py as u32 * w + px as u32) as usize] = sum.y / sum.x;
            }
        }
    }
    out
}

/// The world radius cap (`hit_radius_cap` in `common.wgsl`): `scale` times the pixel's
/// [`hit_mean`], over the square root of its history length, or over the length itself with
/// [`FLAG_RECURRENT`] in `flags[2]`; [`NO_RADIUS_CAP`] without a hit or a scale.
pub fn hit_radius_cap(hit_mean: f32, scale: f32, history_length: f32, flags: [u32; 4]) -> f32 {
    if !(scale > 0.0) || !(hit_mean > 0.0) || !hit_mean.is_finite() {
        return NO_RADIUS_CAP;
    }
    let l = history_length.max(1.0);
    scale * hit_mean
        / if flags[2] & FLAG_RECURRENT != 0 {
            l
        } else {
            l.sqrt()
        }
}

fn load_ao_pixel(
    params: &GiDenoiserParams,
    view: &View,
    geo: &GeometryImage,
    ao: &[f32],
    history_length: &[f32],
    hit_mean: &[f32],
    pixel: UVec2,
) -> AoPixel {
    let (w, h) = (geo.width, geo.height);
    let i = (pixel.y * w + pixel.x) as usize;
    let (mean, mean_sq) = moments_3x3(w, h, pixel, |j| ao[j]);
    let history = finite_or(history_length[i], 1.0);
    AoPixel {
        surface: make_surface(view, pixel, geo.depth[i], geo.normal_oct[i]),
        ao: finite_or(ao[i], 1.0),
        ao_ok: ao[i].is_finite(),
        keep: combine_weight(history, params),
        variance_scale: radius_scale_variance(mean, mean_sq, params),
        radius_cap: hit_radius_cap(hit_mean[i], params.scales[3], history, params.flags),
    }
}

/// Weighted AO sum and weight of the samples about `centre_px` against `s`, added to `acc`.
#[allow(clippy::too_many_arguments)]
fn filter_ao(
    params: &GiDenoiserParams,
    view: &View,
    geo: &GeometryImage,
    ao: &[f32],
    centre_px: Vec2,
    s: &Surface,
    variance_scale: f32,
    radius_cap: f32,
    mut acc: Vec2,
) -> Vec2 {
    let (w, h) = (geo.width, geo.height);
    let radius_m =
        (params.radius[0] * radius_scale_z(s.view_z, params.rotation[3]) * variance_scale)
            .min(radius_cap);
    let radius = radius_pixels(radius_m, s.view_z, params);
    let count = ((params.flags[0] as f32 * variance_scale).ceil() as u32)
        .max(MIN_AO_SAMPLES.min(params.flags[0]))
        .min(params.flags[0]);
    for i in 0..count {
        let Some(q) = tap(centre_px, params.disk_point(i) * radius, w, h) else {
            continue;
        };
        let j = (q.y * w + q.x) as usize;
        let depth = geo.depth[j];
        if !(depth > 0.0) || !depth.is_finite() {
            continue;
        }
        let mut wt = geometry_weight(s, world_from_depth(view, q, depth), params);
        if !(wt > 0.0) {
            continue;
        }
        let oct = geo.normal_oct[j];
        if !oct.is_finite() {
            continue;
        }
        wt *= s.normal.dot(octahedral::decode(oct)).max(0.0);
        let v = ao[j];
        if !(wt > 0.0) || !v.is_finite() {
            continue;
        }
        acc += Vec2::new(wt * v, wt);
    }
    acc
}

fn combine_ao(p: &AoPixel, acc: Vec2) -> f32 {
    if !(acc.y > 0.0) {
        return p.ao;
    }
    let k = if p.ao_ok { p.keep } else { 0.0 };
    (acc.x / acc.y + (p.ao - acc.x / acc.y) * k).clamp(0.0, 1.0)
}

fn centre_acc(p: &AoPixel) -> Vec2 {
    if p.ao_ok {
        Vec2::new(p.ao, 1.0)
    } else {
        Vec2::ZERO
    }
}

/// The AO denoiser (`ao.wgsl`): pixel pairs (2x, y), (2x + 1, y) share one set of samples
/// where no edge lies between them. `hit_mean`: [`hit_mean`] of this frame's hit distances.
pub fn ao_pass(
    params: &GiDenoiserParams,
    view: &View,
    geo: &GeometryImage,
    ao: &[f32],
    history_length: &[f32],
    hit_mean: &[f32],
) -> Vec<f32> {
    let (w, h) = (geo.width, geo.height);
    let mut out = vec![0.0; (w * h) as usize];
    for y in 0..h {
        for x in (0..w).step_by(2) {
            let pa = UVec2::new(x, y);
            let pb = UVec2::new(x + 1, y);
            let has_b = pb.x < w;
            let load = |p| load_ao_pixel(params, view, geo, ao, history_length, hit_mean, p);
            let a = load(pa);
            let b = has_b.then(|| load(pb));
            let ia = (y * w + x) as usize;
            if let (Some(b), Some(sa), Some(sb)) =
                (&b, &a.surface, b.as_ref().and_then(|b| b.surface))
                && geometry_weight(sa, sb.position, params) > 0.0
                && sa.normal.dot(sb.normal) >= EDGE_NORMAL_COS
            {
                let acc = filter_ao(
                    params,
                    view,
                    geo,
                    ao,
                    Vec2::new(x as f32 + 1.0, y as f32 + 0.5),
                    sa,
                    a.variance_scale.max(b.variance_scale),
                    a.radius_cap.max(b.radius_cap),
                    centre_acc(&a) + centre_acc(b),
                );
                out[ia] = combine_ao(&a, acc);
                out[ia + 1] = combine_ao(b, acc);
                continue;
            }
            for (p, pixel, idx) in [(Some(&a), pa, ia), (b.as_ref(), pb, ia + 1)] {
                let Some(p) = p else { continue };
                out[idx] = match &p.surface {
                    Some(s) => combine_ao(
                        p,
                        filter_ao(
                            params,
                            view,
                            geo,
                            ao,
                            pixel.as_vec2() + 0.5,
                            s,
                            p.variance_scale,
                            p.radius_cap,
                            centre_acc(p),
                        ),
                    ),
                    None => p.ao,
                };
            }
        }
    }
    out
}
