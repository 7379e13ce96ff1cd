//! Small dense f64 helpers: the crate needs a handful of tiny solves and exact quadrature,
//! not a linear-algebra dependency.

/// LU factorisation with partial pivoting, for solving many right-hand sides.
pub(crate) struct Lu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
}

impl Lu {
    /// Factorises a row-major `n x n` matrix; `None` when singular.
    pub(crate) fn new(a: &[f64], n: usize) -> Option<Self> {
        let mut lu = a.to_vec();
        let mut perm: Vec<usize> = (0..n).collect();
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        for col in 0..n {
            let piv = (col..n)
                .max_by(|&i, &j| lu[i * n + col].abs().total_cmp(&lu[j * n + col].abs()))?;
            if lu[piv * n + col].abs() <= 1e-13 * scale {
                return None;
            }
            if piv != col {
                for k in 0..n {
                    lu.swap(piv * n + k, col * n + k);
                }
                perm.swap(piv, col);
            }
            let d = lu[col * n + col];
            for r in col + 1..n {
                let f = lu[r * n + col] / d;
                lu[r * n + col] = f;
                if f != 0.0 {
                    for k in col + 1..n {
                        lu[r * n + k] -= f * lu[col * n + k];
                    }
                }
            }
        }
        Some(Self { n, lu, perm })
    }

    /// Solves `a x = b`.
    pub(crate) fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut x: Vec<f64> = self.perm.iter().map(|&p| b[p]).collect();
        for r in 0..n {
            let mut s = x[r];
            for k in 0..r {
                s -= self.lu[r * n + k] * x[k];
            }
            x[r] = s;
        }
        for r in (0..n).rev() {
            let mut s = x[r];
            for k in r + 1..n {
                s -= self.lu[r * n + k] * x[k];
            }
            x[r] = s / self.lu[r * n + r];
        }
        x
    }
}

/// Inverse of a row-major `n x n` matrix, or `None` if singular.
pub(crate) fn invert(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let lu = Lu::new(a, n)?;
    let mut inv = vec![0.0; n * n];
    for c in 0..n {
        let mut e = vec![0.0; n];
        e[c] = 1.0;
        let x = lu.solve(&e);
        for r in 0..n {
            inv[r * n + c] = x[r];
        }
    }
    Some(inv)
}

/// Gauss-Legendre nodes and weights on [-1, 1]; exact for polynomials of degree `2n - 1`.
/// Newton iteration on the Legendre recurrence, converged to machine precision.
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        // Tricomi's initial guess, then Newton.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pn1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let (x, w) = gauss_legendre(5);
        // ∫_{-1}^{1} z^k dz = 2/(k+1) for even k, 0 for odd k; degree up to 9 must be exact.
        for k in 0..10 {
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
            let exact = if k % 2 == 0 {
                2.0 / (k as f64 + 1.0)
            } else {
                0.0
            };
            assert!((q - exact).abs() < 1e-14, "k={k} q={q} exact={exact}");
        }
    }

    #[test]
    fn solve_recovers_known_solution() {
        let a = [4.0, 1.0, 2.0, 1.0, 5.0, 1.0, 2.0, 1.0, 6.0];
        let x = [1.0, -2.0, 3.0];
        let b: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| a[r * 3 + c] * x[c]).sum())
            .collect();
        let b = Lu::new(&a, 3).unwrap().solve(&b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-12);
        }
        assert!(invert(&[1.0, 2.0, 2.0, 4.0], 2).is_none());
    }
}
