//! Directional albedo tables of the single-scattering GGX lobe, which the energy compensation
//! of the full BRDF needs (Kulla & Conty 2017; Kelemen & Szirmay-Kalos 2001).
//!
//! With Schlick's Fresnel `F = F0 + (1 − F0) w(v·h)`, `w = (1 − v·h)⁵`, the directional albedo
//! of `D V F` is linear in `F0`: `E_F(μ) = F0 E(μ) + (1 − F0) E_w(μ)`, so two tables hold it
//! for every `F0`:
//!
//! * `E(μ, r) = ∫ D V (n·l) dω_l`: the albedo with `F = 1` (what a white metal keeps after one
//!   bounce);
//! * `E_w(μ, r) = ∫ D V w(v·h) (n·l) dω_l`: the Schlick-weighted albedo (the "bias" of the
//!   split-sum environment BRDF);
//!
//! and two rows hold their cosine-weighted hemispherical averages
//! `E_avg(r) = 2 ∫₀¹ E(μ) μ dμ`, `E_w,avg(r)`.
//!
//! The grid is [`ALBEDO_TABLE_SIZE`]² nodes: perceptual roughness
//! `r_j = r_min + (1 − r_min) (j / (N − 1))²` from `r_min` = [`MIN_PERCEPTUAL_ROUGHNESS`] (the
//! smallest any material has) to 1, denser where the albedo at grazing angles changes fastest
//! with roughness (this halved the furnace error of an even spacing), and
//! `x_i = i / (N − 1)` with `μ = n·v = x²`, which puts nodes close to grazing where smooth lobes
//! lose their energy (the first node above 0 is at 88.1°). Lookups interpolate bilinearly in
//! `(x, r)`; the GPU does the same on `crates/hikari-render/shaders/common/brdf_tables.wgsl`,
//! which `examples/gen_brdf_tables.rs` writes from [`AlbedoTables::to_wgsl`].
//!
//! The integrals are deterministic quadratures over Heitz 2018's visible-normal
//! parameterisation, where the integrand is `G2(v, l) / G1(v)` (times `w`), bounded by 1 and
//! continuous (it falls to 0 as `l` reaches the horizon), so a midpoint rule converges
//! without sampling noise. Computed once per process on first use: 0.2 s in release, 0.5 s in
//! an unoptimised build.

use super::material::{MIN_PERCEPTUAL_ROUGHNESS, alpha_from_perceptual};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Nodes per axis of the tables (roughness x `sqrt(n·v)`).
pub const ALBEDO_TABLE_SIZE: usize = 32;

/// Quadrature nodes per axis of each directional albedo (`n × n` visible normals).
pub const ALBEDO_QUADRATURE_NODES: usize = 64;

/// Where the `μ = 0` column is evaluated: the albedo's limit at grazing, reached to far better
/// than the tables' precision by `μ = 1e-9` (the weight `G2 / G1` tends to 1 on every
/// reflected direction above the horizon).
const GRAZING_MU: f64 = 1e-9;

const N: usize = ALBEDO_TABLE_SIZE;

