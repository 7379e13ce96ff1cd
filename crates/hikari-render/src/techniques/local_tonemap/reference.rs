//! CPU twin of every local tonemap pass, in the same order and arithmetic.

use super::{BlurParams, GRID_SIZE, LocalTonemapParams, WIDE_RADIUS, WIDE_SIZE};
use crate::techniques::exposure::reference::LUMA;

/// Fixed-point unit of `local_tonemap.fill`'s sums.
pub const FIXED: f32 = 1024.0;

/// A volume of `[f32; 2]` homogeneous pairs (Σ w V, Σ w), x fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    pub size: [usize; 3],
    pub data: Vec<[f32; 2]>,
}

impl Volume {
    pub fn new(size: [usize; 3]) -> Self {
        Self {
            size,
            data: vec![[0.0; 2]; size[0] * size[1] * size[2]],
        }
    }

    pub fn at(&self, x: usize, y: usize, z: usize) -> [f32; 2] {
        self.data[(z * self.size[1] + y) * self.size[0] + x]
    }

    fn at_mut(&mut self, x: usize, y: usize, z: usize) -> &mut [f32; 2] {
        &mut self.data[(z * self.size[1] + y) * self.size[0] + x]
    }
}

/// Exposed log2 luminance relative to the grid's lower end, clamped to its range.
pub fn grid_log2(rgb: [f32; 3], scale: f32, p: &LocalTonemapParams) -> f32 {
    let y = (rgb[0] * LUMA[0] + rgb[1] * LUMA[1] + rgb[2] * LUMA[2]) * scale;
    let y = if y >= 0.0 { y } else { 0.0 };
    (y.max(1e-30).log2() - p.grid[0]).clamp(0.0, p.grid[2])
}

/// Twin of `local_tonemap.fill`: the grid and the 64x32 column sums (a volume of depth 1).
pub fn fill(
    radiance: &[[f32; 3]],
    size: [usize; 2],
    scale: f32,
    p: &LocalTonemapParams,
) -> (Volume, Volume) {
    let [gw, gh, gd] = GRID_SIZE.map(|v| v as usize);
    let mut acc_w = vec![0u32; gw * gh * gd];
    let mut acc_wv = vec![0u32; gw * gh * gd];
    for y in 0..size[1] {
        for x in 0..size[0] {
            // The GPU's cell of pixel x is the cx with cx*W/64 <= x < (cx+1)*W/64.
            let cx = (0..gw)
                .find(|&c| x < (c + 1) * size[0] / gw)
                .unwrap_or(gw - 1);
            let cy = (0..gh)
                .find(|&c| y < (c + 1) * size[1] / gh)
                .unwrap_or(gh - 1);
            let v = grid_log2(radiance[y * size[0] + x], scale, p);
            let t = v * p.grid[1] - 0.5;
            let k = t.floor();
            let w1 = ((t - k) * FIXED).round() as u32;
            let w0 = FIXED as u32 - w1;
            let k0 = k.clamp(0.0, (gd - 1) as f32) as usize;
            let k1 = (k + 1.0).clamp(0.0, (gd - 1) as f32) as usize;
            for (kk, w) in [(k0, w0), (k1, w1)] {
                let i = (kk * gh + cy) * gw + cx;
                acc_w[i] += w;
                acc_wv[i] += (w as f32 * v).round() as u32;
            }
        }
    }
    let mut grid = Volume::new([gw, gh, gd]);
    let mut coarse = Volume::new([gw, gh, 1]);
    for z in 0..gd {
        for y in 0..gh {
            for x in 0..gw {
                let i = (z * gh + y) * gw + x;
                *grid.at_mut(x, y, z) = [acc_wv[i] as f32 / FIXED, acc_w[i] as f32 / FIXED];
                let c = coarse.at_mut(x, y, 0);
                c[0] += acc_wv[i] as f32;
                c[1] += acc_w[i] as f32;
            }
        }
    }
    for c in &mut coarse.data {
        *c = [c[0] / FIXED, c[1] / FIXED];
    }
    (grid, coarse)
}

fn gaussian(i: i32, sigma: f32) -> f32 {
    let x = i as f32 / sigma;
    (-0.5 * x * x).exp()
}

