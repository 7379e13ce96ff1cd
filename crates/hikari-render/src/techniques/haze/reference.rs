//! CPU twin of the haze passes: the analytic density and its optical depth along a ray, the
//! slice mapping, the froxel lighting (`haze.light`), the front-to-back integration
//! (`haze.integrate`) and the per-pixel composite with tricubic sampling (`haze.composite`).
//! Every function here mirrors a WGSL function of the same name in `common.wgsl` or the pass
//! shaders, in f32 as the GPU computes.

use crate::lights::reference::light_attenuation;
pub use crate::reference::phase::hg_phase;
use glam::{Mat4, Vec2, Vec3, Vec4};
use hikari_math::sh::Sh;

use super::{
    HAZE_DENSITY_AA, HAZE_LOCAL_LIGHTS, HAZE_SKY, HAZE_SKY_OCCLUSION, HAZE_SUN_SHADOWS,
    HAZE_TRICUBIC, HazeParams,
};
use crate::scene::upload::LightGpu;
use crate::techniques::gbuffer;
use crate::view::View;

/// Largest value the f16 grids hold.
pub const MAX_HALF: f32 = 65504.0;

/// Thickness of the first of `slices` slices from `near` to `far`, each `growth` times as thick
/// as the one before: the geometric series sums to `far - near`.
pub fn first_slice_m(near: f32, far: f32, growth: f32, slices: u32) -> f32 {
    let (near, far, r) = (f64::from(near), f64::from(far), f64::from(growth));
    ((far - near) * (r - 1.0) / (r.powi(slices as i32) - 1.0)) as f32
}

/// Extinction per metre at world height `y`.
pub fn density(p: &HazeParams, y: f32) -> f32 {
    let [de, inv_k, h, _] = p.exponential;
    let [d0, d1, hs, ks] = p.layer;
    let z = y - hs;
    let t = 0.5 * z / (z * z + ks * ks).sqrt().max(1e-6) + 0.5;
    de * (-(y - h) * inv_k).clamp(-80.0, 80.0).exp() + d0 + (d1 - d0) * t
}

/// (1 - e^-x) / x, accurate near 0.
fn one_minus_exp_over(x: f32) -> f32 {
    if x.abs() < 1e-3 {
        1.0 - 0.5 * x + x * x / 6.0
    } else {
        -(-x).exp_m1() / x
    }
}

/// 1 - e^-tau, accurate for small tau.
pub fn opacity(tau: f32) -> f32 {
    -(-tau.max(0.0)).exp_m1()
}

/// Optical depth from `o` along the unit direction `d` over `len` metres, in closed form: the
/// exponential layer integrates to an exponential, the sigmoid z / sqrt(z^2 + k^2) to
/// sqrt(z^2 + k^2), both written so that level rays lose no precision.
pub fn optical_depth(p: &HazeParams, o: Vec3, d: Vec3, len: f32) -> f32 {
    let [de, inv_k, h, _] = p.exponential;
    let [d0, d1, hs, ks] = p.layer;
    let len = len.max(0.0);
    // Exponential: de e^(-(y0 - h)/k) * len * (1 - e^-x) / x with x = len dy / k.
    let x = (len * d.y * inv_k).clamp(-80.0, 80.0);
    let e0 = de * (-(o.y - h) * inv_k).clamp(-80.0, 80.0).exp();
    let exponential = e0 * len * one_minus_exp_over(x);
    // Sigmoid: the mean of t(z) over the segment is 1/2 + (z0 + z1) / (2 (S0 + S1)).
    let z0 = o.y - hs;
    let z1 = z0 + len * d.y;
    let s0 = (z0 * z0 + ks * ks).sqrt();
    let s1 = (z1 * z1 + ks * ks).sqrt();
    let mean_t = 0.5 + 0.5 * (z0 + z1) / (s0 + s1).max(1e-6);
    let layer = len * (d0 + (d1 - d0) * mean_t);
    (exponential + layer).max(0.0)
}

/// Depth (metres along the view's forward axis) of slice boundary `s` (0: near plane,
/// `slices`: far plane); fractional `s` interpolates the geometric series.
pub fn slice_depth(p: &HazeParams, s: f32) -> f32 {
    let [near, first, r, ln_r] = p.slicing;
    near + first * ((s * ln_r).exp() - 1.0) / (r - 1.0)
}

/// The inverse of [`slice_depth`]: which boundary (fractional) lies at depth `z`; 0 before the
/// near plane.
pub fn slice_of_depth(p: &HazeParams, z: f32) -> f32 {
    let [near, first, r, ln_r] = p.slicing;
    let x = ((z - near) * (r - 1.0) / first).max(0.0);
    x.ln_1p() / ln_r
}

