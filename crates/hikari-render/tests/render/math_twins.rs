//! The WGSL math twins (`hikari::sh`, `hikari::color`) against hikari-math on the CPU, on a
//! few hundred seeded random cases each, through the verification kernels of
//! `passes::math_check`.
//!
//! Tolerances are `|gpu − cpu| ≤ rel · scale + abs`, where `scale` is the size of the terms the
//! function combines (not the size of the result), so cancellation in a sum does not make a
//! tight relative bound meaningless and a near-zero result is not held to a relative bound it
//! cannot meet. Each `rel` is a small multiple of f32's unit roundoff (`ε = 2^-24 ≈ 6e-8`) per
//! rounding on the path, summed over both sides (the GPU in f32; hikari-math in f32 or f64),
//! and for the built-ins Vulkan does not round correctly (division 2.5 ulp, `inverseSqrt`
//! 2 ulp, `pow` as `exp2(y log2 x)`), the precision Vulkan allows for them. A constant wrong
//! in its 5th significant digit, a swapped component or a transposed matrix is tens to
//! millions of times over these bounds.

// Record fields are read by index, as the WGSL writes them.
#![allow(clippy::needless_range_loop)]

use crate::common;

use glam::{DVec3, Vec3};
use hikari_math::color::primaries::{ACESCG, LMS_RAYLEIGH, REC709, TONEMAP, rgb_to_rgb};
use hikari_math::color::purkinje::{PurkinjeMatrices, purkinje_reference};
use hikari_math::color::{Mat3Rows, mul3v, transfer};
use hikari_math::sh::basis::{self, C0, C1, C2, C3, C4};
use hikari_math::sh::dering::{
    dering, dering_window, directionality_boost, find_minimum, linear_max_direction,
};
use hikari_math::sh::ycocg::{ShL1YCoCg, rgb_to_ycocg, ycocg_to_rgb};
use hikari_math::sh::{ShL1, ShL2, ShL2Rgb, window, zonal};
use hikari_render::checks::math_check::{Kernel, MathCheck};
use hikari_render::shader;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// Unit roundoff of f32.
const EPS: f64 = f32::EPSILON as f64 * 0.5;

/// Runs `kernel` on `input` and returns one output record per case; `None` without a GPU.
fn run(kernel: Kernel, input: &[f32]) -> Vec<Vec<f32>> {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let check = MathCheck::new(&ctx, &mut lib, kernel).unwrap();
    let out = check.run(&ctx, input).unwrap();
    assert_eq!(
        out.len(),
        input.len() / kernel.in_stride() * kernel.out_stride()
    );
    out.chunks(kernel.out_stride())
        .map(<[f32]>::to_vec)
        .collect()
}

/// The comparisons of one function: counts them, keeps the worst error relative to its
/// tolerance and the first failures.
struct Compare {
    what: &'static str,
    rel: f64,
    abs: f64,
    n: usize,
    worst: f64,
    failures: Vec<String>,
    failed: usize,
}

impl Compare {
    fn new(what: &'static str, rel: f64, abs: f64) -> Self {
        Self {
            what,
            rel,
            abs,
            n: 0,
            worst: 0.0,
            failures: Vec::new(),
            failed: 0,
        }
    }

    /// `got` must be within `rel · scale + abs` of `want`.
    fn check(&mut self, case: usize, got: f32, want: f64, scale: f64) {
        let allowed = self.rel * scale.abs() + self.abs;
        self.check_allowed(case, got, want, allowed);
    }

    /// `got` must be within `allowed` of `want` (for tolerances with several parts).
    fn check_allowed(&mut self, case: usize, got: f32, want: f64, allowed: f64) {
        self.n += 1;
        let err = (got as f64 - want).abs();
        let ratio = if err == 0.0 { 0.0 } else { err / allowed };
        if err.is_nan() || allowed.is_nan() || err > allowed {
            self.failed += 1;
            if self.failures.len() < 8 {
                self.failures.push(format!(
                    "{} case {case}: gpu {got:e}, cpu {want:e}, error {err:.3e} > allowed {allowed:.3e}",
                    self.what
                ));
            }
        }
        if ratio.is_nan() || ratio > self.worst {
            self.worst = if ratio.is_nan() { f64::INFINITY } else { ratio };
        }
    }

    /// A condition that must hold, counted like a comparison.
    fn require(&mut self, case: usize, ok: bool, detail: impl FnOnce() -> String) {
        self.n += 1;
        if !ok {
            self.failed += 1;
            if self.failures.len() < 8 {
                self.failures
                    .push(format!("{} case {case}: {}", self.what, detail()));
            }
        }
    }
}

/// Prints every comparison's worst error (run with `--nocapture` to see how much margin is
/// left) and fails with the first failures of each.
fn report(compares: &[Compare]) {
    let mut failures = Vec::new();
    for c in compares {
        eprintln!(
            "{:<40} {:>6} checks, worst error {:.3} of tolerance{}",
            c.what,
            c.n,
            c.worst,
            if c.failed > 0 {
                format!(", {} FAILED", c.failed)
            } else {
                String::new()
            }
        );
        assert!(c.n > 0, "{}: nothing was compared", c.what);
        failures.extend(c.failures.iter().cloned());
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ---- Inputs ----

fn unit(rng: &mut SmallRng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length_squared();
        if l > 1e-3 && l <= 1.0 {
            return v.normalize();
        }
    }
}

/// `10^u`, u uniform in `[lo, hi)`: magnitudes spread over several decades.
fn decades(rng: &mut SmallRng, lo: f32, hi: f32) -> f32 {
    10f32.powf(rng.random_range(lo..hi))
}

fn random_l2(rng: &mut SmallRng) -> ShL2 {
    let s = decades(rng, -2.0, 2.0);
    ShL2::new(std::array::from_fn(|_| rng.random_range(-1.0..1.0) * s))
}

fn random_l2_rgb(rng: &mut SmallRng) -> ShL2Rgb {
    let s = decades(rng, -2.0, 2.0);
    ShL2Rgb::new(std::array::from_fn(|_| {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ) * s
    }))
}

fn push_rgb(v: &mut Vec<f32>, sh: &ShL2Rgb) {
    for c in &sh.coeffs {
        v.extend_from_slice(&c.to_array());
    }
}

fn read_rgb(r: &[f32]) -> ShL2Rgb {
    ShL2Rgb::new(std::array::from_fn(|i| {
        Vec3::new(r[3 * i], r[3 * i + 1], r[3 * i + 2])
    }))
}

/// `|Y_i(d)|` with the magnitude of the terms each basis function sums, for tolerances.
fn basis_scale(d: Vec3) -> [f64; 9] {
    let (x, y, z) = (d.x as f64, d.y as f64, d.z as f64);
    [
        C0,
        C1 * y.abs(),
        C1 * z.abs(),
        C1 * x.abs(),
        C2 * (x * y).abs(),
        C2 * (y * z).abs(),
        C3 * (3.0 * z * z + 1.0),
        C2 * (x * z).abs(),
        C4 * (x * x + y * y),
    ]
}

/// `Σ |c_i| · scale_i`: the size of the terms of an SH evaluation.
fn eval_scale(c: impl IntoIterator<Item = f32>, s: &[f64]) -> f64 {
    c.into_iter().zip(s).map(|(c, s)| c.abs() as f64 * s).sum()
}