/// Smith `Λ` for isotropic GGX from `μ = n·w > 0`.
fn lambda(mu: f64, alpha: f64) -> f64 {
    let tan2 = (1.0 - mu) * (1.0 + mu) / (mu * mu);
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Single-scattering directional albedos `(E, E_w)` of the isotropic GGX lobe of width `alpha`
/// (height-correlated Smith) seen at `μ = n·v` ∈ (0, 1], by a midpoint rule on `nodes x nodes`
/// visible normals (Heitz 2018's map from the unit square, halved in azimuth by the lobe's
/// mirror symmetry). Both are dimensionless, in [0, 1].
pub fn single_scattering_albedo(mu: f64, alpha: f64, nodes: usize) -> (f64, f64) {
    let mu = mu.clamp(GRAZING_MU, 1.0);
    let sin_v = ((1.0 - mu) * (1.0 + mu)).sqrt();
    let lambda_v = lambda(mu, alpha);
    // The view direction stretched to a lobe of width 1, and a frame around it.
    let (sx, sz) = (alpha * sin_v, mu);
    let len = (sx * sx + sz * sz).sqrt();
    let (vhx, vhz) = (sx / len, sz / len);
    let s = 0.5 * (1.0 + vhz);
    let (mut e, mut e_w, mut total) = (0.0, 0.0, 0.0);
    for i in 0..nodes {
        // The disk radius r = sqrt(u), u = 1 − (1 − s)⁴ with s on midpoints: GGX's tail (the
        // facets steep enough to reflect below the horizon) sits in a band of width ~α² at
        // u → 1, which uniform nodes in u miss; this map spreads it over ~α^½ in s and makes
        // the disk's edge, where sqrt(1 − r²) has an infinite slope, smooth.
        let t = 1.0 - (i as f64 + 0.5) / nodes as f64;
        let t2 = t * t;
        let r = (1.0 - t2 * t2).sqrt();
        let jacobian = 4.0 * t2 * t;
        total += jacobian * nodes as f64;
        for j in 0..nodes {
            // φ over [−π/2, π/2]: φ and π − φ are mirror images about the plane of incidence.
            let phi = PI * ((j as f64 + 0.5) / nodes as f64 - 0.5);
            let p1 = r * phi.cos();
            let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
            let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
            // Frame: t1 = (0, 1, 0), t2 = vh × t1 = (−vh.z, 0, vh.x), vh = (vh.x, 0, vh.z).
            let nx = -vhz * p2 + vhx * p3;
            let ny = p1;
            let nz = vhx * p2 + vhz * p3;
            let (hx, hy, hz) = (alpha * nx, alpha * ny, nz.max(0.0));
            let hl = (hx * hx + hy * hy + hz * hz).sqrt();
            let (hx, hz) = (hx / hl, hz / hl);
            let v_dot_h = sin_v * hx + mu * hz;
            let lz = 2.0 * v_dot_h * hz - mu;
            if v_dot_h <= 0.0 || lz <= 0.0 {
                continue;
            }
            let weight = (1.0 + lambda_v) / (1.0 + lambda_v + lambda(lz.min(1.0), alpha));
            e += jacobian * weight;
            e_w += jacobian * weight * (1.0 - v_dot_h.min(1.0)).powi(5);
        }
    }
    // Divided by the rule's own integral of 1 (not by nodes²), so a constant integrand comes out
    // exact: this cancels the largest part of the midpoint rule's error on the Jacobian.
    (e / total, e_w / total)
}

/// The tables of the module docs, in `f64`, indexed `[roughness j][x i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoTables {
    /// `E(μ = x_i², r_j)`: single-scattering albedo with `F = 1`.
    pub e: [[f64; N]; N],
    /// `E_w(μ = x_i², r_j)`: single-scattering albedo with `F = (1 − v·h)⁵`.
    pub e_schlick: [[f64; N]; N],
    /// `E_avg(r_j) = 2 ∫₀¹ E(μ) μ dμ`.
    pub e_avg: [f64; N],
    /// `E_w,avg(r_j)`, likewise.
    pub e_schlick_avg: [f64; N],
}

/// `2 ∫₀¹ E(μ) μ dμ = 4 ∫₀¹ E(x²) x³ dx` of the piecewise-linear interpolant in `x` of one
/// table row, integrated exactly (on `[a, b]`, `E = E_a + (E_b − E_a)(x − a)/(b − a)` and
/// `∫ x³ = (b⁴ − a⁴)/4`, `∫ x⁴ = (b⁵ − a⁵)/5`). Averaging the interpolant the lookups use,
/// rather than the exact `E`, makes the compensation lobes integrate to exactly what the table
/// says is missing.
fn hemispherical_average(row: &[f64; N]) -> f64 {
    let h = 1.0 / (N - 1) as f64;
    let mut acc = 0.0;
    for i in 0..N - 1 {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        let slope = (row[i + 1] - row[i]) / h;
        let c = row[i] - slope * a;
        acc += c * (b.powi(4) - a.powi(4)) / 4.0 + slope * (b.powi(5) - a.powi(5)) / 5.0;
    }
    4.0 * acc
}

/// Perceptual roughness of table row `j`.
pub fn table_roughness(j: usize) -> f64 {
    let u = j as f64 / (N - 1) as f64;
    MIN_PERCEPTUAL_ROUGHNESS + (1.0 - MIN_PERCEPTUAL_ROUGHNESS) * u * u
}

/// `(r − r_min) / (1 − r_min)`: where perceptual roughness `r` falls on the rows, in [0, 1].
fn roughness_coordinate(perceptual_roughness: f64) -> f64 {
    ((perceptual_roughness - MIN_PERCEPTUAL_ROUGHNESS) / (1.0 - MIN_PERCEPTUAL_ROUGHNESS))
        .max(0.0)
        .sqrt()
}

/// Grid coordinate of `value` ∈ [0, 1] on `N` nodes: the lower node and the weight of the upper.
fn grid(value: f64) -> (usize, f64) {
    let p = value.clamp(0.0, 1.0) * (N - 1) as f64;
    let i = (p.floor() as usize).min(N - 2);
    (i, p - i as f64)
}

