//! Projection onto the SH basis: from a function (exact quadrature), from sample sets, and
//! from a cube map (per-texel solid angles).

use super::{Sh, ShCoeff, basis};
use crate::MathError;
use crate::linalg::gauss_legendre;
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

/// Projects `f` with a product quadrature: Gauss-Legendre in `z = cos θ` (`n_z` nodes) times
/// `n_phi` uniform azimuths. Exact when `f · Y_i` is a polynomial of degree `< min(2 n_z, n_phi)`
/// in `(x, y, z)`, so an L2 function times the L2 basis needs only `n_z = 3`, `n_phi = 5`.
pub fn project_fn_quadrature<T: ShCoeff, const N: usize>(
    mut f: impl FnMut(Vec3) -> T,
    n_z: usize,
    n_phi: usize,
) -> Sh<T, N> {
    let (zs, ws) = gauss_legendre(n_z.max(1));
    let n_phi = n_phi.max(1);
    // f64 accumulation: thousands of f32 terms would cost ~1e-5 relative accuracy.
    let mut acc = Accumulator::<N>::new();
    for (z, wz) in zs.iter().zip(&ws) {
        let r = (1.0 - z * z).max(0.0).sqrt();
        for k in 0..n_phi {
            let phi = 2.0 * PI * (k as f64 + 0.5) / n_phi as f64;
            let d = DVec3::new(r * phi.cos(), r * phi.sin(), *z);
            let w = wz * 2.0 * PI / n_phi as f64;
            acc.add(d, f(d.as_vec3()), w);
        }
    }
    acc.finish(1.0)
}

/// Projects `f` with a 32 x 64 quadrature: exact for band-limited `f` up to band ~29 and
/// accurate for smooth ones.
pub fn project_fn<T: ShCoeff, const N: usize>(f: impl FnMut(Vec3) -> T) -> Sh<T, N> {
    project_fn_quadrature(f, 32, 64)
}

/// f64 accumulator of `Σ w f(ω) Y_i(ω)`, per channel.
struct Accumulator<const N: usize> {
    acc: [[f64; 3]; N],
}

impl<const N: usize> Accumulator<N> {
    fn new() -> Self {
        Self { acc: [[0.0; 3]; N] }
    }

    fn add<T: ShCoeff>(&mut self, d: DVec3, v: T, w: f64) {
        let y = basis::eval_l2_f64(d);
        for i in 0..N {
            for k in 0..T::CHANNELS {
                self.acc[i][k] += f64::from(v.channel(k)) * w * y[i];
            }
        }
    }

    fn finish<T: ShCoeff>(self, scale: f64) -> Sh<T, N> {
        Sh {
            coeffs: self.acc.map(|c| T::from_channels(c.map(|v| v * scale))),
        }
    }
}

/// Monte Carlo projection of samples drawn uniformly over the whole sphere:
/// `c_i ≈ (4π / n) Σ f(ω_k) Y_i(ω_k)`. Returns zero for an empty set.
pub fn project_uniform_samples<T: ShCoeff, const N: usize>(
    samples: impl IntoIterator<Item = (Vec3, T)>,
) -> Sh<T, N> {
    let mut acc = Accumulator::<N>::new();
    let mut n = 0usize;
    for (d, v) in samples {
        acc.add(d.as_dvec3(), v, 1.0);
        n += 1;
    }
    acc.finish(if n == 0 { 0.0 } else { 4.0 * PI / n as f64 })
}

/// Projection from samples that each carry their own solid angle (steradians), e.g. texels or
/// importance samples with weight `1 / pdf / n`: `c_i = Σ f_k Y_i(ω_k) ΔΩ_k`.
pub fn project_weighted_samples<T: ShCoeff, const N: usize>(
    samples: impl IntoIterator<Item = (Vec3, T, f32)>,
) -> Sh<T, N> {
    let mut acc = Accumulator::<N>::new();
    for (d, v, w) in samples {
        acc.add(d.as_dvec3(), v, f64::from(w));
    }
    acc.finish(1.0)
}