fn sum_abs(c: &[f32]) -> f64 {
    c.iter().map(|v| v.abs() as f64).sum()
}

/// Fibonacci sphere, for dense scans on the CPU.
fn dense_dirs(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.399_963_229_728_653 * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Smallest eigenvalue of the Hessian of `f` on the sphere at `v` (finite differences in f64
/// along two tangents): how sharply a minimum at `v` is defined.
fn smallest_curvature(c: &[f32; 9], v: DVec3) -> f64 {
    let (t1, t2) = v.any_orthonormal_pair();
    let h = 1e-3;
    let g = |a: f64, b: f64| eval_f64(c, v + a * t1 + b * t2);
    let f0 = g(0.0, 0.0);
    let gaa = (g(h, 0.0) - 2.0 * f0 + g(-h, 0.0)) / (h * h);
    let gbb = (g(0.0, h) - 2.0 * f0 + g(0.0, -h)) / (h * h);
    let gab = (g(h, h) - g(h, -h) - g(-h, h) + g(-h, -h)) / (4.0 * h * h);
    let (tr, det) = (gaa + gbb, gaa * gbb - gab * gab);
    0.5 * (tr - (tr * tr - 4.0 * det).max(0.0).sqrt())
}

fn eval_f64(c: &[f32; 9], d: DVec3) -> f64 {
    let y = basis::eval_l2_f64(d.normalize());
    (0..9).map(|i| c[i] as f64 * y[i]).sum()
}

// ---- SH ----

/// Basis, mono L1 / L2 and RGB L2 evaluation.
#[test]
fn sh_basis_and_evaluation_match_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0001);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for i in 0..512 {
        let mono = random_l2(&mut rng);
        let rgb = random_l2_rgb(&mut rng);
        // The axes exactly, where band-2 terms cancel or vanish, then random directions.
        let d = match i {
            0..6 => [
                Vec3::X,
                Vec3::NEG_X,
                Vec3::Y,
                Vec3::NEG_Y,
                Vec3::Z,
                Vec3::NEG_Z,
            ][i],
            _ => unit(&mut rng),
        };
        input.extend_from_slice(&mono.coeffs);
        push_rgb(&mut input, &rgb);
        input.extend_from_slice(&d.to_array());
        cases.push((mono, rgb, d));
    }
    let out = run(Kernel::ShEval, &input);

    // Basis: the CPU rounds the f64 basis to f32 (0.5 ulp), the GPU rounds constant and
    // each of up to three products (≤ 2 ulp): 6 ε of the terms.
    let mut basis_cmp = Compare::new("sh_basis_l1 / sh_basis_l2", 6.0 * EPS, 0.0);
    // Evaluation: both sides sum up to 9 rounded products of f32 inputs, ~12 roundings each
    // of at most the term scale: 48 ε ≈ 2.9e-6 of Σ|c_i Y_i|.
    let mut l1_cmp = Compare::new("sh_eval_l1", 48.0 * EPS, 0.0);
    let mut l2_cmp = Compare::new("sh_eval_l2", 48.0 * EPS, 0.0);
    let mut rgb_cmp = Compare::new("sh_eval_l2_rgb", 48.0 * EPS, 0.0);
    for (i, ((mono, rgb, d), r)) in cases.iter().zip(&out).enumerate() {
        let y = basis::eval_l2_f64(d.as_dvec3());
        let s = basis_scale(*d);
        for k in 0..4 {
            basis_cmp.check(i, r[k], y[k], s[k]);
        }
        for k in 0..9 {
            basis_cmp.check(i, r[4 + k], y[k], s[k]);
        }
        let l1 = ShL1::new([
            mono.coeffs[0],
            mono.coeffs[1],
            mono.coeffs[2],
            mono.coeffs[3],
        ]);
        l1_cmp.check(i, r[13], l1.eval(*d) as f64, eval_scale(l1.coeffs, &s));
        l2_cmp.check(i, r[14], mono.eval(*d) as f64, eval_scale(mono.coeffs, &s));
        let want = rgb.eval(*d);
        for c in 0..3 {
            rgb_cmp.check(
                i,
                r[15 + c],
                want[c] as f64,
                eval_scale(rgb.coeffs.map(|v| v[c]), &s),
            );
        }
    }
    report(&[basis_cmp, l1_cmp, l2_cmp, rgb_cmp]);
}

/// Irradiance from radiance SH (clamped-cosine convolution, then evaluation).
#[test]
fn sh_irradiance_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0002);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for _ in 0..512 {
        let l2 = random_l2(&mut rng);
        let l1 = ShL1::new([l2.coeffs[0], l2.coeffs[1], l2.coeffs[2], l2.coeffs[3]]);
        let rgb = random_l2_rgb(&mut rng);
        let n = unit(&mut rng);
        input.extend_from_slice(&l1.coeffs);
        push_rgb(&mut input, &rgb);
        input.extend_from_slice(&n.to_array());
        cases.push((l1, rgb, n));
    }
    let out = run(Kernel::ShIrradiance, &input);

    // As evaluation, with one more rounded product per term (the band factor) on each side:
    // 56 ε of Σ|Â_l c_i Y_i|.
    let mut l1_cmp = Compare::new("sh_irradiance_l1", 56.0 * EPS, 0.0);
    let mut rgb_cmp = Compare::new("sh_irradiance_l2_rgb", 56.0 * EPS, 0.0);
    let bands = zonal::CLAMPED_COSINE_BANDS.map(f64::from);
    for (i, ((l1, rgb, n), r)) in cases.iter().zip(&out).enumerate() {
        let s = basis_scale(*n);
        let sa: Vec<f64> = (0..9).map(|k| s[k] * bands[basis::band_of(k)]).collect();
        l1_cmp.check(
            i,
            r[0],
            zonal::irradiance_at(l1, *n) as f64,
            eval_scale(l1.coeffs, &sa),
        );
        let want = zonal::irradiance_at(rgb, *n);
        for c in 0..3 {
            rgb_cmp.check(
                i,
                r[1 + c],
                want[c] as f64,
                eval_scale(rgb.coeffs.map(|v| v[c]), &sa),
            );
        }
    }
    report(&[l1_cmp, rgb_cmp]);
}

