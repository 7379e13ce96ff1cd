//! Sampling against scipy's Sobol points, analytic integrals and numerical integration.
#![allow(clippy::needless_range_loop)]

mod common;
use common::{assert_close, integrate_sphere};
use glam::{Vec2, Vec3};
use hikari_math::sampling::blue_noise::{blue_noise_slices, void_and_cluster};
use hikari_math::sampling::ggx::{ggx_d, sample_vndf, vndf_pdf};
use hikari_math::sampling::lowdiscrepancy::{Sobol, hammersley, radical_inverse_base2};
use hikari_math::sampling::poisson::poisson_disk;
use hikari_math::sampling::sphere::*;
use std::f64::consts::PI;

#[test]
fn sobol_matches_scipy() {
    let path = format!("{}/tests/fixtures/sobol.json", env!("CARGO_MANIFEST_DIR"));
    let fx: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let dims = fx["dims"].as_u64().unwrap() as usize;
    let s = Sobol::new(dims).unwrap();
    for (i, p) in fx["points"].as_array().unwrap().iter().enumerate() {
        for d in 0..dims {
            assert_close(
                s.sample(i as u32, d),
                p[d].as_f64().unwrap(),
                1e-12,
                &format!("point {i} dim {d}"),
            );
        }
    }
    assert!(Sobol::new(0).is_err());
    assert!(Sobol::new(65).is_err());
}

#[test]
fn hammersley_and_radical_inverse() {
    for (i, v) in [
        (0u32, 0.0f32),
        (1, 0.5),
        (2, 0.25),
        (3, 0.75),
        (6, 0.375),
        (5, 0.625),
    ] {
        assert_eq!(radical_inverse_base2(i), v);
    }
    assert_eq!(hammersley(3, 8), Vec2::new(3.5 / 8.0, 0.75));
}

#[test]
fn sphere_mappings_integrate_correctly() {
    // Fibonacci points carry equal solid angle: ∫ z² dω = 4π/3, ∫ x dω = 0.
    let n = 2000;
    let (mut z2, mut x) = (0.0f64, 0.0f64);
    for i in 0..n {
        let d = fibonacci_sphere(i, n);
        assert!((d.length() - 1.0).abs() < 1e-6);
        z2 += (d.z * d.z) as f64;
        x += d.x as f64;
    }
    assert_close(
        z2 * 4.0 * PI / n as f64,
        4.0 * PI / 3.0,
        2e-3,
        "fibonacci z²",
    );
    assert_close(x * 4.0 * PI / n as f64, 0.0, 2e-3, "fibonacci x");
    // Cosine hemisphere: E[cos θ] = ∫ cos² θ / π dω = 2/3; uniform hemisphere E[cos θ] = 1/2;
    // uniform sphere E[z²] = 1/3.
    let m = 4096;
    let (mut c, mut u, mut s) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..m {
        let h = hammersley(i, m);
        let d = cosine_hemisphere(h);
        assert!(d.z >= 0.0 && (d.length() - 1.0).abs() < 1e-5);
        c += d.z as f64;
        u += uniform_hemisphere(h).z as f64;
        s += (uniform_sphere(h).z as f64).powi(2);
    }
    assert_close(c / m as f64, 2.0 / 3.0, 1e-3, "cosine hemisphere");
    assert_close(u / m as f64, 0.5, 1e-3, "uniform hemisphere");
    assert_close(s / m as f64, 1.0 / 3.0, 1e-3, "uniform sphere");
    // The cosine pdf integrates to 1 over the hemisphere.
    let total = integrate_sphere(200, |d| cosine_hemisphere_pdf(d.as_vec3()) as f64);
    assert_close(total, 1.0, 1e-4, "cosine pdf");
}

#[test]
fn ggx_normalisation_and_vndf_sampling() {
    for (ax, ay) in [(0.3f32, 0.3f32), (0.6, 0.2), (0.9, 0.9)] {
        // Projected microfacet area equals the macro-surface: ∫ D(h) h.z dω = 1.
        let proj = integrate_sphere(400, |h| ggx_d(h.as_vec3(), ax, ay) as f64 * h.z.max(0.0));
        assert_close(proj, 1.0, 5e-3, "∫ D cos");
        let v = Vec3::new(0.5, 0.2, 0.8).normalize();
        // The visible-normal density integrates to 1 (this checks G1 against D).
        let total = integrate_sphere(400, |h| vndf_pdf(v, h.as_vec3(), ax, ay) as f64);
        assert_close(total, 1.0, 5e-3, "∫ D_v");
        // Samples follow D_v: compare the sample mean of h with ∫ h D_v(h) dω.
        let mean_ref: [f64; 3] = std::array::from_fn(|k| {
            integrate_sphere(300, |h| {
                h.to_array()[k] * vndf_pdf(v, h.as_vec3(), ax, ay) as f64
            })
        });
        let n = 16_384;
        let mut mean = [0.0f64; 3];
        for i in 0..n {
            let h = sample_vndf(v, ax, ay, hammersley(i, n));
            assert!(h.z >= 0.0 && v.dot(h) >= -1e-5);
            for k in 0..3 {
                mean[k] += h.to_array()[k] as f64 / n as f64;
            }
        }
        for k in 0..3 {
            assert_close(mean[k], mean_ref[k], 5e-3, "VNDF sample mean");
        }
    }
}

