//! Product of two SH functions, truncated to L2, with exact triple-product (Gaunt) coefficients.
//!
//! `G[i][j][k] = ∫ Y_i Y_j Y_k dω`. The integrand is a polynomial of degree ≤ 6 in
//! `(x, y, z)`, so a Gauss-Legendre (4 nodes in z) x uniform (8 azimuths) product rule
//! integrates it exactly; the tensor is computed once in f64 at first use.

use super::{Sh, ShCoeff, basis};
use crate::linalg::gauss_legendre;
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// The 9x9x9 Gaunt tensor for the crate's basis (exact to f64 rounding).
pub fn gaunt_l2() -> &'static [[[f64; 9]; 9]; 9] {
    static G: OnceLock<[[[f64; 9]; 9]; 9]> = OnceLock::new();
    G.get_or_init(|| {
        let (zs, ws) = gauss_legendre(6);
        let n_phi = 12;
        let mut g = [[[0.0; 9]; 9]; 9];
        for (z, wz) in zs.iter().zip(&ws) {
            let r = (1.0 - z * z).sqrt();
            for p in 0..n_phi {
                let phi = 2.0 * PI * p as f64 / n_phi as f64;
                let y = basis::eval_l2_f64(DVec3::new(r * phi.cos(), r * phi.sin(), *z));
                let w = wz * 2.0 * PI / n_phi as f64;
                for i in 0..9 {
                    for j in 0..9 {
                        let wij = w * y[i] * y[j];
                        for k in 0..9 {
                            g[i][j][k] += wij * y[k];
                        }
                    }
                }
            }
        }
        // Exact zeros are exact; drop quadrature dust so sparsity is visible.
        for v in g.iter_mut().flatten().flatten() {
            if v.abs() < 1e-14 {
                *v = 0.0;
            }
        }
        g
    })
}

/// SH coefficients of `a(ω) · b(ω)` projected back onto L2 (the degree-4 product truncated).
/// For RGB inputs the product is per channel.
pub fn product_l2<T: ShCoeff>(a: &Sh<T, 9>, b: &Sh<T, 9>) -> Sh<T, 9> {
    let g = gaunt_l2();
    let mut out = Sh::<T, 9>::zero();
    for i in 0..9 {
        for j in 0..9 {
            let ab = a.coeffs[i] * b.coeffs[j];
            for k in 0..9 {
                let gk = g[i][j][k];
                if gk != 0.0 {
                    out.coeffs[k] = out.coeffs[k] + ab * gk as f32;
                }
            }
        }
    }
    out
}

/// Product of an SH function with a scalar L2 function (e.g. RGB radiance times a mono
/// visibility), truncated to L2.
pub fn product_l2_mono<T: ShCoeff>(a: &Sh<T, 9>, b: &Sh<f32, 9>) -> Sh<T, 9> {
    let g = gaunt_l2();
    let mut out = Sh::<T, 9>::zero();
    for i in 0..9 {
        for j in 0..9 {
            let ab = a.coeffs[i] * b.coeffs[j];
            for k in 0..9 {
                let gk = g[i][j][k];
                if gk != 0.0 {
                    out.coeffs[k] = out.coeffs[k] + ab * gk as f32;
                }
            }
        }
    }
    out
}
