//! Smits-style RGB → reflectance basis, as Ghost of Tsushima computed it for the Purkinje shift
//! (Patry 2021, after Smits 1999): three reflectance spectra `R_r, R_g, R_b` on a 10 nm grid
//! (390..=780 nm) that
//!
//! * reproduce Rec.709 under D65: spectrum `R_j` has linear Rec.709 colour `e_j`,
//! * lie in `[0, 1]` and sum to 1 at every wavelength (so white is a flat 1 and any RGB in
//!   `[0, 1]³` gives a physically valid reflectance),
//! * are as smooth as possible: minimal `Σ_j Σ_λ (R_j(λ + Δ) − R_j(λ))²`.
//!
//! The colour constraint uses a "spectral Rec.709": XYZ from the CIE 1931 tables under the D65
//! table, then Rec.709's XYZ → RGB, then a per-channel von Kries scale (≈ 1 ± 2·10⁻⁴) so that
//! the D65 table maps to RGB (1, 1, 1) exactly; without it "sum to 1" and "reproduce Rec.709"
//! contradict each other by the rounding of the tables.
//!
//! Solved as a small convex QP by ADMM (splitting the per-wavelength simplex constraint from the
//! linear colour constraints), then polished by solving the equality-constrained problem on the
//! detected active set, which gives the exact optimum when the active set is right.
//!
//! Smits' original table (7 spectra, 10 bins 380..=720 nm) is [`super::spectral::SMITS1999`].

use super::primaries::REC709;
use super::spectral::{COARSE_LEN, coarse_reflectance_to_xyz, coarse_wavelengths_nm};
use super::to_dmat3;
use crate::linalg::Lu;
use std::sync::OnceLock;

/// Number of wavelengths of the basis.
pub const N: usize = COARSE_LEN;

/// The computed basis.
#[derive(Clone, Debug, PartialEq)]
pub struct SmitsBasis {
    /// Wavelengths, nm.
    pub wavelengths_nm: [f64; N],
    /// Reflectance of the red, green and blue basis spectra at each wavelength, in [0, 1].
    pub rgb: [[f64; N]; 3],
}

/// `3 x N` matrix: reflectance on the grid → linear "spectral Rec.709" RGB under D65
/// (white → (1, 1, 1) exactly, see the module docs).
pub fn reflectance_to_rec709() -> [[f64; N]; 3] {
    let xyz = coarse_reflectance_to_xyz();
    let m = to_dmat3(&REC709.xyz_to_rgb());
    let mut out = [[0.0; N]; 3];
    for i in 0..N {
        let v = m * glam::DVec3::new(xyz[0][i], xyz[1][i], xyz[2][i]);
        for k in 0..3 {
            out[k][i] = v[k];
        }
    }
    let white: [f64; 3] = std::array::from_fn(|k| out[k].iter().sum());
    for k in 0..3 {
        for v in out[k].iter_mut() {
            *v /= white[k];
        }
    }
    out
}

/// The basis, computed once.
pub fn smits_basis() -> &'static SmitsBasis {
    static B: OnceLock<SmitsBasis> = OnceLock::new();
    B.get_or_init(compute)
}

/// Linear Rec.709 RGB → reflectance spectrum on the basis grid (valid in [0, 1] for RGB in
/// [0, 1]³).
pub fn rgb_to_reflectance(rgb: [f64; 3]) -> [f64; N] {
    let b = smits_basis();
    std::array::from_fn(|i| rgb[0] * b.rgb[0][i] + rgb[1] * b.rgb[1][i] + rgb[2] * b.rgb[2][i])
}

/// Colour of a reflectance on the basis grid, linear Rec.709 (the spectral Rec.709 above).
pub fn reflectance_rgb(r: &[f64; N]) -> [f64; 3] {
    let t = reflectance_to_rec709();
    std::array::from_fn(|k| (0..N).map(|i| t[k][i] * r[i]).sum())
}

/// Euclidean projection of `v` onto the probability simplex {x ≥ 0, Σx = 1}.
fn project_simplex(v: [f64; 3]) -> [f64; 3] {
    let mut u = v;
    u.sort_by(|a, b| b.total_cmp(a));
    let mut css = 0.0;
    let mut theta = 0.0;
    for (j, uj) in u.iter().enumerate() {
        css += uj;
        let t = (css - 1.0) / (j as f64 + 1.0);
        if uj - t > 0.0 {
            theta = t;
        }
    }
    v.map(|x| (x - theta).max(0.0))
}

// Variable layout: x[j * N + i] = R_j(λ_i).
const NV: usize = 3 * N;

fn smoothness_hessian() -> Vec<f64> {
    let mut p = vec![0.0; NV * NV];
    for j in 0..3 {
        for i in 0..N - 1 {
            let (a, b) = (j * N + i, j * N + i + 1);
            // ½ xᵀ P x = Σ (x_b − x_a)²  →  P = 2 DᵀD
            p[a * NV + a] += 2.0;
            p[b * NV + b] += 2.0;
            p[a * NV + b] -= 2.0;
            p[b * NV + a] -= 2.0;
        }
    }
    p
}