fn inv_view_proj(view: &View) -> Mat4 {
    Mat4::from_cols_array_2d(&view.inv_view_proj)
}

fn eye(view: &View) -> Vec3 {
    Vec3::from_slice(&view.position[..3])
}

/// Froxel `(i, j)`'s central ray.
pub fn froxel_ray(p: &HazeParams, view: &View, i: u32, j: u32) -> Vec3 {
    froxel_ray_at(p, view, Vec2::new(i as f32 + 0.5, j as f32 + 0.5))
}

/// The ray through grid position `xy` (froxels; a froxel's centre is its index plus 0.5).
pub fn froxel_ray_at(p: &HazeParams, view: &View, xy: Vec2) -> Vec3 {
    let uv = xy / Vec2::new(p.grid[0] as f32, p.grid[1] as f32);
    gbuffer::reference::uv_ray(inv_view_proj(view), eye(view), uv)
}

/// Frames in the temporal filter's cycle of sample positions.
pub const JITTER_FRAMES: u64 = 16;

fn radical_inverse(mut i: u64, base: u64) -> f32 {
    let (mut f, mut r) = (1.0f64, 0.0f64);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r as f32
}

/// Where frame `frame` samples each froxel: x and y in froxels about its centre (-0.5 to 0.5),
/// z the fraction of its slice's depth. Frame 0 of each cycle takes the centre, (0, 0, 0.5),
/// then Halton's bases 2, 3 and 5: the talk's jittered samples, filtered over frames.
pub fn jitter(frame: u64) -> Vec3 {
    let i = frame % JITTER_FRAMES;
    if i == 0 {
        return Vec3::new(0.0, 0.0, 0.5);
    }
    Vec3::new(
        radical_inverse(i, 2) - 0.5,
        radical_inverse(i, 3) - 0.5,
        radical_inverse(i, 5),
    )
}

/// The froxel (i, j, k)'s centre in last frame's grid (`view.prev_view_proj`, the same
/// slicing): normalised coordinates, or `None` off that grid or behind its camera.
pub fn reproject(p: &HazeParams, view: &View, i: u32, j: u32, k: u32) -> Option<Vec3> {
    let cam = eye(view);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let v = froxel_ray(p, view, i, j);
    let z = 0.5 * (slice_depth(p, k as f32) + slice_depth(p, k as f32 + 1.0));
    let x = cam + v * (z / v.dot(fwd).max(1e-4));
    let c = Mat4::from_cols_array_2d(&view.prev_view_proj) * x.extend(1.0);
    if c.w <= 1e-4 {
        return None;
    }
    let uvw = Vec3::new(
        0.5 + 0.5 * c.x / c.w,
        0.5 - 0.5 * c.y / c.w,
        slice_of_depth(p, c.w) / p.grid[2] as f32,
    );
    (uvw.cmpge(Vec3::ZERO).all() && uvw.cmple(Vec3::ONE).all()).then_some(uvw)
}

/// What lights the haze besides the params: the sky's deringed L2 SH (radiance, nits) and the
/// sun's visibility at a point (1 without shadows).
pub struct HazeLightInputs<'a> {
    pub sky_sh: &'a Sh<Vec3, 9>,
    pub lights: &'a [LightGpu],
    pub sun_visibility: &'a dyn Fn(Vec3) -> f32,
    /// The sky visibility at a point ([`probe_sky_visibility`] of the probes there), applied
    /// with [`HAZE_SKY_OCCLUSION`].
    pub sky_visibility: &'a dyn Fn(Vec3) -> f32,
}

/// Interior mask of a point in the air for the probe lookup (`light.wgsl`'s
/// `AIR_INTERIOR_MASK`): none, the probes weigh by their interpolation weights alone.
pub const AIR_INTERIOR_MASK: f32 = 0.5;

/// The talk's haze AO, `light.wgsl`'s `sky_visibility_at`: the probes' irradiance averaged over
/// every normal (`probe_average`, lux, as the lookup gives it at n = 0; `None` where no probe
/// covers the point) over the open sky's (`sky_sh`'s constant term times π and the diffuse
/// `balance`), by luminance, in [0, 1]; 1 without probes or sky.
pub fn probe_sky_visibility(
    probe_average: Option<Vec3>,
    sky_sh: &Sh<Vec3, 9>,
    balance: f32,
) -> f32 {
    let luma = Vec3::from_array(hikari_math::color::REC709_LUMA);
    let c0 = 0.5 / std::f32::consts::PI.sqrt();
    let open = (sky_sh.coeffs[0] * (c0 * std::f32::consts::PI)).max(Vec3::ZERO) * balance;
    match probe_average {
        Some(e) if open.dot(luma) > 0.0 => (e.dot(luma) / open.dot(luma)).clamp(0.0, 1.0),
        _ => 1.0,
    }
}