/// Cube map faces, in the order of the Vulkan / D3D layer index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeFace {
    /// +X (layer 0)
    PosX,
    /// −X (layer 1)
    NegX,
    /// +Y (layer 2)
    PosY,
    /// −Y (layer 3)
    NegY,
    /// +Z (layer 4)
    PosZ,
    /// −Z (layer 5)
    NegZ,
}

impl CubeFace {
    /// All faces in layer order.
    pub const ALL: [CubeFace; 6] = [
        CubeFace::PosX,
        CubeFace::NegX,
        CubeFace::PosY,
        CubeFace::NegY,
        CubeFace::PosZ,
        CubeFace::NegZ,
    ];

    /// Unnormalised direction through face coordinates `s, t ∈ [−1, 1]` (s to the right,
    /// t downwards in the stored image), following the Vulkan / D3D cube map selection table,
    /// so texel `(i, j)` of layer `k` is what a GPU fetches in that direction.
    pub fn direction(self, s: f64, t: f64) -> DVec3 {
        match self {
            CubeFace::PosX => DVec3::new(1.0, -t, -s),
            CubeFace::NegX => DVec3::new(-1.0, -t, s),
            CubeFace::PosY => DVec3::new(s, 1.0, t),
            CubeFace::NegY => DVec3::new(s, -1.0, -t),
            CubeFace::PosZ => DVec3::new(s, -t, 1.0),
            CubeFace::NegZ => DVec3::new(-s, -t, -1.0),
        }
    }
}

/// Unit direction through the centre of texel `(i, j)` (column, row from the top) of a
/// `size x size` face.
pub fn cube_texel_direction(face: CubeFace, size: usize, i: usize, j: usize) -> Vec3 {
    let s = 2.0 * (i as f64 + 0.5) / size as f64 - 1.0;
    let t = 2.0 * (j as f64 + 0.5) / size as f64 - 1.0;
    face.direction(s, t).normalize().as_vec3()
}

/// Exact solid angle (steradians) of texel `(i, j)` of a `size x size` face: the integral of
/// `(1 + s² + t²)^(-3/2)` over the texel, whose antiderivative is `atan2(s t, √(1 + s² + t²))`.
pub fn cube_texel_solid_angle(size: usize, i: usize, j: usize) -> f64 {
    let area = |s: f64, t: f64| (s * t).atan2((1.0 + s * s + t * t).sqrt());
    let inv = 2.0 / size as f64;
    let (s0, t0) = (i as f64 * inv - 1.0, j as f64 * inv - 1.0);
    let (s1, t1) = (s0 + inv, t0 + inv);
    area(s0, t0) - area(s0, t1) - area(s1, t0) + area(s1, t1)
}

/// Projects a cube map given as six row-major faces of `size x size` texels, layer order
/// +X, −X, +Y, −Y, +Z, −Z, weighting each texel by its exact solid angle.
pub fn project_cubemap<T: ShCoeff, const N: usize>(
    size: usize,
    faces: [&[T]; 6],
) -> Result<Sh<T, N>, MathError> {
    for (k, f) in faces.iter().enumerate() {
        if size == 0 || f.len() != size * size {
            return Err(MathError::CubeMapFace {
                face: k,
                got: f.len(),
                expected: size * size,
                size,
            });
        }
    }
    // Solid angles depend only on (i, j), not on the face.
    let solid: Vec<f64> = (0..size * size)
        .map(|k| cube_texel_solid_angle(size, k % size, k / size))
        .collect();
    let mut acc = Accumulator::<N>::new();
    for (face, texels) in CubeFace::ALL.iter().zip(faces) {
        for j in 0..size {
            for i in 0..size {
                let s = 2.0 * (i as f64 + 0.5) / size as f64 - 1.0;
                let t = 2.0 * (j as f64 + 0.5) / size as f64 - 1.0;
                let d = face.direction(s, t).normalize();
                acc.add(d, texels[j * size + i], solid[j * size + i]);
            }
        }
    }
    Ok(acc.finish(1.0))
}
