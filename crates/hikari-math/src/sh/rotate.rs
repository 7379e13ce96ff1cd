//! Rotation of SH coefficients.
//!
//! Band 1 transforms like a vector (exact, it is the 3x3 rotation itself). Band 2 uses the
//! projection method: a rotated band-2 function is determined by its values at 5 fixed
//! directions, chosen so the 5x5 basis matrix is well conditioned, so the 5x5 rotation is
//! `B⁻ᵀ · [Y₂(Rᵀ n_k)]`. Exact up to rounding for any rotation (no Euler-angle singularities).

use super::{Sh, ShCoeff, basis};
use crate::linalg::invert;
use glam::{DMat3, DVec3, Mat3};
use std::sync::OnceLock;

/// The 5 directions that pin down a band-2 function (each basis term is isolated by one of them).
fn band2_directions() -> [DVec3; 5] {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    [
        DVec3::X,
        DVec3::Z,
        DVec3::new(h, h, 0.0),
        DVec3::new(h, 0.0, h),
        DVec3::new(0.0, h, h),
    ]
}

/// `(Bᵀ)⁻¹` where `B[i][k] = Y_{4+i}(n_k)`, row-major 5x5.
fn band2_inverse() -> &'static [f64; 25] {
    static INV: OnceLock<[f64; 25]> = OnceLock::new();
    INV.get_or_init(|| {
        let dirs = band2_directions();
        let mut bt = [0.0; 25];
        for (k, d) in dirs.iter().enumerate() {
            let y = basis::eval_l2_f64(*d);
            for i in 0..5 {
                bt[k * 5 + i] = y[4 + i];
            }
        }
        let inv = invert(&bt, 5).expect("band-2 sample directions are independent by construction");
        let mut out = [0.0; 25];
        out.copy_from_slice(&inv);
        out
    })
}

/// A rotation prepared for SH: build once, apply to many coefficient sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShRotation {
    /// Band-1 block in the coefficient order (y, z, x), row-major.
    pub band1: [[f64; 3]; 3],
    /// Band-2 block, row-major.
    pub band2: [[f64; 5]; 5],
}

impl ShRotation {
    /// SH rotation that rotates the represented function by `r` (a rotation matrix): the result
    /// `g` satisfies `g(r ω) = f(ω)`.
    pub fn new(r: Mat3) -> Self {
        Self::new_f64(r.as_dmat3())
    }

    /// As [`ShRotation::new`], from a unit quaternion.
    pub fn from_quat(q: glam::Quat) -> Self {
        Self::new_f64(glam::DMat3::from_quat(q.as_dquat()))
    }

    /// As [`ShRotation::new`], from an f64 rotation matrix.
    pub fn new_f64(r: DMat3) -> Self {
        // Band 1: coefficient order (y, z, x) → permute into and out of (x, y, z).
        let perm = [1usize, 2, 0]; // coefficient slot k holds axis perm[k]
        let mut band1 = [[0.0; 3]; 3];
        for (a, pa) in perm.iter().enumerate() {
            for (b, pb) in perm.iter().enumerate() {
                band1[a][b] = r.col(*pb)[*pa];
            }
        }
        // Band 2: column j of the rotation = coefficients of the rotated basis function j,
        // recovered from its values at the 5 pinning directions: Y_j(rᵀ n_k).
        let inv = band2_inverse();
        let rt = r.transpose();
        let dirs = band2_directions();
        let mut vals = [[0.0; 5]; 5]; // vals[k][j]
        for (k, d) in dirs.iter().enumerate() {
            let y = basis::eval_l2_f64(rt * *d);
            vals[k].copy_from_slice(&y[4..9]);
        }
        let mut band2 = [[0.0; 5]; 5];
        for i in 0..5 {
            for j in 0..5 {
                band2[i][j] = (0..5).map(|k| inv[i * 5 + k] * vals[k][j]).sum();
            }
        }
        Self { band1, band2 }
    }

    /// Applies the rotation to L0, L1 or L2 coefficients.
    pub fn apply<T: ShCoeff, const N: usize>(&self, sh: &Sh<T, N>) -> Sh<T, N> {
        let mut out = *sh;
        if N >= 4 {
            for a in 0..3 {
                let mut acc = T::default();
                for b in 0..3 {
                    acc = acc + sh.coeffs[1 + b] * self.band1[a][b] as f32;
                }
                out.coeffs[1 + a] = acc;
            }
        }
        if N >= 9 {
            for a in 0..5 {
                let mut acc = T::default();
                for b in 0..5 {
                    acc = acc + sh.coeffs[4 + b] * self.band2[a][b] as f32;
                }
                out.coeffs[4 + a] = acc;
            }
        }
        out
    }
}
