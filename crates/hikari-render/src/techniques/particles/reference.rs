//! CPU twin of `particles.draw`: each pixel's ray meets each sprite's plane, back to front,
//! composited premultiplied; and the talk's multiple-scattering ratios. It ignores the sprites'
//! screen rectangles, which only spare the GPU work: one too small fails the test.

use glam::{Mat4, Vec3, Vec4};

use super::{ParticleGpu, ParticleParams};
use crate::techniques::gbuffer;
use crate::techniques::haze::HazeParams;
use crate::techniques::haze::reference as haze;
use crate::view::View;

/// The talk's multiple-scattering scale of a haze-lit particle: the ratio of an HG phase of
/// asymmetry `g_back` (a stand-in for light scattered many times) to the haze's HG phase of
/// asymmetry `g`, (with the eye on the light's side, with the eye facing the light). The first
/// is back scattering (scattering angle 180 degrees), where the talk reduced the effect: it is
/// taken as `1 + back_strength (ratio - 1)`.
pub fn multiple_scattering(g: f32, g_back: f32, back_strength: f32) -> (f32, f32) {
    let ratio = |cos: f32| haze::hg_phase(cos, g_back) / haze::hg_phase(cos, g).max(1e-12);
    (1.0 + back_strength * (ratio(-1.0) - 1.0), ratio(1.0))
}

/// A sprite's plane facing the camera at `cam` (forward axis `fwd`): its normal `f` (the line
/// of sight through its centre) and the `right` and `up` axes of its square.
pub fn sprite_basis(centre: Vec3, cam: Vec3, fwd: Vec3) -> [Vec3; 3] {
    let to_eye = cam - centre;
    let f = if to_eye.length_squared() > 1e-8 {
        -to_eye.normalize()
    } else {
        fwd
    };
    let up_hint = if f.y.abs() > 0.99 { Vec3::X } else { Vec3::Y };
    let right = f.cross(up_hint).normalize();
    [f, right, right.cross(f)]
}

/// What the pass reads besides the sprites.
pub struct Inputs<'a> {
    pub view: &'a View,
    pub params: &'a ParticleParams,
    /// The haze's parameters and its light grid (`haze.light` as stored, x fastest, then y,
    /// then the slice); `None` without haze.
    pub haze: Option<(&'a HazeParams, &'a [Vec4])>,
    /// Reverse-Z depth of the pixel, `w` by `h`.
    pub depth: &'a [f32],
}

/// One sprite's premultiplied colour and alpha at `pixel`, or `None` where it does not cover it.
pub fn fragment(inputs: &Inputs<'_>, p: &ParticleGpu, pixel: [u32; 2]) -> Option<Vec4> {
    let view = inputs.view;
    let params = inputs.params;
    let size = [view.viewport[0] as u32, view.viewport[1] as u32];
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let centre = Vec3::from_slice(&p.position_radius[..3]);
    let radius = p.position_radius[3];
    let [f, right, up] = sprite_basis(centre, cam, fwd);
    // The pixel's ray meets the sprite's plane (normal f through the centre).
    let ray = gbuffer::reference::pixel_ray(inv, cam, pixel, size);
    let denom = ray.dot(f);
    if denom <= 1e-6 {
        return None;
    }
    let t = (centre - cam).dot(f) / denom;
    let world = cam + ray * t;
    let corner = glam::Vec2::new((world - centre).dot(right), (world - centre).dot(up)) / radius;
    let r2 = corner.length_squared();
    if r2 >= 1.0 {
        return None;
    }
    let haze_lit = p.albedo_opacity[3] < 0.0;
    let peak = p.albedo_opacity[3].abs();
    let mut alpha = peak * (1.0 - r2) * (1.0 - r2);
    let d = world - cam;
    let dist = d.length();
    let v = d / dist.max(1e-6);
    let depth = inputs.depth[(pixel[1] * size[0] + pixel[0]) as usize];
    if depth > 0.0 && depth.is_finite() {
        let surface = gbuffer::reference::world_from_depth(inv, pixel, size, depth).distance(cam);
        alpha *= ((surface - dist) / (params.sky[3] * radius).max(1e-4)).clamp(0.0, 1.0);
    }
    alpha *= ((dist - view.forward_near[3]) / radius.max(1e-4)).clamp(0.0, 1.0);
    if alpha.is_nan() || alpha <= 1e-4 {
        return None;
    }
    let to_sun = Vec3::from_slice(&params.sun_dir[..3]);
    let light = match inputs.haze {
        Some((h, grid)) if haze_lit && params.sun_lux[3] > 0.0 => {
            let uv = (glam::Vec2::new(pixel[0] as f32, pixel[1] as f32) + 0.5)
                / glam::Vec2::new(size[0] as f32, size[1] as f32);
            let s = haze::slice_of_depth(h, d.dot(fwd));
            let uvw = Vec3::new(uv.x, uv.y, s / h.grid[2] as f32);
            let bicubic = peak > params.sun_dir[3];
            let l = haze::sample_axes(h, grid, uvw, [bicubic, bicubic, false]).truncate()
                * params.ms[2];
            let ms = params.ms[1] + (params.ms[0] - params.ms[1]) * (0.5 + 0.5 * (-v).dot(to_sun));
            l * (1.0 + (ms - 1.0) * peak)
        }
        _ => {
            Vec3::from_slice(&p.albedo_opacity[..3])
                * (Vec3::from_slice(&params.sun_lux[..3]) / (4.0 * std::f32::consts::PI)
                    + Vec3::from_slice(&params.sky[..3]))
        }
    };
    let t = match inputs.haze {
        Some((h, _)) if params.ms[3] > 0.0 => {
            1.0 - haze::opacity(haze::optical_depth(h, cam, v, dist))
        }
        _ => 1.0,
    };
    let c = light * (alpha * t);
    let c = if c.is_finite() {
        c.max(Vec3::ZERO).min(Vec3::splat(65000.0))
    } else {
        Vec3::ZERO
    };
    Some(c.extend(alpha))
}

/// The pass at one pixel: `sprites` (back to front) composited over `background` (0 where it
/// is not finite).
pub fn composite_pixel(
    inputs: &Inputs<'_>,
    sprites: &[ParticleGpu],
    pixel: [u32; 2],
    background: Vec3,
) -> Vec3 {
    let background = if background.is_finite() {
        background.max(Vec3::ZERO)
    } else {
        Vec3::ZERO
    };
    sprites
        .iter()
        .fold(background, |dst, p| match fragment(inputs, p, pixel) {
            Some(f) => f.truncate() + dst * (1.0 - f.w),
            None => dst,
        })
}