/// [`HazeLightInputs::sky_visibility`] averaged over `p.lights[1]` points spread evenly along
/// the depth of froxel slice `k` on the ray `v` (`light.wgsl`'s `froxel_sky_visibility`).
pub fn froxel_sky_visibility(
    p: &HazeParams,
    view: &View,
    inputs: &HazeLightInputs,
    v: Vec3,
    k: u32,
) -> f32 {
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let (z0, z1) = (slice_depth(p, k as f32), slice_depth(p, k as f32 + 1.0));
    let n = p.lights[1].max(1);
    let sum: f32 = (0..n)
        .map(|i| {
            let z = z0 + (z1 - z0) * ((i as f32 + 0.5) / n as f32);
            (inputs.sky_visibility)(cam + v * (z / v.dot(fwd).max(1e-4)))
        })
        .sum();
    sum / n as f32
}

/// Light a point scatters towards the camera per unit scattering coefficient, nits: the
/// integral over the sphere of incoming radiance times the phase function (the talk's L_i).
/// `v`: unit direction from the camera to the point; the sky's share is taken times the sky
/// visibility at `x`.
pub fn inscatter(p: &HazeParams, inputs: &HazeLightInputs, x: Vec3, v: Vec3) -> Vec3 {
    inscatter_seeing(p, inputs, x, v, (inputs.sky_visibility)(x))
}

/// [`inscatter`] with the sky visibility given (applied with [`HAZE_SKY_OCCLUSION`]).
pub fn inscatter_seeing(
    p: &HazeParams,
    inputs: &HazeLightInputs,
    x: Vec3,
    v: Vec3,
    sky_visibility: f32,
) -> Vec3 {
    let g = p.scatter[1];
    let flags = p.grid[3];
    let to_sun = Vec3::from_slice(&p.sun[..3]);
    let sun_rgb = Vec3::from_slice(&p.sun_lux[..3]);
    let mut l = Vec3::ZERO;
    if sun_rgb.max_element() > 0.0 {
        let vis = if flags & HAZE_SUN_SHADOWS != 0 {
            (inputs.sun_visibility)(x)
        } else {
            1.0
        };
        l += sun_rgb * vis * hg_phase(to_sun.dot(v), g);
    }
    if flags & HAZE_SKY != 0 {
        // The HG phase's zonal harmonics are g^l: convolving the sky's SH with it scales band
        // l by g^l (Funk-Hecke).
        let sky = inputs
            .sky_sh
            .scale_bands([1.0, g, g * g])
            .eval(v)
            .max(Vec3::ZERO);
        let visibility = if flags & HAZE_SKY_OCCLUSION != 0 {
            sky_visibility
        } else {
            1.0
        };
        l += sky * visibility;
    }
    if flags & HAZE_LOCAL_LIGHTS != 0 {
        let cutoff = p.sun[3];
        for light in inputs.lights.iter().take(p.lights[0] as usize) {
            l += local_light(light, cutoff, x, v, g);
        }
    }
    l
}

/// One point or spot light's share of [`inscatter`], unshadowed (the lights' attenuation,
/// [`crate::lights::reference::light_attenuation`]).
pub fn local_light(light: &LightGpu, cutoff_lux: f32, x: Vec3, v: Vec3, g: f32) -> Vec3 {
    let intensity = Vec3::from_slice(&light.intensity[..3]);
    let to_light = Vec3::from_slice(&light.position_range[..3]) - x;
    let d2 = to_light.length_squared().max(1e-8);
    let l = to_light / d2.sqrt();
    intensity * light_attenuation(cutoff_lux, light, l, d2) * hg_phase(l.dot(v), g)
}

/// Index of froxel `(i, j, k)` in the grids (x fastest, then y, then slice).
pub fn froxel_index(p: &HazeParams, i: u32, j: u32, k: u32) -> usize {
    ((k * p.grid[1] + j) * p.grid[0] + i) as usize
}

/// `haze.light`: every froxel's L_i at its slice's middle along its central ray, times the
/// albedo and the storage scale, as the f16 grid holds it (not rounded to f16 here).
pub fn light_grid(p: &HazeParams, view: &View, inputs: &HazeLightInputs) -> Vec<Vec3> {
    light_grid_jittered(p, view, inputs, jitter(0))
}