impl AlbedoTables {
    /// Integrates every entry ([`single_scattering_albedo`] on [`ALBEDO_QUADRATURE_NODES`]²
    /// nodes) and averages each row's interpolant exactly.
    pub fn compute() -> Self {
        let mut t = Self {
            e: [[0.0; N]; N],
            e_schlick: [[0.0; N]; N],
            e_avg: [0.0; N],
            e_schlick_avg: [0.0; N],
        };
        for j in 0..N {
            let alpha = alpha_from_perceptual(table_roughness(j));
            for i in 0..N {
                let x = i as f64 / (N - 1) as f64;
                let (e, e_w) = single_scattering_albedo(x * x, alpha, ALBEDO_QUADRATURE_NODES);
                t.e[j][i] = e;
                t.e_schlick[j][i] = e_w;
            }
            t.e_avg[j] = hemispherical_average(&t.e[j]);
            t.e_schlick_avg[j] = hemispherical_average(&t.e_schlick[j]);
        }
        t
    }

    /// `(E, E_w)` at `μ = n·v` and perceptual roughness `r`, bilinear in `(sqrt(μ), r)`;
    /// `μ` is clamped to [0, 1] and `r` to [`MIN_PERCEPTUAL_ROUGHNESS`, 1].
    pub fn lookup(&self, mu: f64, perceptual_roughness: f64) -> (f64, f64) {
        let (i, fx) = grid(mu.clamp(0.0, 1.0).sqrt());
        let (j, fr) = grid(roughness_coordinate(perceptual_roughness));
        let bilinear = |t: &[[f64; N]; N]| {
            let lo = t[j][i] + (t[j][i + 1] - t[j][i]) * fx;
            let hi = t[j + 1][i] + (t[j + 1][i + 1] - t[j + 1][i]) * fx;
            lo + (hi - lo) * fr
        };
        (bilinear(&self.e), bilinear(&self.e_schlick))
    }

    /// `(E_avg, E_w,avg)` at perceptual roughness `r` (clamped as in [`Self::lookup`]), linear
    /// in `r`.
    pub fn average(&self, perceptual_roughness: f64) -> (f64, f64) {
        let (j, fr) = grid(roughness_coordinate(perceptual_roughness));
        let lerp = |t: &[f64; N]| t[j] + (t[j + 1] - t[j]) * fr;
        (lerp(&self.e_avg), lerp(&self.e_schlick_avg))
    }

    /// The tables as the GPU reads them (`hikari::brdf_tables`, a storage buffer of
    /// `vec2<f32>`): `N * N` pairs `(E, E_w)` at `j * N + i`, then `N` pairs
    /// `(E_avg, E_w,avg)` at `N * N + j`.
    pub fn gpu_data(&self) -> Vec<[f32; 2]> {
        let mut out = Vec::with_capacity(N * N + N);
        for j in 0..N {
            for i in 0..N {
                out.push([self.e[j][i] as f32, self.e_schlick[j][i] as f32]);
            }
        }
        for j in 0..N {
            out.push([self.e_avg[j] as f32, self.e_schlick_avg[j] as f32]);
        }
        out
    }
}

/// The tables, integrated on first use and shared by the whole process.
pub fn albedo_tables() -> &'static AlbedoTables {
    static TABLES: OnceLock<AlbedoTables> = OnceLock::new();
    TABLES.get_or_init(AlbedoTables::compute)
}

/// Perceptual roughness at which the tables are read for an anisotropic lobe of widths
/// `(alpha_x, alpha_y)`: that of the isotropic lobe with the same peak `D(n)`,
/// `alpha = sqrt(alpha_x alpha_y)`, i.e. `r = (alpha_x alpha_y)^(1/4)`, clamped to
/// [[`MIN_PERCEPTUAL_ROUGHNESS`], 1]. For the anisotropy mapping of
/// [`super::material::anisotropic_alphas`], which keeps the product, it is the material's own
/// roughness unless a width was raised to its minimum.
///
/// One roughness for every direction keeps the compensation reciprocal and costs the GPU one
/// table row a pixel; the price is that it is only approximate for anisotropic lobes, which
/// lose less than the isotropic lobe seen along their smooth axis and more along the rough
/// one (docs/brdf.md gives the furnace numbers). Reading each direction at its projected
/// width, or everything at the smaller width, was measured and is no better overall.
pub fn isotropic_equivalent_roughness(alpha_x: f64, alpha_y: f64) -> f64 {
    (alpha_x * alpha_y)
        .sqrt()
        .sqrt()
        .clamp(MIN_PERCEPTUAL_ROUGHNESS, 1.0)
}
