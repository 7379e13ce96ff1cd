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