/// [`light_grid`] sampled at `jitter` in every froxel ([`jitter`]).
pub fn light_grid_jittered(
    p: &HazeParams,
    view: &View,
    inputs: &HazeLightInputs,
    jitter: Vec3,
) -> Vec<Vec3> {
    let [w, h, n, _] = p.grid;
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let mut out = vec![Vec3::ZERO; (w * h * n) as usize];
    for k in 0..n {
        let (z0, z1) = (slice_depth(p, k as f32), slice_depth(p, k as f32 + 1.0));
        let z = z0 + (z1 - z0) * jitter.z;
        for j in 0..h {
            for i in 0..w {
                let at = Vec2::new(i as f32 + 0.5 + jitter.x, j as f32 + 0.5 + jitter.y);
                let v = froxel_ray_at(p, view, at);
                let x = cam + v * (z / v.dot(fwd).max(1e-4));
                let sky_visibility = if p.grid[3] & HAZE_SKY_OCCLUSION != 0 {
                    froxel_sky_visibility(p, view, inputs, v, k)
                } else {
                    1.0
                };
                let li = inscatter_seeing(p, inputs, x, v, sky_visibility)
                    * (p.scatter[0] * p.scatter[2]);
                out[froxel_index(p, i, j, k)] = li.min(Vec3::splat(MAX_HALF));
            }
        }
    }
    out
}

/// The temporal filter of `haze.light`: this frame's grid blended with last frame's (`history`,
/// as stored, read trilinearly where each froxel's centre was), the history weighing `blend`
/// and rescaled by `rescale` (this frame's storage scale over last frame's). `blend` 0, or a
/// froxel that was off last frame's grid, takes this frame's value alone.
pub fn temporal(
    p: &HazeParams,
    view: &View,
    current: &[Vec3],
    history: &[Vec4],
    blend: f32,
    rescale: f32,
) -> Vec<Vec3> {
    let [w, h, n, _] = p.grid;
    let mut out = current.to_vec();
    if blend <= 0.0 {
        return out;
    }
    for k in 0..n {
        for j in 0..h {
            for i in 0..w {
                let at = froxel_index(p, i, j, k);
                if let Some(uvw) = reproject(p, view, i, j, k) {
                    let old = sample(p, history, uvw, false).truncate() * rescale;
                    let blended = current[at] + (old - current[at]) * blend;
                    out[at] = blended.min(Vec3::splat(MAX_HALF));
                }
            }
        }
    }
    out
}

/// `haze.integrate`: front to back along each froxel column. With density anti-aliasing the
/// grid holds L / alpha (rgb) and alpha at each slice's far boundary; without, L and alpha.
pub fn integrate(p: &HazeParams, view: &View, light: &[Vec3]) -> Vec<Vec4> {
    let [w, h, n, flags] = p.grid;
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let mut out = vec![Vec4::ZERO; (w * h * n) as usize];
    for j in 0..h {
        for i in 0..w {
            let v = froxel_ray(p, view, i, j);
            let inv_cos = 1.0 / v.dot(fwd).max(1e-4);
            let mut transmittance = 1.0f32;
            let mut weight = 0.0f32;
            let mut sum = Vec3::ZERO;
            for k in 0..n {
                let t0 = slice_depth(p, k as f32) * inv_cos;
                let t1 = slice_depth(p, k as f32 + 1.0) * inv_cos;
                let tau = optical_depth(p, cam + v * t0, v, t1 - t0);
                let a = transmittance * opacity(tau);
                let li = light[froxel_index(p, i, j, k)];
                sum += li * a;
                weight += a;
                transmittance *= (-tau).exp();
                let alpha = 1.0 - transmittance;
                let rgb = if flags & HAZE_DENSITY_AA != 0 {
                    if weight > 1e-30 { sum / weight } else { li }
                } else {
                    sum
                };
                out[froxel_index(p, i, j, k)] = rgb.min(Vec3::splat(MAX_HALF)).extend(alpha);
            }
        }
    }
    out
}

/// Cubic B-spline weights of the four texels about a sample `f` (0..1) past the second.
pub fn bspline_weights(f: f32) -> [f32; 4] {
    let f2 = f * f;
    let f3 = f2 * f;
    [
        (1.0 - f) * (1.0 - f) * (1.0 - f) / 6.0,
        (3.0 * f3 - 6.0 * f2 + 4.0) / 6.0,
        (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) / 6.0,
        f3 / 6.0,
    ]
}