/// Band scaling (mono and RGB), the Sloan 2017 window and the deringing window.
#[test]
fn sh_band_scaling_and_windows_match_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0003);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for i in 0..512 {
        let mono = random_l2(&mut rng);
        let rgb = random_l2_rgb(&mut rng);
        let f = Vec3::new(
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
        );
        // λ over six decades, and 0 and negatives (treated as 0).
        let lambda = match i % 8 {
            0 => 0.0,
            1 => -rng.random_range(0.0..1.0),
            _ => decades(&mut rng, -4.0, 2.0),
        };
        // Strength on the search grid (k/8, as the deringing search produces it), anywhere in
        // [0, 1), and outside [0, 1] (clamped).
        let t = match i % 4 {
            0 => (i / 4 % 9) as f32 / 8.0,
            1 => rng.random_range(-0.5..0.0),
            2 => rng.random_range(1.0..1.5),
            _ => rng.random_range(0.0..1.0),
        };
        input.extend_from_slice(&mono.coeffs);
        push_rgb(&mut input, &rgb);
        input.extend_from_slice(&f.to_array());
        input.push(lambda);
        input.push(t);
        cases.push((mono, rgb, f, lambda, t));
    }
    let out = run(Kernel::ShBands, &input);

    // One correctly rounded product on each side: equal up to 2 ulp (4 ε).
    let mut mono_cmp = Compare::new("sh_scale_bands_l2", 4.0 * EPS, 0.0);
    let mut rgb_cmp = Compare::new("sh_scale_bands_l2_rgb", 4.0 * EPS, 0.0);
    // 1 / (1 + λ e): one product and sum (1 ulp each side), Vulkan's division 2.5 ulp,
    // the CPU's 0.5 ulp: 12 ε of the factor.
    let mut sloan_cmp = Compare::new("sh_window_sloan2017", 12.0 * EPS, 0.0);
    // The same after λ = 0.3 t / (1 − t): one more division (2.5 ulp) and two roundings on
    // each side, the factor's relative sensitivity to λ being below 1: 24 ε.
    let mut window_cmp = Compare::new("sh_dering_window", 24.0 * EPS, 0.0);
    for (i, ((mono, rgb, f, lambda, t), r)) in cases.iter().zip(&out).enumerate() {
        let fa = f.to_array();
        let want = mono.scale_bands(fa);
        for k in 0..9 {
            mono_cmp.check(i, r[k], want.coeffs[k] as f64, want.coeffs[k] as f64);
        }
        let want = rgb.scale_bands(fa);
        for k in 0..9 {
            for c in 0..3 {
                rgb_cmp.check(
                    i,
                    r[9 + 3 * k + c],
                    want.coeffs[k][c] as f64,
                    want.coeffs[k][c] as f64,
                );
            }
        }
        let want = window::sloan2017(*lambda);
        for l in 0..3 {
            sloan_cmp.check(i, r[36 + l], want[l] as f64, want[l] as f64);
        }
        let want = dering_window(*t);
        for l in 0..3 {
            window_cmp.check(i, r[39 + l], want[l] as f64, want[l] as f64);
        }
    }
    report(&[mono_cmp, rgb_cmp, sloan_cmp, window_cmp]);
}

/// Projection of a delta direction.
#[test]
fn sh_delta_projection_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0004);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for _ in 0..512 {
        let d = unit(&mut rng);
        let w = decades(&mut rng, -3.0, 3.0) * if rng.random_bool(0.2) { -1.0 } else { 1.0 };
        input.extend_from_slice(&d.to_array());
        input.push(w);
        cases.push((d, w));
    }
    let out = run(Kernel::ShDelta, &input);

    // The basis as in the evaluation test (6 ε) and one more product on each side: 8 ε.
    let mut cmp = Compare::new("sh_delta_l2", 8.0 * EPS, 0.0);
    for (i, ((d, w), r)) in cases.iter().zip(&out).enumerate() {
        let want = ShL2::delta(*d, *w);
        let s = basis_scale(*d);
        for k in 0..9 {
            cmp.check(i, r[k], want.coeffs[k] as f64, *w as f64 * s[k]);
        }
    }
    report(&[cmp]);
}

/// Scalar L2 functions whose minimum search is not trivial: random ones, ringing lobes (a
/// delta or a narrow light plus ambient) and band-1-free ones (no linear start direction).
fn minimum_cases(rng: &mut SmallRng, n: usize) -> Vec<ShL2> {
    (0..n)
        .map(|i| match i % 4 {
            0 | 1 => random_l2(rng),
            2 => {
                let w = decades(rng, -1.0, 1.0);
                let mut f = ShL2::delta(unit(rng), w);
                f.coeffs[0] += rng.random_range(0.0..0.3) * w;
                f
            }
            _ => {
                let mut f = random_l2(rng);
                f.coeffs[1..4].fill(0.0);
                f
            }
        })
        .collect()
}

/// Newton minimum search: the twin's minimum must be a true value of the function at its
/// direction, and as low as the CPU's.
#[test]
fn sh_find_minimum_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0005);
    let cases = minimum_cases(&mut rng, 512);
    let input: Vec<f32> = cases.iter().flat_map(|f| f.coeffs).collect();
    let out = run(Kernel::ShFindMin, &input);

    // A normalised f32 vector: within a few ε of unit length.
    let mut unit_cmp = Compare::new("sh_find_min_l2 direction length", 0.0, 8.0 * EPS);
    // The value the twin reports is its f32 evaluation at its direction: as the evaluation
    // test, 48 ε of the term scale Σ|c_i| · max|Y_i| (≤ 1.1 Σ|c_i|).
    let mut value_cmp = Compare::new("sh_find_min_l2 value at its direction", 48.0 * EPS, 0.0);
    // Against the CPU's search (the same steps in f64): the two agree to rounding except where
    // two candidates tie to rounding and the final refinement starts from different ones;
    // near a minimum the function is flat, so that costs ~ (step error)² and stays far below
    // the search's own accuracy (~1e-4 of Σ|c_i|, hikari-math docs). 1e-5 of Σ|c_i| is 10x
    // tighter than that accuracy and ~100x above rounding.
    let mut cpu_cmp = Compare::new("sh_find_min_l2 value vs CPU", 1e-5, 0.0);
    // Directions: as close as the minimum's curvature makes them. Where the two values agree
    // to Δf = 1e-5 of the term scale, the directions may differ by up to √(2 Δf / h), h the
    // smallest curvature of f on the sphere at the CPU's minimum (a projected delta is zonal:
    // its minimum is a whole ring, h = 0, and any direction on it is right). A function
    // without band 1 is even (f(−ω) = f(ω)): its minimum is reached at opposite directions too.
    let mut dir_cmp = Compare::new("sh_find_min_l2 direction vs CPU", 1.0, 1e-4);
    let (mut isolated, mut total) = (0, 0);
    for (i, (f, r)) in cases.iter().zip(&out).enumerate() {
        let scale = 1.1 * sum_abs(&f.coeffs);
        let dir = DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64);
        unit_cmp.check(i, dir.length() as f32, 1.0, 0.0);
        value_cmp.check(i, r[3], eval_f64(&f.coeffs, dir), scale);
        let (cpu_dir, cpu_value) = find_minimum(f);
        cpu_cmp.check(i, r[3], cpu_value as f64, scale);
        let cpu_dir = cpu_dir.as_dvec3();
        let even = f.coeffs[1..4].iter().all(|&c| c == 0.0);
        let apart = if even {
            (dir - cpu_dir).length().min((dir + cpu_dir).length())
        } else {
            (dir - cpu_dir).length()
        };
        let h = smallest_curvature(&f.coeffs, cpu_dir);
        let spread = if h > 0.0 {
            (2.0 * cpu_cmp.rel * scale / h).sqrt()
        } else {
            f64::INFINITY
        };
        total += 1;
        if spread < 0.05 {
            isolated += 1;
        }
        dir_cmp.check(i, apart as f32, 0.0, spread.min(2.0));
    }
    // Most minima are isolated, so the direction comparison is not vacuous.
    eprintln!("find_min: {isolated} of {total} minima isolated (direction spread < 0.05)");
    assert!(
        isolated * 2 >= total,
        "only {isolated} of {total} minima are isolated"
    );
    report(&[unit_cmp, value_cmp, cpu_cmp, dir_cmp]);
}

