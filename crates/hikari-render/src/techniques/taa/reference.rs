//! CPU twin of [`super::Taa`]: the jitter sequence and the history resolve, pixel for pixel.

use glam::{Vec2, Vec3, Vec4};

use hikari_math::sampling::lowdiscrepancy::halton;

use super::TaaParams;

/// The sub-pixel jitter of frame `frame_index` in pixels, x right and y down, in [-0.5, 0.5):
/// the pixel centre on the first frame of each cycle (so that a single frame is not shifted),
/// then Halton (2, 3) points.
pub fn jitter(frame_index: u64, samples: u32) -> [f32; 2] {
    let i = (frame_index % samples.max(1) as u64) as u32;
    if i == 0 {
        [0.0, 0.0]
    } else {
        [halton(i, 2) - 0.5, halton(i, 3) - 0.5]
    }
}

pub fn rgb_to_ycocg(c: Vec3) -> Vec3 {
    Vec3::new(
        0.25 * c.x + 0.5 * c.y + 0.25 * c.z,
        0.5 * c.x - 0.5 * c.z,
        -0.25 * c.x + 0.5 * c.y - 0.25 * c.z,
    )
}

pub fn ycocg_to_rgb(v: Vec3) -> Vec3 {
    Vec3::new(v.x + v.y - v.z, v.x + v.z, v.x - v.y - v.z)
}

/// `p` moved towards the box's centre until it lies inside the box (Playdead's clip, which
/// keeps the history's hue better than a per-channel clamp).
pub fn clip_to_box(p: Vec3, lo: Vec3, hi: Vec3) -> Vec3 {
    let centre = 0.5 * (lo + hi);
    let extent = (0.5 * (hi - lo)).max(Vec3::splat(1e-6));
    let d = p - centre;
    let ratio = (d / extent).abs().max_element();
    if ratio > 1.0 { centre + d / ratio } else { p }
}

/// What enters the frame is finite and non-negative: NaN and negatives become 0, +inf the
/// largest half.
pub fn sanitize(c: Vec3) -> Vec3 {
    let f = |v: f32| {
        if v.is_nan() || v < 0.0 {
            0.0
        } else {
            v.min(65504.0)
        }
    };
    Vec3::new(f(c.x), f(c.y), f(c.z))
}

/// Images of one frame for [`resolve`], row-major.
pub struct TaaInputs<'a> {
    pub size: [u32; 2],
    /// This frame's radiance (rgb).
    pub current: &'a [Vec3],
    /// Motion vectors in pixels (previous minus current position).
    pub motion: &'a [Vec2],
    /// Last frame's history (rgb + frames seen), `None` when invalid.
    pub history: Option<&'a [Vec4]>,
}

/// The resolved image and the new history (rgb + frames seen).
pub fn resolve(inp: &TaaInputs, params: &TaaParams) -> Vec<Vec4> {
    let [w, h] = inp.size;
    let at = |x: i32, y: i32| {
        let x = x.clamp(0, w as i32 - 1) as usize;
        let y = y.clamp(0, h as i32 - 1) as usize;
        sanitize(inp.current[y * w as usize + x])
    };
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let cur = at(x, y);
            let mut lo = Vec3::splat(f32::MAX);
            let mut hi = Vec3::splat(f32::MIN);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let v = rgb_to_ycocg(at(x + dx, y + dy));
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            let m = inp.motion[(y * w as i32 + x) as usize];
            let prev_pos = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + m;
            let hist = inp.history.and_then(|hist| {
                if params.history_valid == 0 {
                    return None;
                }
                sample_bilinear(hist, inp.size, prev_pos)
            });
            let resolved = match hist {
                None => cur.extend(1.0),
                Some(prev) => {
                    let mut p = prev.truncate();
                    if params.clip != 0 {
                        p = ycocg_to_rgb(clip_to_box(rgb_to_ycocg(p), lo, hi));
                    }
                    let n = prev.w.max(1.0);
                    let alpha = (1.0 / (n + 1.0)).max(1.0 / params.max_history);
                    sanitize(p.lerp(cur, alpha)).extend((n + 1.0).min(params.max_history))
                }
            };
            out.push(resolved);
        }
    }
    out
}

/// Bilinear history at pixel position `p` (pixel centres at +0.5); `None` outside the image.
pub fn sample_bilinear(img: &[Vec4], [w, h]: [u32; 2], p: Vec2) -> Option<Vec4> {
    if p.x < 0.0 || p.y < 0.0 || p.x > w as f32 || p.y > h as f32 {
        return None;
    }
    let q = p - 0.5;
    let base = q.floor();
    let f = q - base;
    let fetch = |x: i32, y: i32| {
        let x = x.clamp(0, w as i32 - 1) as usize;
        let y = y.clamp(0, h as i32 - 1) as usize;
        img[y * w as usize + x]
    };
    let (x0, y0) = (base.x as i32, base.y as i32);
    let top = fetch(x0, y0).lerp(fetch(x0 + 1, y0), f.x);
    let bottom = fetch(x0, y0 + 1).lerp(fetch(x0 + 1, y0 + 1), f.x);
    Some(top.lerp(bottom, f.y))
}