#[test]
fn poisson_disk_sets() {
    let r = 0.3;
    let pts = poisson_disk(16, r, 42).unwrap();
    assert_eq!(pts.len(), 16);
    for (i, p) in pts.iter().enumerate() {
        assert!(p.length() <= 1.0);
        for q in &pts[i + 1..] {
            assert!(p.distance(*q) >= r);
        }
    }
    assert_eq!(pts, poisson_disk(16, r, 42).unwrap(), "deterministic");
    assert!(poisson_disk(4, 0.0, 1).is_err());
    assert!(poisson_disk(4, f32::NAN, 1).is_err());
}

/// Mean toroidal nearest-neighbour distance. For a Poisson (white) process it is about half the
/// ideal spacing √(area / k); for blue noise close to the ideal spacing.
fn mean_nn_distance(points: &[(usize, usize)], size: usize) -> f64 {
    let mut sum = 0.0;
    for (i, a) in points.iter().enumerate() {
        let mut best = f64::INFINITY;
        for (j, b) in points.iter().enumerate() {
            if i != j {
                let dx = a.0.abs_diff(b.0).min(size - a.0.abs_diff(b.0)) as f64;
                let dy = a.1.abs_diff(b.1).min(size - a.1.abs_diff(b.1)) as f64;
                best = best.min((dx * dx + dy * dy).sqrt());
            }
        }
        sum += best;
    }
    sum / points.len() as f64
}

#[test]
fn void_and_cluster_is_a_well_spread_permutation() {
    let size = 16;
    let r = void_and_cluster(size, size, 7).unwrap();
    let mut seen = vec![false; size * size];
    for v in &r {
        assert!(!seen[*v as usize]);
        seen[*v as usize] = true;
    }
    // Every threshold level is well spread, and the measure tells white noise apart.
    let mut rng = hikari_math::sampling::SplitMix64(3);
    let mut white: Vec<u32> = (0..(size * size) as u32).collect();
    for i in (1..white.len()).rev() {
        white.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    // On a pixel grid, distances are quantised, so dense levels (25 %) can only be compared
    // with white noise; sparse ones also against the ideal spacing √(area / k).
    for k in [8usize, 26, 64] {
        let ideal = ((size * size) as f64 / k as f64).sqrt();
        let level = |ranks: &[u32]| -> Vec<(usize, usize)> {
            (0..size * size)
                .filter(|&p| (ranks[p] as usize) < k)
                .map(|p| (p % size, p / size))
                .collect()
        };
        let d = mean_nn_distance(&level(&r), size);
        let dw = mean_nn_distance(&level(&white), size);
        assert!(d >= 1.15 * dw, "k={k}: blue {d} vs white {dw}");
        if k <= 26 {
            assert!(
                d >= 0.75 * ideal,
                "k={k}: mean NN distance {d}, ideal spacing {ideal}"
            );
        }
    }
    assert!(void_and_cluster(2, 16, 0).is_err());
    let slices = blue_noise_slices(8, 2, 1).unwrap();
    assert_eq!(slices.len(), 2);
    assert_ne!(slices[0], slices[1]);
}

#[test]
fn committed_blue_noise_comes_from_void_and_cluster() {
    use hikari_math::sampling::blue_noise::*;
    // Regenerating one 64 x 64 slice is affordable in a debug test; all 64 are not.
    let slice0 = void_and_cluster(BLUE_NOISE_SIZE, BLUE_NOISE_SIZE, BLUE_NOISE_SEED).unwrap();
    let n = (BLUE_NOISE_SIZE * BLUE_NOISE_SIZE) as u64;
    let expect: Vec<u8> = slice0.iter().map(|&v| (v as u64 * 256 / n) as u8).collect();
    assert_eq!(blue_noise_slice(0), expect.as_slice());
    // Each slice uses every u8 level equally often (16 texels each).
    for k in [0, 31, 63] {
        let mut hist = [0u32; 256];
        for v in blue_noise_slice(k) {
            hist[*v as usize] += 1;
        }
        assert!(hist.iter().all(|&h| h == 16), "slice {k}");
    }
    assert_ne!(blue_noise_slice(0), blue_noise_slice(1));
}