/// Twin of one blur pass (`blur_grid` or `blur_wide`): zero outside the volume.
pub fn blur(src: &Volume, b: &BlurParams) -> Volume {
    let axis = b.config[0] as usize;
    let r = b.config[1] as i32;
    let sigma = b.sigma[0];
    let norm: f32 = (-r..=r).map(|i| gaussian(i, sigma)).sum();
    let mut dst = Volume::new(src.size);
    for z in 0..src.size[2] {
        for y in 0..src.size[1] {
            for x in 0..src.size[0] {
                let mut sum = [0f32; 2];
                for i in -r..=r {
                    let mut q = [x as i32, y as i32, z as i32];
                    q[axis] += i;
                    if (0..3).all(|a| q[a] >= 0 && q[a] < src.size[a] as i32) {
                        let s = src.at(q[0] as usize, q[1] as usize, q[2] as usize);
                        let w = gaussian(i, sigma);
                        sum[0] += w * s[0];
                        sum[1] += w * s[1];
                    }
                }
                *dst.at_mut(x, y, z) = [sum[0] / norm, sum[1] / norm];
            }
        }
    }
    dst
}

fn bspline(t: f32) -> [f32; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        (1.0 - t).powi(3) / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

/// Twin of `local_tonemap.upsample`: 256x128 log2 luminance relative to the grid's lower end.
pub fn upsample(src: &Volume, p: &LocalTonemapParams) -> Vec<f32> {
    let [ow, oh] = WIDE_SIZE.map(|v| v as usize);
    let [sw, sh] = [src.size[0], src.size[1]];
    let mut out = vec![0f32; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            let px = (x as f32 + 0.5) * sw as f32 / ow as f32 - 0.5;
            let py = (y as f32 + 0.5) * sh as f32 / oh as f32 - 0.5;
            let (bx, by) = (px.floor(), py.floor());
            let (wx, wy) = (bspline(px - bx), bspline(py - by));
            let mut sum = [0f32; 2];
            for (j, wyj) in wy.iter().enumerate() {
                for (i, wxi) in wx.iter().enumerate() {
                    let qx = (bx as i32 + i as i32 - 1).clamp(0, sw as i32 - 1) as usize;
                    let qy = (by as i32 + j as i32 - 1).clamp(0, sh as i32 - 1) as usize;
                    let s = src.at(qx, qy, 0);
                    sum[0] += wxi * wyj * s[0];
                    sum[1] += wxi * wyj * s[1];
                }
            }
            out[y * ow + x] = if sum[1] > 0.0 {
                sum[0] / sum[1]
            } else {
                p.tone[3] - p.grid[0]
            };
        }
    }
    out
}

fn taps(pos: f32, n: usize) -> (usize, usize, f32) {
    let p = pos.clamp(0.0, (n - 1) as f32);
    let a = p.floor().min((n - 1) as f32);
    (a as usize, (a as usize + 1).min(n - 1), p - a)
}

/// The grid's bilateral value at pixel (x, y) of an image of `size` with grid log2 `v`
/// (relative), trilinear and normalised; `None` where the grid is empty around it.
pub fn grid_lookup(
    grid: &Volume,
    size: [usize; 2],
    x: usize,
    y: usize,
    v: f32,
    p: &LocalTonemapParams,
) -> Option<f32> {
    let [gw, gh, gd] = grid.size;
    let u = (x as f32 + 0.5) / size[0] as f32;
    let w = (y as f32 + 0.5) / size[1] as f32;
    let tx = taps(u * gw as f32 - 0.5, gw);
    let ty = taps(w * gh as f32 - 0.5, gh);
    let tz = taps(v * p.grid[1] - 0.5, gd);
    let mut g = [0f32; 2];
    for k in 0..8 {
        let (sx, sy, sz) = (k & 1 != 0, k & 2 != 0, k & 4 != 0);
        let pick = |t: (usize, usize, f32), s: bool| if s { (t.1, t.2) } else { (t.0, 1.0 - t.2) };
        let (cx, wx) = pick(tx, sx);
        let (cy, wy) = pick(ty, sy);
        let (cz, wz) = pick(tz, sz);
        let s = grid.at(cx, cy, cz);
        g[0] += wx * wy * wz * s[0];
        g[1] += wx * wy * wz * s[1];
    }
    (g[1] > 1e-6).then(|| g[0] / g[1])
}