/// Images of one upsampled frame for [`resolve_upsampled`], row-major.
pub struct UpsampleInputs<'a> {
    /// The size rendered at: `current` and `motion`.
    pub render: [u32; 2],
    /// The output's size: the history and the result.
    pub output: [u32; 2],
    pub current: &'a [Vec3],
    /// Motion vectors in render pixels (previous minus current position).
    pub motion: &'a [Vec2],
    /// Last frame's history at the output's size (rgb + summed weight), `None` when invalid.
    pub history: Option<&'a [Vec4]>,
}

/// `exp(-SPREAD d^2)`, d in output pixels: the upsampling's Gaussian, sigma 0.4 of a pixel.
pub const SPREAD: f32 = 3.125;

/// Catmull-Rom weights of the four texels around a sample at fraction `f` past the second.
pub fn catmull_rom(f: f32) -> [f32; 4] {
    [
        f * (-0.5 + f * (1.0 - 0.5 * f)),
        1.0 + f * f * (-2.5 + 1.5 * f),
        f * (0.5 + f * (2.0 - 1.5 * f)),
        f * f * (-0.5 + 0.5 * f),
    ]
}

/// The upsampled image and the new history, pixel for pixel as `taa.upsample` computes them
/// (resolve.wgsl, `upsample`).
pub fn resolve_upsampled(inp: &UpsampleInputs, params: &TaaParams) -> Vec<Vec4> {
    let [rw, rh] = inp.render;
    let [ow, oh] = inp.output;
    let ratio = Vec2::from(params.ratio);
    let jitter = Vec2::from(params.jitter);
    let at = |x: i32, y: i32| {
        let x = x.clamp(0, rw as i32 - 1) as usize;
        let y = y.clamp(0, rh as i32 - 1) as usize;
        sanitize(inp.current[y * rw as usize + x])
    };
    let history = |x: i32, y: i32| {
        let hist = inp.history.expect("history");
        let x = x.clamp(0, ow as i32 - 1) as usize;
        let y = y.clamp(0, oh as i32 - 1) as usize;
        hist[y * ow as usize + x]
    };
    let mut out = Vec::with_capacity((ow * oh) as usize);
    for oy in 0..oh as i32 {
        for ox in 0..ow as i32 {
            let x = (Vec2::new(ox as f32, oy as f32) + 0.5) * ratio;
            let c = x.floor().as_ivec2().clamp(
                glam::IVec2::ZERO,
                glam::IVec2::new(rw as i32 - 1, rh as i32 - 1),
            );
            let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
            let mut lo = Vec3::splat(3.0e38);
            let mut hi = Vec3::splat(-3.0e38);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let q = c + glam::IVec2::new(dx, dy);
                    let v = at(q.x, q.y);
                    let y = rgb_to_ycocg(v);
                    lo = lo.min(y);
                    hi = hi.max(y);
                    let d = (q.as_vec2() + 0.5 - jitter - x) / ratio;
                    let w = (-SPREAD * d.dot(d)).exp();
                    sum += w * v;
                    weight += w;
                }
            }
            let cur = sum / weight.max(1e-30);
            let confidence = weight.min(1.0);
            let m = inp.motion[(c.y * rw as i32 + c.x) as usize] / ratio;
            let prev_pos = Vec2::new(ox as f32, oy as f32) + 0.5 + m;
            let inside = prev_pos.x >= 0.0
                && prev_pos.y >= 0.0
                && prev_pos.x <= ow as f32
                && prev_pos.y <= oh as f32;
            let resolved = if params.history_valid != 0 && inp.history.is_some() && inside {
                let q = prev_pos - 0.5;
                let base = q.floor();
                let (wx, wy) = (catmull_rom(q.x - base.x), catmull_rom(q.y - base.y));
                let b = base.as_ivec2() - 1;
                let mut prev = Vec4::ZERO;
                for (j, wy) in wy.iter().enumerate() {
                    let mut row = Vec4::ZERO;
                    for (i, wx) in wx.iter().enumerate() {
                        row += *wx * history(b.x + i as i32, b.y + j as i32);
                    }
                    prev += *wy * row;
                }
                let mut p = prev.truncate().max(Vec3::ZERO);
                if params.clip != 0 {
                    p = ycocg_to_rgb(clip_to_box(rgb_to_ycocg(p), lo, hi));
                }
                let n = prev.w.clamp(0.0, params.max_history);
                let alpha =
                    (confidence / (n + confidence).max(1e-6)).max(confidence / params.max_history);
                sanitize(p.lerp(cur, alpha)).extend((n + confidence).min(params.max_history))
            } else {
                cur.extend(confidence)
            };
            out.push(resolved);
        }
    }
    out
}