/// RGB L2 inputs for deringing: random ones, ringing lobes with colour, smooth lobes that need
/// no windowing, and a few with a negative mean in one channel (zeroed).
fn dering_cases(rng: &mut SmallRng, n: usize) -> Vec<ShL2Rgb> {
    (0..n)
        .map(|i| match i % 8 {
            0..3 => {
                let amp = rng.random_range(0.05..1.2);
                let mut c: [Vec3; 9] = std::array::from_fn(|_| {
                    Vec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    ) * amp
                });
                c[0] = Vec3::new(
                    rng.random_range(0.2..2.0),
                    rng.random_range(0.2..2.0),
                    rng.random_range(0.2..2.0),
                );
                ShL2Rgb::new(c).scale(decades(rng, -2.0, 2.0))
            }
            3..5 => {
                // A projected delta light (the strongest ringing), tinted, on a weak ambient.
                let colour = Vec3::new(
                    rng.random_range(0.1..1.0),
                    rng.random_range(0.1..1.0),
                    rng.random_range(0.1..1.0),
                );
                let mut f = ShL2Rgb::delta(unit(rng), colour * decades(rng, -1.0, 2.0));
                let ambient = rng.random_range(0.0..0.5) * f.coeffs[0];
                f.coeffs[0] += ambient;
                f
            }
            5 | 6 => {
                // 1 + b max(0, n·ω): the SH of a clamped cosine is Â_l Y_lm(n), positive
                // enough that no windowing should be needed.
                let b = rng.random_range(0.2..0.9);
                let mut f = zonal::irradiance(&ShL2Rgb::delta(unit(rng), Vec3::splat(b)));
                f.coeffs[0] += Vec3::splat((1.0 / C0) as f32);
                f.scale(decades(rng, -2.0, 2.0))
            }
            _ => {
                let mut f = random_l2_rgb(rng);
                f.coeffs[0] = Vec3::new(rng.random_range(-1.0..-0.01), 0.5, 0.5)
                    * f.coeffs[0].abs().max_element();
                f
            }
        })
        .collect()
}

/// Deringing: the window strength of the depth-3 search and the deringed coefficients match
/// the CPU, and the GPU's result is non-negative on many directions.
#[test]
fn sh_dering_matches_the_cpu_and_is_non_negative() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0006);
    let cases = dering_cases(&mut rng, 384);
    let mut input = Vec::new();
    for f in &cases {
        push_rgb(&mut input, f);
    }
    let out = run(Kernel::ShDering, &input);

    // Strength is a grid value (k/8): equal, unless the CPU's estimated minimum at every grid
    // strength between the two is within the find-minimum agreement (1e-5 of the term scale,
    // see `sh_find_minimum_matches_the_cpu`) of zero, a tie that rounding may break either way.
    let tie = 1e-5;
    let mut strength_cmp = Compare::new("sh_dering_strength_rgb", 0.0, 0.0);
    // Coefficients = input · window(strength), compared at the GPU's strength: the window's
    // 24 ε (see the windows test) and one product: 28 ε of the coefficient.
    let mut coeff_cmp = Compare::new("sh_dering_l2_rgb coefficients", 28.0 * EPS, 0.0);
    // The GPU's own minimum search accepted the result: its estimated minimum of each channel
    // is ≥ 0 up to the rounding of recomputing it (48 ε of the term scale).
    let mut self_min = Compare::new("deringed minimum, GPU search", 48.0 * EPS, 0.0);
    // The true minimum, scanned densely (512 directions on the GPU with sh_eval_l2_rgb,
    // 4000 on the CPU in f64): the search estimates the minimum to ~1e-4 of the term scale and
    // a projected delta's minimum sits in a sharp trough, so a scan may find a value below the
    // estimate by that much; 1e-3 of the channel's term scale leaves room for it, while a
    // projected delta left ringing goes below zero by a few percent of it (~50x the bound).
    let mut scan_gpu = Compare::new("deringed minimum, GPU scan", 1e-3, 0.0);
    let mut scan_cpu = Compare::new("deringed minimum, CPU scan of GPU coefficients", 1e-3, 0.0);
    let dirs = dense_dirs(4000);
    let grid: Vec<f32> = (0..8).map(|k| k as f32 / 8.0).collect();
    let (mut ties, mut deringed, mut untouched) = (0, 0, 0);
    for (i, (f, r)) in cases.iter().zip(&out).enumerate() {
        let cpu = dering(f);
        let gpu_strength = r[0];
        let term_scale = |sh: &ShL2Rgb, c: usize| 1.1 * sum_abs(&sh.coeffs.map(|v| v[c]));
        let scale = (0..3).map(|c| term_scale(f, c)).fold(0.0, f64::max);
        if gpu_strength != cpu.strength {
            let (lo, hi) = (
                gpu_strength.min(cpu.strength),
                gpu_strength.max(cpu.strength),
            );
            // Every grid strength whose verdict differs must be a near-zero minimum.
            let near_zero = grid.iter().filter(|&&t| t >= lo && t < hi).all(|&t| {
                let w = f.scale_bands(dering_window(t));
                let lowest = (0..3)
                    .map(|c| find_minimum(&w.channel(c)).1)
                    .fold(f32::INFINITY, f32::min);
                (lowest as f64).abs() <= tie * scale
            });
            strength_cmp.require(i, near_zero, || {
                format!(
                    "gpu strength {gpu_strength}, cpu {}, and not a tie",
                    cpu.strength
                )
            });
            ties += 1;
        } else {
            strength_cmp.require(i, true, String::new);
        }
        if cpu.strength > 0.0 {
            deringed += 1;
        } else {
            untouched += 1;
        }
        let gpu = read_rgb(&r[1..28]);
        // At the CPU's strength this is `dering(f).sh` itself; at a tie, the same windowing
        // at the GPU's strength.
        let want = if gpu_strength == cpu.strength {
            cpu.sh
        } else {
            f.scale_bands(dering_window(gpu_strength))
        };
        for k in 0..9 {
            for c in 0..3 {
                coeff_cmp.check(
                    i,
                    gpu.coeffs[k][c],
                    want.coeffs[k][c] as f64,
                    want.coeffs[k][c] as f64,
                );
            }
        }
        for c in 0..3 {
            // Only negative values are errors: min(·, 0) compared with 0.
            let s = term_scale(&gpu, c);
            self_min.check(i, r[28 + c].min(0.0), 0.0, s);
            scan_gpu.check(i, r[31 + c].min(0.0), 0.0, s);
            let coeffs = gpu.coeffs.map(|v| v[c]);
            let lowest = dirs
                .iter()
                .map(|&d| eval_f64(&coeffs, d))
                .fold(f64::INFINITY, f64::min);
            scan_cpu.check(i, lowest.min(0.0) as f32, 0.0, s);
        }
    }
    eprintln!(
        "dering: {deringed} inputs windowed, {untouched} left alone, {ties} strength mismatches"
    );
    report(&[strength_cmp, coeff_cmp, self_min, scan_gpu, scan_cpu]);
    // The inputs exercise both outcomes, and ties stay rare: a twin whose search differs
    // (a wrong λ scale, a different start set) disagrees on many inputs, not on a few ties.
    assert!(
        deringed >= cases.len() / 4 && untouched >= cases.len() / 4,
        "{deringed} / {untouched}"
    );
    assert!(
        ties * 50 <= cases.len(),
        "{ties} strength mismatches in {} cases",
        cases.len()
    );
}

