//! Dense RGB tables with the GPU's sampling rules (texel centres at `(i + 0.5) / n`, clamp to
//! edge, linear filtering), so a WGSL twin reading the same data as textures agrees.

use serde::{Deserialize, Serialize};

/// A 2D or 3D table of RGB `f32` texels; `x` varies fastest, then `y`, then `z`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// Texels along x, y, z (`z = 1` for a 2D table).
    pub size: [usize; 3],
    /// `size[0] * size[1] * size[2]` texels.
    pub data: Vec<[f32; 3]>,
}

fn axis(u: f64, n: usize) -> (usize, usize, f64) {
    let t = (u * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
    let i0 = (t.floor() as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, t - i0 as f64)
}

impl Table {
    /// A table filled from `f(x, y, z)`, computed on all cores.
    pub fn from_fn(size: [usize; 3], f: impl Fn(usize, usize, usize) -> [f64; 3] + Sync) -> Self {
        let [nx, ny, _] = size;
        let data = crate::parallel::map(size.iter().product(), |i| {
            f(i % nx, (i / nx) % ny, i / (nx * ny)).map(|v| v as f32)
        });
        Self { size, data }
    }

    /// The texel at integer coordinates.
    pub fn at(&self, x: usize, y: usize, z: usize) -> [f64; 3] {
        let [nx, ny, _] = self.size;
        self.data[(z * ny + y) * nx + x].map(f64::from)
    }

    /// Trilinear (bilinear when 2D) sample at normalised coordinates.
    pub fn sample(&self, u: f64, v: f64, w: f64) -> [f64; 3] {
        let (x0, x1, fx) = axis(u, self.size[0]);
        let (y0, y1, fy) = axis(v, self.size[1]);
        let (z0, z1, fz) = axis(w, self.size[2]);
        let mut out = [0.0; 3];
        for (z, wz) in [(z0, 1.0 - fz), (z1, fz)] {
            for (y, wy) in [(y0, 1.0 - fy), (y1, fy)] {
                for (x, wx) in [(x0, 1.0 - fx), (x1, fx)] {
                    let wgt = wx * wy * wz;
                    if wgt != 0.0 {
                        let t = self.at(x, y, z);
                        for c in 0..3 {
                            out[c] += wgt * t[c];
                        }
                    }
                }
            }
        }
        out
    }
}