fn texel(p: &HazeParams, grid: &[Vec4], c: [i32; 3]) -> Vec4 {
    let i = c[0].clamp(0, p.grid[0] as i32 - 1) as u32;
    let j = c[1].clamp(0, p.grid[1] as i32 - 1) as u32;
    let k = c[2].clamp(0, p.grid[2] as i32 - 1) as u32;
    grid[froxel_index(p, i, j, k)]
}

/// The grid at normalised coordinates `uvw` (texel centres at (i + 0.5) / size, clamped at the
/// edges): a tricubic B-spline over the 4x4x4 texels about it, or trilinear.
pub fn sample(p: &HazeParams, grid: &[Vec4], uvw: Vec3, tricubic: bool) -> Vec4 {
    sample_axes(p, grid, uvw, [tricubic; 3])
}

/// [`sample`] with a cubic B-spline along the axes `cubic` names and linear along the others
/// (the particles read the light bicubic in x and y).
pub fn sample_axes(p: &HazeParams, grid: &[Vec4], uvw: Vec3, cubic: [bool; 3]) -> Vec4 {
    let size = [p.grid[0], p.grid[1], p.grid[2]];
    let mut base = [0i32; 3];
    let mut w = [[0.0f32; 4]; 3];
    for a in 0..3 {
        let c = uvw[a] * size[a] as f32 - 0.5;
        let fl = c.floor();
        let f = c - fl;
        base[a] = fl as i32;
        w[a] = if cubic[a] {
            bspline_weights(f)
        } else {
            [0.0, 1.0 - f, f, 0.0]
        };
    }
    let mut acc = Vec4::ZERO;
    for (z, wz) in w[2].iter().enumerate() {
        for (y, wy) in w[1].iter().enumerate() {
            for (x, wx) in w[0].iter().enumerate() {
                let wt = wx * wy * wz;
                if wt != 0.0 {
                    let c = [
                        base[0] + x as i32 - 1,
                        base[1] + y as i32 - 1,
                        base[2] + z as i32 - 1,
                    ];
                    acc += texel(p, grid, c) * wt;
                }
            }
        }
    }
    acc
}

/// Where a pixel's ray ends: its distance from the camera and its depth along the forward
/// axis (the far plane's for the sky and for depths that are not finite).
pub fn pixel_extent(p: &HazeParams, view: &View, pixel: [u32; 2], depth: f32) -> (Vec3, f32, f32) {
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let size = [view.viewport[0] as u32, view.viewport[1] as u32];
    let v = gbuffer::reference::pixel_ray(inv_view_proj(view), cam, pixel, size);
    let far = p.scatter[3];
    if depth.is_finite() && depth > 0.0 {
        let world = gbuffer::reference::world_from_depth(inv_view_proj(view), pixel, size, depth);
        let d = world - cam;
        let dist = d.length();
        if dist.is_finite() && dist < far {
            return (v, dist, d.dot(fwd));
        }
    }
    (v, far, far * v.dot(fwd).max(1e-4))
}

/// `haze.composite` of one pixel: the surface's (or sky's) radiance `lit` seen through the
/// haze. `grid`: what [`integrate`] gives (scaled).
pub fn composite_pixel(
    p: &HazeParams,
    view: &View,
    grid: &[Vec4],
    pixel: [u32; 2],
    depth: f32,
    lit: Vec3,
) -> Vec3 {
    let flags = p.grid[3];
    let cam = Vec3::from_slice(&view.position[..3]);
    let (v, dist, z) = pixel_extent(p, view, pixel, depth);
    let uvw = Vec3::new(
        (pixel[0] as f32 + 0.5) * view.viewport[2],
        (pixel[1] as f32 + 0.5) * view.viewport[3],
        (slice_of_depth(p, z) - 0.5) / p.grid[2] as f32,
    );
    let s = sample(p, grid, uvw, flags & HAZE_TRICUBIC != 0);
    let lit = if lit.is_finite() {
        lit.max(Vec3::ZERO)
    } else {
        Vec3::ZERO
    };
    let inv_scale = 1.0 / p.scatter[2];
    let out = if flags & HAZE_DENSITY_AA != 0 {
        let alpha = opacity(optical_depth(p, cam, v, dist));
        lit * (1.0 - alpha) + s.truncate() * (alpha * inv_scale)
    } else {
        let alpha = s.w.clamp(0.0, 1.0);
        lit * (1.0 - alpha) + s.truncate() * inv_scale
    };
    if out.is_finite() {
        out.max(Vec3::ZERO)
    } else {
        lit
    }
}