/// Linear-maximum direction and directionality boost.
#[test]
fn sh_directionality_boost_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0007);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for i in 0..512 {
        let mut f = random_l2_rgb(&mut rng);
        f.coeffs[0] = f.coeffs[0].abs();
        if i % 32 == 0 {
            // No band 1: no direction, unchanged.
            f.coeffs[1..4].fill(Vec3::ZERO);
        }
        // The talk's 25 %, and any amount.
        let amount = if i % 2 == 0 {
            0.25
        } else {
            rng.random_range(0.0..1.0)
        };
        push_rgb(&mut input, &f);
        input.push(amount);
        cases.push((f, amount));
    }
    let out = run(Kernel::ShBoost, &input);

    const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];
    // The direction normalises v = luminance of (c3, c1, c2): 3-term dot products and a
    // normalisation on each side, ~10 roundings of Σ|terms| relative to |v|: 20 ε · cond.
    let mut dir_cmp = Compare::new("sh_linear_max_dir_rgb", 20.0 * EPS, 0.0);
    // mix(c, w Y(d), a): the basis (6 ε), w = c0 / C0 (division 2.5 ulp), the mix (3 roundings)
    // on each side: 24 ε of |c| + a |w Y|, plus the direction's error times the basis
    // gradient (|∇Y| ≤ 2 C2) times a |w|.
    let mut boost_cmp = Compare::new("sh_directionality_boost_rgb", 24.0 * EPS, 0.0);
    for (i, ((f, amount), r)) in cases.iter().zip(&out).enumerate() {
        let lin = [f.coeffs[3], f.coeffs[1], f.coeffs[2]];
        let v: Vec<f64> = lin
            .iter()
            .map(|c| (0..3).map(|k| c[k] as f64 * LUMA[k]).sum())
            .collect();
        let terms: f64 = lin
            .iter()
            .map(|c| (0..3).map(|k| (c[k] as f64 * LUMA[k]).abs()).sum::<f64>())
            .sum();
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let cond = if len > 0.0 { terms / len } else { 0.0 };
        let want_dir = linear_max_direction(f).unwrap_or(Vec3::ZERO);
        for k in 0..3 {
            dir_cmp.check(i, r[k], want_dir[k] as f64, cond.max(1.0));
        }
        let dir_err = 20.0 * EPS * cond.max(1.0);
        let want = directionality_boost(f, *amount);
        let d = Vec3::new(r[0], r[1], r[2]);
        let y = basis_scale(if d == Vec3::ZERO { Vec3::Z } else { d });
        for k in 0..9 {
            for c in 0..3 {
                let w = (f.coeffs[0][c] as f64 / C0).abs();
                let scale = f.coeffs[k][c].abs() as f64 + *amount as f64 * w * y[k];
                let from_dir = *amount as f64 * w * 2.0 * C2 * dir_err;
                let allowed = boost_cmp.rel * scale + from_dir;
                boost_cmp.check_allowed(i, r[3 + 3 * k + c], want.coeffs[k][c] as f64, allowed);
            }
        }
    }
    report(&[dir_cmp, boost_cmp]);
}

// ---- Metro Exodus YCoCg + L1 ----

/// RGB <-> YCoCg, encoding, and the decoders of the Metro encoding.
#[test]
fn ycocg_encoding_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0008);
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for i in 0..512 {
        // HDR colours over six decades, some with negative (out-of-gamut) channels.
        let mut color = Vec3::new(
            rng.random_range(0.0..1.0),
            rng.random_range(0.0..1.0),
            rng.random_range(0.0..1.0),
        ) * decades(&mut rng, -3.0, 3.0);
        if i % 8 == 0 {
            color.x -= color.max_element() * 0.7;
        }
        let dir = unit(&mut rng);
        // A pixel's encoding as the renderer makes it: the mean of a few samples from the
        // hemisphere around the normal, with colour.
        let n = unit(&mut rng);
        let samples = 1 + i % 12;
        let mut acc = ShL1YCoCg::default();
        for _ in 0..samples {
            let mut d = unit(&mut rng);
            if d.dot(n) < 0.0 {
                d -= 2.0 * d.dot(n) * n;
            }
            let c = Vec3::new(
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
            ) * decades(&mut rng, -2.0, 2.0);
            acc = acc.add(&ShL1YCoCg::encode(c, d));
        }
        let mut enc = acc.scale(1.0 / samples as f32);
        if i % 64 == 1 {
            // Nothing hit: all zero.
            enc = ShL1YCoCg::default();
        }
        let alpha = rng.random_range(0.0..1.0f32).powi(2);
        input.extend_from_slice(&color.to_array());
        input.extend_from_slice(&dir.to_array());
        input.extend_from_slice(&enc.y.coeffs);
        input.extend_from_slice(&enc.co_cg.to_array());
        input.extend_from_slice(&n.to_array());
        input.push(alpha);
        cases.push((color, dir, enc, n, alpha));
    }
    let out = run(Kernel::YCoCg, &input);

    // The lifting steps are exact-but-for-rounding adds and halvings, done in the same order:
    // up to 4 roundings per side of Σ|rgb|: 8 ε.
    let mut to_ycocg = Compare::new("sh_rgb_to_ycocg", 8.0 * EPS, 0.0);
    let mut to_rgb = Compare::new("sh_ycocg_to_rgb", 8.0 * EPS, 0.0);
    // Basis (6 ε) times Y, clamped: 8 ε of |Y Y_i|; chroma as the lifting.
    let mut encode = Compare::new("shy_encode", 8.0 * EPS, 0.0);
    // Y = c0 / C0 (division 2.5 ulp on the GPU), then the lifting: 16 ε of |Y| + |Co| + |Cg|.
    let mut to_color = Compare::new("shy_to_color", 16.0 * EPS, 0.0);
    // Y = 2 (a1 (c · n) + a0 c0): ~8 roundings per side; chroma scaled by C0 Y / (c0 + 1e-6)
    // (division 2.5 ulp, 3 products), then the lifting: 48 ε of the terms
    // |Y| + |Co'| + |Cg'| where Y's own terms are 2 (a1 Σ|c_k n_k| + a0 |c0|).
    let mut resolve = Compare::new("shy_resolve_diffuse", 48.0 * EPS, 0.0);
    // Normalising (x, y, z): a length and a division each side: 12 ε · |c|₁ / |c|.
    let mut dominant = Compare::new("shy_dominant_direction", 12.0 * EPS, 0.0);
    // |L1| C0 / (C1 c0): length, product, division (2.5 ulp): 16 ε of R.
    let mut directionality = Compare::new("shy_directionality", 16.0 * EPS, 0.0);
    // α from R through κ(R) = R (3 − R²) / (1 − R²): R's tolerance propagated by the exact
    // derivative (evaluated in f64), plus ~10 roundings of α (sqrt, two divisions): 20 ε.
    let mut spec = Compare::new("shy_specular_alpha", 20.0 * EPS, 0.0);
    let a1 = 2.0 * std::f64::consts::PI / 3.0 * C1;
    let a0 = std::f64::consts::PI * C0;
    for (i, ((color, dir, enc, n, alpha), r)) in cases.iter().zip(&out).enumerate() {
        let s = sum_abs(&color.to_array());
        let want = rgb_to_ycocg(*color);
        for k in 0..3 {
            to_ycocg.check(i, r[k], want[k] as f64, s);
        }
        let want = ycocg_to_rgb(*color);
        for k in 0..3 {
            to_rgb.check(i, r[3 + k], want[k] as f64, s);
        }
        let want = ShL1YCoCg::encode(*color, *dir);
        let yb = basis_scale(*dir);
        let y = want.y.coeffs[0] as f64 / C0;
        for k in 0..4 {
            encode.check(i, r[6 + k], want.y.coeffs[k] as f64, y * yb[k]);
        }
        encode.check(i, r[10], want.co_cg.x as f64, s);
        encode.check(i, r[11], want.co_cg.y as f64, s);

        let c = &enc.y.coeffs;
        let terms = c[0].abs() as f64 / C0 + enc.co_cg.x.abs() as f64 + enc.co_cg.y.abs() as f64;
        let want = enc.to_color();
        for k in 0..3 {
            to_color.check(i, r[12 + k], want[k] as f64, terms);
        }
        let dot_terms =
            (c[3] * n.x).abs() as f64 + (c[1] * n.y).abs() as f64 + (c[2] * n.z).abs() as f64;
        let y_terms = 2.0 * (a1 * dot_terms + a0 * c[0].abs() as f64);
        let ratio = C0 * y_terms / (c[0] as f64 + 1e-6).abs();
        let terms = y_terms + ratio * (enc.co_cg.x.abs() + enc.co_cg.y.abs()) as f64;
        let want = enc.resolve_diffuse(*n);
        for k in 0..3 {
            resolve.check(i, r[15 + k], want[k] as f64, terms);
        }
        let l1 = Vec3::new(c[3], c[1], c[2]);
        let cond = if l1.length() > 0.0 {
            sum_abs(&l1.to_array()) / l1.length() as f64
        } else {
            0.0
        };
        let want = enc.dominant_direction().unwrap_or(Vec3::ZERO);
        for k in 0..3 {
            dominant.check(i, r[18 + k], want[k] as f64, cond);
        }
        let rr = enc.directionality() as f64;
        directionality.check(i, r[21], rr, rr);
        let alpha64 = |r: f64| {
            let r = r.clamp(0.0, 0.999_999);
            let kappa = r * (3.0 - r * r) / (1.0 - r * r);
            ((*alpha as f64).powi(2) + 2.0 / (kappa + 2.0))
                .sqrt()
                .min(1.0)
        };
        let dr = directionality.rel * rr;
        let propagated = (alpha64(rr + dr) - alpha64(rr - dr)).abs() / 2.0;
        let want = enc.specular_alpha(*alpha) as f64;
        spec.check_allowed(i, r[22], want, spec.rel * want + propagated);
    }
    report(&[
        to_ycocg,
        to_rgb,
        encode,
        to_color,
        resolve,
        dominant,
        directionality,
        spec,
    ]);
}