/// The intermediate images of the twin.
pub struct Twin {
    pub grid: Volume,
    pub coarse: Volume,
    pub blurred: Volume,
    pub wide: Vec<f32>,
    /// Log2 gain per pixel.
    pub gain: Vec<f32>,
    /// The base layer B per pixel (absolute exposed log2 luminance).
    pub base: Vec<f32>,
    /// The grid's bilateral value alone per pixel (absolute), the wide Gaussian's where empty.
    pub bilateral: Vec<f32>,
}

/// The contrast above the midpoint for a frame whose highlight (exposed log2,
/// `exposure.value.w`) is `highlight`: the look's, or lower where the highlight lies above the
/// fit's target, (T − M) / (H − M), at least the least contrast.
pub fn contrast_above(p: &LocalTonemapParams, highlight: f32) -> f32 {
    let (m, t) = (p.tone[3], p.blend[1]);
    let mut c = p.tone[0];
    if highlight > t && t > m {
        c = c.min(((t - m) / (highlight - m)).max(p.blend[2]));
    }
    c
}

/// Twin of the whole technique on `radiance` (nits) exposed by `scale`, with the frame's
/// highlight `highlight` (`exposure.value.w`).
#[allow(clippy::too_many_arguments)]
pub fn run(
    radiance: &[[f32; 3]],
    size: [usize; 2],
    scale: f32,
    highlight: f32,
    p: &LocalTonemapParams,
    sigma_xy: f32,
    sigma_z: f32,
    wide_sigma: f32,
) -> Twin {
    let (grid, coarse) = fill(radiance, size, scale, p);
    let mut blurred = blur(
        &blur(&grid, &BlurParams::gaussian(0, sigma_xy)),
        &BlurParams::gaussian(1, sigma_xy),
    );
    if sigma_z > 0.0 {
        blurred = blur(&blurred, &BlurParams::gaussian(2, sigma_z));
    }
    let wide_xy = blur(
        &blur(&coarse, &BlurParams::taps(0, wide_sigma, WIDE_RADIUS)),
        &BlurParams::taps(1, wide_sigma, WIDE_RADIUS),
    );
    let wide = upsample(&wide_xy, p);
    let [ow, oh] = WIDE_SIZE.map(|v| v as usize);
    let mut gain = Vec::with_capacity(radiance.len());
    let mut base = Vec::with_capacity(radiance.len());
    let mut bilateral = Vec::with_capacity(radiance.len());
    for y in 0..size[1] {
        for x in 0..size[0] {
            let v = grid_log2(radiance[y * size[0] + x], scale, p);
            let u = (x as f32 + 0.5) / size[0] as f32;
            let w = (y as f32 + 0.5) / size[1] as f32;
            let (x0, x1, fx) = taps(u * ow as f32 - 0.5, ow);
            let (y0, y1, fy) = taps(w * oh as f32 - 0.5, oh);
            let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
            let wide_v = lerp(
                lerp(wide[y0 * ow + x0], wide[y0 * ow + x1], fx),
                lerp(wide[y1 * ow + x0], wide[y1 * ow + x1], fx),
                fy,
            );
            let bil = grid_lookup(&blurred, size, x, y, v, p).unwrap_or(wide_v);
            let b = lerp(wide_v, bil, p.blend[0]) + p.grid[0];
            let i = v + p.grid[0];
            let m = p.tone[3];
            let c = if b > m {
                contrast_above(p, highlight)
            } else {
                p.tone[1]
            };
            let o = c * (b - m) + p.tone[2] * (i - b) + m;
            gain.push((o - i).clamp(-p.grid[3], p.grid[3]));
            base.push(b);
            bilateral.push(bil + p.grid[0]);
        }
    }
    Twin {
        grid,
        coarse,
        blurred,
        wide,
        gain,
        base,
        bilateral,
    }
}

/// The grid's effective Gaussian sigmas for an image of `size`: spatial in pixels (box of a
/// cell, the blur, the bilinear lookup: variance s² (σ² + 1/12 + 1/6)) and range in EV (the
/// fill's tent, the z blur, the lookup's tent: Δ² (σ_z² + 1/6 + 1/6)).
pub fn effective_sigmas(
    size: [usize; 2],
    p: &LocalTonemapParams,
    sigma_xy: f32,
    sigma_z: f32,
) -> (f32, f32) {
    let cell = size[0] as f32 / GRID_SIZE[0] as f32;
    let slice = 1.0 / p.grid[1];
    (
        cell * (sigma_xy * sigma_xy + 0.25).sqrt(),
        slice * (sigma_z * sigma_z + 1.0 / 3.0).sqrt(),
    )
}