/// Colour rows: R_r → (1,0,0), R_g → (0,1,0). The blue spectrum's colour follows from the sum
/// constraint, so including it would make the system singular.
fn colour_constraints() -> (Vec<[f64; NV]>, Vec<f64>) {
    let t = reflectance_to_rec709();
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for j in 0..2 {
        for k in 0..3 {
            let mut r = [0.0; NV];
            r[j * N..(j + 1) * N].copy_from_slice(&t[k]);
            rows.push(r);
            rhs.push(if j == k { 1.0 } else { 0.0 });
        }
    }
    (rows, rhs)
}

fn kkt_solve(p: &[f64], rho: f64, rows: &[Vec<f64>]) -> Option<Lu> {
    let m = rows.len();
    let n = NV + m;
    let mut k = vec![0.0; n * n];
    for r in 0..NV {
        for c in 0..NV {
            k[r * n + c] = p[r * NV + c];
        }
        k[r * n + r] += rho;
    }
    for (a, row) in rows.iter().enumerate() {
        for c in 0..NV {
            k[(NV + a) * n + c] = row[c];
            k[c * n + NV + a] = row[c];
        }
    }
    Lu::new(&k, n)
}

fn compute() -> SmitsBasis {
    let p = smoothness_hessian();
    let (crow, crhs) = colour_constraints();
    let crow: Vec<Vec<f64>> = crow.iter().map(|r| r.to_vec()).collect();
    let rho = 1.0;
    let lu = kkt_solve(&p, rho, &crow).expect("colour constraints are independent");
    // Feasible-ish start: a flat third each.
    let mut z = vec![1.0 / 3.0; NV];
    let mut u = vec![0.0; NV];
    let mut x = z.clone();
    for _ in 0..4000 {
        let mut rhs: Vec<f64> = (0..NV).map(|i| rho * (z[i] - u[i])).collect();
        rhs.extend_from_slice(&crhs);
        let sol = lu.solve(&rhs);
        x.copy_from_slice(&sol[..NV]);
        for i in 0..N {
            let v = project_simplex([
                x[i] + u[i],
                x[N + i] + u[N + i],
                x[2 * N + i] + u[2 * N + i],
            ]);
            for j in 0..3 {
                z[j * N + i] = v[j];
            }
        }
        for i in 0..NV {
            u[i] += x[i] - z[i];
        }
    }
    let polished = polish(&p, &crow, &crhs, &z).unwrap_or(z);
    let rgb = std::array::from_fn(|j| std::array::from_fn(|i| polished[j * N + i].clamp(0.0, 1.0)));
    SmitsBasis {
        wavelengths_nm: coarse_wavelengths_nm(),
        rgb,
    }
}

/// Exact optimum for the active set read off the ADMM iterate: variables near 0 are fixed at 0,
/// and the sum-to-one and colour constraints hold with equality. Rejected (None) when the
/// result leaves the feasible set, i.e. the active set guess was wrong.
fn polish(p: &[f64], crow: &[Vec<f64>], crhs: &[f64], z: &[f64]) -> Option<Vec<f64>> {
    let mut rows: Vec<Vec<f64>> = crow.to_vec();
    let mut rhs: Vec<f64> = crhs.to_vec();
    for i in 0..N {
        let mut r = vec![0.0; NV];
        for j in 0..3 {
            r[j * N + i] = 1.0;
        }
        rows.push(r);
        rhs.push(1.0);
    }
    for (v, zv) in z.iter().enumerate() {
        if *zv < 1e-6 {
            let mut r = vec![0.0; NV];
            r[v] = 1.0;
            rows.push(r);
            rhs.push(0.0);
        }
    }
    let lu = kkt_solve(p, 0.0, &rows)?;
    let mut b = vec![0.0; NV];
    b.extend_from_slice(&rhs);
    let sol = lu.solve(&b);
    let x = sol[..NV].to_vec();
    if x.iter().all(|v| *v > -1e-9 && *v < 1.0 + 1e-9) {
        Some(x)
    } else {
        None
    }
}

/// Colour (linear Rec.709) of each basis spectrum, for checks: should be the identity.
pub fn basis_colours() -> [[f64; 3]; 3] {
    let b = smits_basis();
    std::array::from_fn(|j| reflectance_rgb(&b.rgb[j]))
}

/// Smits' (1999) original conversion with his published table ([`super::spectral::SMITS1999`],
/// 10 bins over 380..=720 nm): the smallest component times white, plus the two-primary
/// secondary (cyan, magenta or yellow) and the remaining primary. Kept for comparison with the
/// computed basis; the renderer uses [`smits_basis`].
pub fn smits1999_rgb_to_spectrum(rgb: [f64; 3]) -> [f64; 10] {
    use super::spectral::SMITS1999 as T;
    let [white, cyan, magenta, yellow, red, green, blue] = [0, 1, 2, 3, 4, 5, 6];
    let [r, g, b] = rgb;
    // (row, weight) pairs
    let parts: [(usize, f64); 3] = if r <= g && r <= b {
        if g <= b {
            [(white, r), (cyan, g - r), (blue, b - g)]
        } else {
            [(white, r), (cyan, b - r), (green, g - b)]
        }
    } else if g <= r && g <= b {
        if r <= b {
            [(white, g), (magenta, r - g), (blue, b - r)]
        } else {
            [(white, g), (magenta, b - g), (red, r - b)]
        }
    } else if r <= g {
        [(white, b), (yellow, r - b), (green, g - r)]
    } else {
        [(white, b), (yellow, g - b), (red, r - g)]
    };
    std::array::from_fn(|i| parts.iter().map(|(row, w)| w * T[*row][i]).sum())
}