// ---- Colour ----

/// sRGB encode / decode (scalar and vec3) and Rec.709 luminance.
#[test]
fn srgb_transfer_and_luminance_match_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_0009);
    let mut input = Vec::new();
    let n = 768;
    for i in 0..n {
        // Linear values over [0, 1] and beyond (odd extension), dense around the linear
        // segment's end (0.0031308 linear, 0.04045 encoded) where a wrong threshold shows.
        let (x, e) = match i % 4 {
            0 => (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)),
            1 => (
                rng.random_range(0.0025..0.0037),
                rng.random_range(0.035..0.046),
            ),
            2 => (decades(&mut rng, -5.0, 0.0), decades(&mut rng, -4.0, 0.0)),
            _ => (rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)),
        };
        let c = Vec3::new(
            rng.random_range(-0.2..1.2),
            rng.random_range(-0.2..1.2),
            rng.random_range(-0.2..1.2),
        );
        input.push(x);
        input.push(e);
        input.extend_from_slice(&c.to_array());
    }
    input[0] = 0.0;
    input[1] = 0.0;
    let out = run(Kernel::Transfer, &input);

    // pow(a, 1/2.4) = exp2(log2(a) / 2.4) in Vulkan: exp2 within 3 + 2|arg| ulp (≤ 12 ulp
    // here), log2 within 3 ulp, which the 1/2.4 scales down: ≤ 2.4e-6 of 1.055 a^(1/2.4),
    // the term that carries the error (the result, after − 0.055, can be 2.4x smaller). The
    // CPU is f64. 48 ε ≈ 2.9e-6 of the pow term.
    let mut enc_cmp = Compare::new("srgb_encode / srgb_encode3", 48.0 * EPS, 0.0);
    // pow(b, 2.4): exp2 of up to |2.4 log2 b| ≤ 8.3 (≤ 20 ulp) plus log2's 3 ulp scaled by 2.4
    // and the division (a + 0.055) / 1.055 (2.5 ulp) scaled by 2.4: ≤ 4.2e-6: 80 ε ≈ 4.8e-6.
    let mut dec_cmp = Compare::new("srgb_decode / srgb_decode3", 80.0 * EPS, 0.0);
    // Dot with the Y row of REC709_TO_XYZ: f32 weights (0.5 ulp) and 3 products and sums:
    // 8 ε of Σ|w_i c_i|.
    let mut lum_cmp = Compare::new("luminance_rec709", 8.0 * EPS, 0.0);
    let y_row = REC709.rgb_to_xyz()[1];
    let enc_scale = |x: f64| {
        if x.abs() <= 0.003_130_8 {
            x.abs() * 12.92
        } else {
            1.055 * x.abs().powf(1.0 / 2.4)
        }
    };
    let dec_scale = |e: f64| {
        if e.abs() <= 0.040_45 {
            e.abs() / 12.92
        } else {
            transfer::srgb_decode(e).abs()
        }
    };
    for (i, (x, r)) in input.chunks(5).zip(&out).enumerate() {
        let (lin, e) = (x[0] as f64, x[1] as f64);
        enc_cmp.check(i, r[0], transfer::srgb_encode(lin), enc_scale(lin));
        dec_cmp.check(i, r[1], transfer::srgb_decode(e), dec_scale(e));
        for k in 0..3 {
            let c = x[2 + k] as f64;
            enc_cmp.check(i, r[2 + k], transfer::srgb_encode(c), enc_scale(c));
            dec_cmp.check(i, r[5 + k], transfer::srgb_decode(c), dec_scale(c));
        }
        let c = [x[2] as f64, x[3] as f64, x[4] as f64];
        let want: f64 = (0..3).map(|k| y_row[k] * c[k]).sum();
        let terms: f64 = (0..3).map(|k| (y_row[k] * c[k]).abs()).sum();
        lum_cmp.check(i, r[8], want, terms);
    }
    report(&[enc_cmp, dec_cmp, lum_cmp]);
}

/// The generated colour matrices, applied to vectors, against the exact f64 derivations.
#[test]
fn colour_matrices_applied_to_vectors_match_the_derivations() {
    let mut rng = SmallRng::seed_from_u64(0x5E_000A);
    let mut input = Vec::new();
    for i in 0..512 {
        let v = if i < 3 {
            // The unit vectors read out one column each.
            Vec3::AXES[i]
        } else {
            Vec3::new(
                rng.random_range(-1.0..2.0),
                rng.random_range(-1.0..2.0),
                rng.random_range(-1.0..2.0),
            ) * decades(&mut rng, -3.0, 3.0)
        };
        input.extend_from_slice(&v.to_array());
    }
    let out = run(Kernel::Matrices, &input);

    let p = PurkinjeMatrices::new();
    let named: [(&'static str, Mat3Rows); 8] = [
        ("REC709_TO_XYZ", REC709.rgb_to_xyz()),
        ("XYZ_TO_REC709", REC709.xyz_to_rgb()),
        ("REC709_TO_ACESCG", rgb_to_rgb(&REC709, &ACESCG)),
        ("ACESCG_TO_REC709", rgb_to_rgb(&ACESCG, &REC709)),
        ("REC709_TO_TONEMAP", rgb_to_rgb(&REC709, &TONEMAP)),
        ("TONEMAP_TO_REC709", rgb_to_rgb(&TONEMAP, &REC709)),
        ("REC709_TO_LMS_RAYLEIGH", rgb_to_rgb(&REC709, &LMS_RAYLEIGH)),
        ("LMS_RAYLEIGH_TO_REC709", rgb_to_rgb(&LMS_RAYLEIGH, &REC709)),
    ];
    // Each entry rounded to f32 (0.5 ulp), 3 products and 2 sums (≤ 5 roundings): 8 ε of
    // Σ_j |m_ij v_j|, against the exact f64 product.
    let mut cmps: Vec<Compare> = named
        .iter()
        .map(|(n, _)| Compare::new(n, 8.0 * EPS, 0.0))
        .collect();
    let mut lmsr_cmp = Compare::new("PURKINJE_LMSR_FROM_REC709", 8.0 * EPS, 0.0);
    let mut gain_cmp = Compare::new("PURKINJE_RGB_FROM_LMS_GAIN", 8.0 * EPS, 0.0);
    let row_check = |cmp: &mut Compare, i: usize, got: f32, row: &[f64; 3], v: [f64; 3]| {
        let want: f64 = (0..3).map(|j| row[j] * v[j]).sum();
        let terms: f64 = (0..3).map(|j| (row[j] * v[j]).abs()).sum();
        cmp.check(i, got, want, terms);
    };
    for (i, (v, r)) in input.chunks(3).zip(&out).enumerate() {
        let v = [v[0] as f64, v[1] as f64, v[2] as f64];
        for (m, ((_, mat), cmp)) in named.iter().zip(cmps.iter_mut()).enumerate() {
            let want = mul3v(mat, v);
            for row in 0..3 {
                row_check(cmp, i, r[3 * m + row], &mat[row], v);
                debug_assert!(
                    (want[row] - (0..3).map(|j| mat[row][j] * v[j]).sum::<f64>()).abs() < 1e-9
                );
            }
        }
        for row in 0..4 {
            row_check(&mut lmsr_cmp, i, r[24 + row], &p.lmsr_from_rgb[row], v);
        }
        for row in 0..3 {
            row_check(&mut gain_cmp, i, r[28 + row], &p.rgb_from_lms_gain[row], v);
        }
    }
    cmps.push(lmsr_cmp);
    cmps.push(gain_cmp);
    report(&cmps);
}

/// The Purkinje shift with the generated matrices, against hikari-math's folded computation
/// (`PurkinjeMatrices::apply`) and its step-by-step version of the talk
/// (`purkinje_reference`), both in f64.
#[test]
fn purkinje_shift_matches_the_cpu() {
    let mut rng = SmallRng::seed_from_u64(0x5E_000B);
    let mut input = Vec::new();
    for i in 0..512 {
        // Scene colours from starlight to daylight (luminance ~1e-5 to 1e3), where the shift
        // goes from dominant to negligible; a few greys and saturated primaries.
        let c = match i % 16 {
            0 => Vec3::ONE,
            1 => Vec3::AXES[i / 16 % 3],
            _ => Vec3::new(
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
            ),
        } * decades(&mut rng, -5.0, 3.0);
        input.extend_from_slice(&c.to_array());
    }
    let out = run(Kernel::Purkinje, &input);

    let p = PurkinjeMatrices::new();
    // rgb + (G g) w with g = inverseSqrt(1 + max(l, 0)): f32 matrices (0.5 ulp), two 3-term
    // dot products for l and w, inverseSqrt (2 ulp, halved in effect since g's sensitivity
    // to its argument is 1/2), G g (3 roundings) and the final product and sum: ~16 roundings
    // of the terms |rgb_r| + Σ_k |G_rk g_k w|: 32 ε.
    let mut apply_cmp = Compare::new("purkinje_shift vs PurkinjeMatrices::apply", 32.0 * EPS, 0.0);
    let mut ref_cmp = Compare::new("purkinje_shift vs purkinje_reference", 32.0 * EPS, 0.0);
    for (i, (c, r)) in input.chunks(3).zip(&out).enumerate() {
        let c = [c[0] as f64, c[1] as f64, c[2] as f64];
        let l: Vec<f64> = (0..4)
            .map(|k| (0..3).map(|j| p.lmsr_from_rgb[k][j] * c[j]).sum())
            .collect();
        let g: Vec<f64> = (0..3).map(|k| (1.0 + l[k].max(0.0)).powf(-0.5)).collect();
        let want = p.apply(c);
        let reference = purkinje_reference(c);
        for row in 0..3 {
            let terms = c[row].abs()
                + (0..3)
                    .map(|k| (p.rgb_from_lms_gain[row][k] * g[k] * l[3]).abs())
                    .sum::<f64>();
            apply_cmp.check(i, r[row], want[row], terms);
            ref_cmp.check(i, r[row], reference[row], terms);
        }
    }
    report(&[apply_cmp, ref_cmp]);
}

/// The checks above can fail: a twin evaluated with one wrong constant is caught by the same
/// tolerance (a self-test of the harness, on the CPU: the GPU path is what the tests above
/// compare).
#[test]
fn tolerances_catch_a_wrong_constant() {
    let mut rng = SmallRng::seed_from_u64(0x5E_000C);
    let mut cmp = Compare::new("sh_eval_l2 with C3 off in the 5th digit", 48.0 * EPS, 0.0);
    for i in 0..256 {
        let f = random_l2(&mut rng);
        let d = unit(&mut rng);
        let mut y = basis::eval_l2_f64(d.as_dvec3());
        y[6] *= 1.0 + 1e-4;
        let wrong: f64 = (0..9).map(|k| f.coeffs[k] as f64 * y[k]).sum();
        cmp.check(
            i,
            wrong as f32,
            f.eval(d) as f64,
            eval_scale(f.coeffs, &basis_scale(d)),
        );
    }
    assert!(
        cmp.failed > 0,
        "a 1e-4 error in one basis constant went unnoticed"
    );
}

// ---- BRDF ----

/// A random shading case for the BRDF kernel: material (with a specular weight of 1, 0 or in
/// between), frame and directions, with `n·v` and
/// `n·l` either clearly above the surface (≥ 0.02, so f32 and f64 agree on the side) or, in one
/// case of eight, clearly below (≤ −0.02, where both must give exactly 0).
fn brdf_case(rng: &mut SmallRng) -> ([f32; 7], [Vec3; 5]) {
    let r = match rng.random_range(0..4) {
        0 => rng.random_range(0.0..0.1),
        _ => rng.random_range(0.0..1.0),
    };
    let a = match rng.random_range(0..3) {
        0 => 0.0,
        _ => rng.random_range(-1.0..1.0),
    };
    let metal = match rng.random_range(0..3) {
        0 => 0.0,
        1 => 1.0,
        _ => rng.random_range(0.0..1.0),
    };
    let mat = [
        rng.random_range(0.0..1.0),
        rng.random_range(0.0..1.0),
        rng.random_range(0.0..1.0),
        r,
        metal,
        a,
        match rng.random_range(0..3) {
            0 => 1.0,
            1 => 0.0,
            _ => rng.random_range(0.0..1.0),
        },
    ];
    let n = unit(rng);
    let t = unit(rng);
    let t = (t - n * n.dot(t)).normalize();
    let b = n.cross(t);
    let side = |rng: &mut SmallRng, below: bool| loop {
        let d = unit(rng);
        let c = d.dot(n);
        if (below && c <= -0.02) || (!below && c >= 0.02) {
            return d;
        }
    };
    let below = rng.random_range(0..8) == 0;
    let v_below = below && rng.random_range(0..2) == 0;
    let v = side(rng, v_below);
    let l = side(rng, below);
    (mat, [n, t, b, v, l])
}

/// `hikari::brdf` against hikari-math's BRDF (f64 inside, on the same f32 inputs): the full
/// anisotropic and isotropic evaluations, the per-light weights the deferred pass sums, and the
/// albedo tables' lookups. Tolerances: the specular lobe's `D` divides by `|s|⁴` with
/// `s = (h_x/α_x, h_y/α_y, h_z)`; f32 `h` (error ~6e-8 absolute) over `α` ≥ 0.002 puts up to
/// ~1e-4 relative into `D` near the peak, and `normalize`, `length`, `sqrt` and the Vulkan
/// division (2.5 ulp) a few ε more: 4e-4 relative, plus 1e-6 absolute (sr⁻¹) for the table
/// terms (f32 tables, rounding 6e-8, bilinear weights in f32). The isotropic form computes `D`
/// from `n·h` alone, whose cancellation (`1 − (n·h)²` against `α² (n·h)²`) costs up to a few
/// per cent at the peak of the smoothest lobes (hikari_math::brdf::material), so it is held to
/// 4e-4 only for roughness ≥ 0.2 and to 5 % below. Lookups: 1e-6 absolute.
#[test]
fn brdf_matches_the_cpu() {
    use hikari_math::brdf::albedo::{albedo_tables, isotropic_equivalent_roughness};
    use hikari_math::brdf::energy::Compensation;
    use hikari_math::brdf::fresnel::schlick_weight;
    use hikari_math::brdf::ggx::ggx_ndf_aniso;
    use hikari_math::brdf::smith::visibility_aniso;
    use hikari_math::brdf::{Material, evaluate, evaluate_isotropic};

    let mut rng = SmallRng::seed_from_u64(0xB4DF_0015);
    let n_cases = 1024;
    let mut input = Vec::new();
    let mut cases = Vec::new();
    for _ in 0..n_cases {
        let (mat, dirs) = brdf_case(&mut rng);
        input.extend_from_slice(&mat[..6]);
        for d in dirs {
            input.extend_from_slice(&d.to_array());
        }
        input.push(mat[6]);
        cases.push((mat, dirs));
    }
    let out = run(Kernel::Brdf, &input);
    let mut eval_cmp = Compare::new("brdf_evaluate", 4e-4, 1e-6);
    let mut iso_cmp = Compare::new("brdf_evaluate_isotropic", 4e-4, 1e-6);
    let mut iso_smooth_cmp = Compare::new("brdf_evaluate_isotropic, roughness < 0.2", 5e-2, 1e-6);
    let mut w_cmp = Compare::new("brdf_light_weights", 4e-4, 1e-6);
    let mut table_cmp = Compare::new("brdf_albedo_lookup / average", 0.0, 1e-6);
    let mut zero = Compare::new("below the surface: 0", 0.0, 0.0);
    for (i, ((mat, [n, t, b, v, l]), r)) in cases.iter().zip(&out).enumerate() {
        let m = Material {
            base_color: Vec3::new(mat[0], mat[1], mat[2]),
            perceptual_roughness: mat[3],
            metalness: mat[4],
            anisotropy: mat[5],
            specular: mat[6],
        };
        let d = |x: Vec3| x.as_dvec3();
        let above = n.dot(*v) > 0.0 && n.dot(*l) > 0.0;
        let want = evaluate(&m, *n, *t, *b, *v, *l);
        let want_iso = evaluate_isotropic(&m, *n, *v, *l);
        for k in 0..3 {
            if !above {
                zero.require(i, r[k] == 0.0 && r[3 + k] == 0.0, || format!("{r:?}"));
                continue;
            }
            eval_cmp.check(i, r[k], want[k] as f64, want[k] as f64);
            if mat[3] >= 0.2 {
                iso_cmp.check(i, r[3 + k], want_iso[k] as f64, want_iso[k] as f64);
            } else {
                iso_smooth_cmp.check(i, r[3 + k], want_iso[k] as f64, want_iso[k] as f64);
            }
        }
        // The weights, from hikari-math's pieces.
        let to_local = |w: Vec3| DVec3::new(d(*t).dot(d(w)), d(*b).dot(d(w)), d(*n).dot(d(w)));
        let (vl, ll) = (to_local(*v), to_local(*l));
        if above {
            let (ax, ay) = m.alphas();
            let h = (vl + ll).normalize();
            let spec = ggx_ndf_aniso(h, ax, ay) * visibility_aniso(vl, ll, ax, ay) * ll.z;
            let c = Compensation::new(&m);
            let (e_l, _) = c.single_scattering(ll);
            // The material's F0 and F90 weigh the first two (brdf_apply_weights).
            let want_w = [
                spec,
                spec * schlick_weight(vl.dot(h)),
                (1.0 - c.dielectric_specular_albedo(ll)) * ll.z,
                (1.0 - e_l) * ll.z,
            ];
            for k in 0..4 {
                w_cmp.check(i, r[6 + k], want_w[k], want_w[k]);
            }
        } else {
            zero.require(i, r[6..10].iter().all(|&x| x == 0.0), || format!("{r:?}"));
        }
        let (ax, ay) = m.alphas();
        let rough = isotropic_equivalent_roughness(ax, ay);
        let (e, e_w) = albedo_tables().lookup(n.dot(*v) as f64, rough);
        let (e_avg, e_w_avg) = albedo_tables().average(rough);
        for (k, want) in [e, e_w, e_avg, e_w_avg].into_iter().enumerate() {
            table_cmp.check(i, r[10 + k], want, 0.0);
        }
    }
    report(&[eval_cmp, iso_cmp, iso_smooth_cmp, w_cmp, table_cmp, zero]);
}
