//! Spherical harmonics against analytic results and independent numerical integration.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use glam::{DVec3, Vec3};
use hikari_math::sh::dering::{dering, directionality_boost, find_minimum, linear_max_direction};
use hikari_math::sh::product::{gaunt_l2, product_l2};
use hikari_math::sh::project::*;
use hikari_math::sh::rotate::ShRotation;
use hikari_math::sh::window::{hanning, lanczos, sloan2017};
use hikari_math::sh::ycocg::{ShL1YCoCg, rgb_to_ycocg, ycocg_to_rgb};
use hikari_math::sh::zonal::{CLAMPED_COSINE_BANDS, convolve_zonal, irradiance};
use hikari_math::sh::{Sh, ShL1, ShL2, ShL2Rgb, basis};
use std::f64::consts::PI;

fn random_l2(rng: &mut Rng) -> ShL2 {
    Sh::new(std::array::from_fn(|_| rng.range(-1.0, 1.0)))
}

#[test]
fn basis_matches_spherical_form_and_is_orthonormal() {
    let mut rng = Rng(7);
    for _ in 0..200 {
        let d = rng.dir();
        let y = basis::eval_l2_f64(d.as_dvec3());
        for (i, yi) in y.iter().enumerate() {
            assert_close(*yi, y_ref(i, d.as_dvec3()), 1e-6, "basis vs spherical form");
        }
    }
    for i in 0..9 {
        for j in 0..9 {
            let g = integrate_sphere(200, |d| y_ref(i, d) * y_ref(j, d));
            assert_close(
                g,
                if i == j { 1.0 } else { 0.0 },
                1e-4,
                &format!("<Y{i},Y{j}>"),
            );
        }
    }
}

#[test]
fn projections_of_known_functions() {
    // Constant 1: c0 = ∫ Y0 = 2√π, all others 0.
    let one: ShL2 = project_fn(|_| 1.0);
    assert_close(one.coeffs[0] as f64, 2.0 * PI.sqrt(), 1e-5, "constant");
    for c in &one.coeffs[1..] {
        assert!(c.abs() < 1e-5);
    }
    // Clamped cosine max(0, z): zonal coefficients √π/2, √(π/3), √(5π)/8 (Ramamoorthi & Hanrahan).
    // The kink at z = 0 needs a fine grid in z (Gauss-Legendre error ~ n⁻²).
    let cc: ShL2 = project_fn_quadrature(|d| d.z.max(0.0), 400, 8);
    assert_close(cc.coeffs[0] as f64, PI.sqrt() / 2.0, 1e-4, "clamped cos l0");
    assert_close(
        cc.coeffs[2] as f64,
        (PI / 3.0).sqrt(),
        1e-4,
        "clamped cos l1",
    );
    assert_close(
        cc.coeffs[6] as f64,
        (5.0 * PI).sqrt() / 8.0,
        1e-4,
        "clamped cos l2",
    );
    // x: c3 = √(4π/3).
    let x: ShL1 = project_fn(|d| d.x);
    assert_close(x.coeffs[3] as f64, (4.0 * PI / 3.0).sqrt(), 1e-5, "x");
    // An L2 function projects to itself, even with the smallest exact quadrature.
    let mut rng = Rng(3);
    let f = random_l2(&mut rng);
    let g: ShL2 = project_fn_quadrature(|d| f.eval(d), 3, 5);
    for i in 0..9 {
        assert_close(g.coeffs[i] as f64, f.coeffs[i] as f64, 1e-5, "round trip");
    }
}

#[test]
fn sample_and_cubemap_projection() {
    let mut rng = Rng(11);
    let f = random_l2(&mut rng);
    let samples: Vec<(Vec3, f32)> = (0..40_000)
        .map(|_| rng.dir())
        .map(|d| (d, f.eval(d)))
        .collect();
    let g: ShL2 = project_uniform_samples(samples.iter().copied());
    for i in 0..9 {
        assert_close(
            g.coeffs[i] as f64,
            f.coeffs[i] as f64,
            0.05,
            "Monte Carlo projection",
        );
    }
    // Solid angles sum to 4π exactly (the area formula is exact).
    let n = 16;
    let total: f64 = (0..6)
        .map(|_| {
            (0..n * n)
                .map(|k| cube_texel_solid_angle(n, k % n, k / n))
                .sum::<f64>()
        })
        .sum();
    assert_close(total, 4.0 * PI, 1e-12, "cube solid angles");
    // Face centres point along the axes in layer order.
    let axes = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    for (face, axis) in CubeFace::ALL.iter().zip(axes) {
        let d = face.direction(0.0, 0.0).as_vec3();
        assert!((d - axis).length() < 1e-6);
        // Each face's (s, t) frame is right-handed when seen from inside: (s × t) points out... or
        // consistently: s × t must be ± the axis; all six must agree in sign.
        let s = (face.direction(1.0, 0.0) - face.direction(0.0, 0.0)).as_vec3();
        let t = (face.direction(0.0, 1.0) - face.direction(0.0, 0.0)).as_vec3();
        assert!((s.cross(t) + axis).length() < 1e-6, "face {face:?}");
    }
    let size = 32;
    let faces: Vec<Vec<f32>> = CubeFace::ALL
        .iter()
        .map(|face| {
            (0..size * size)
                .map(|k| f.eval(cube_texel_direction(*face, size, k % size, k / size)))
                .collect()
        })
        .collect();
    let g: ShL2 = project_cubemap(size, std::array::from_fn(|k| faces[k].as_slice())).unwrap();
    for i in 0..9 {
        assert_close(
            g.coeffs[i] as f64,
            f.coeffs[i] as f64,
            2e-3,
            "cube map projection",
        );
    }
    let bad = vec![0.0f32; 3];
    assert!(project_cubemap::<f32, 9>(size, std::array::from_fn(|_| bad.as_slice())).is_err());
}

#[test]
fn rotation_is_exact_and_invariant() {
    let mut rng = Rng(5);
    for _ in 0..100 {
        let f = random_l2(&mut rng);
        let r = rng.rotation();
        let g = ShRotation::new(r).apply(&f);
        for _ in 0..10 {
            let d = rng.dir();
            assert_close(
                g.eval(r * d) as f64,
                f.eval(d) as f64,
                1e-5,
                "g(R d) = f(d)",
            );
        }
        // Per-band energy is rotation invariant.
        let e =
            |s: &ShL2, a: usize, b: usize| s.coeffs[a..b].iter().map(|c| c * c).sum::<f32>() as f64;
        assert_close(e(&g, 1, 4), e(&f, 1, 4), 1e-5, "band 1 energy");
        assert_close(e(&g, 4, 9), e(&f, 4, 9), 1e-5, "band 2 energy");
        // Composition.
        let r2 = rng.rotation();
        let a = ShRotation::new(r2).apply(&g);
        let b = ShRotation::new(r2 * r).apply(&f);
        for i in 0..9 {
            assert_close(a.coeffs[i] as f64, b.coeffs[i] as f64, 1e-5, "composition");
        }
    }
}

#[test]
fn product_matches_numerical_integration() {
    let g = gaunt_l2();
    for i in 0..9 {
        for j in 0..9 {
            // Y0 · Y_j = C0 Y_j, so G[0][i][j] = C0 δij.
            assert_close(
                g[0][i][j],
                if i == j { basis::C0 } else { 0.0 },
                1e-13,
                "G0ij",
            );
            for k in 0..9 {
                assert_close(g[i][j][k], g[j][k][i], 1e-13, "symmetry");
            }
        }
    }
    let mut rng = Rng(9);
    for _ in 0..3 {
        let a = random_l2(&mut rng);
        let b = random_l2(&mut rng);
        let p = product_l2(&a, &b);
        for k in 0..9 {
            let reference = integrate_sphere(120, |d| {
                let dv = d.as_vec3();
                a.eval(dv) as f64 * b.eval(dv) as f64 * y_ref(k, d)
            });
            assert_close(p.coeffs[k] as f64, reference, 1e-4, "product coefficient");
        }
    }
    // RGB products are per channel.
    let a = random_l2(&mut rng);
    let b = random_l2(&mut rng);
    let rgb = product_l2(
        &ShL2Rgb::from_channels(&a, &b, &a),
        &ShL2Rgb::from_channels(&b, &a, &a),
    );
    let p = product_l2(&a, &b);
    for k in 0..9 {
        assert_close(
            rgb.coeffs[k].x as f64,
            p.coeffs[k] as f64,
            1e-6,
            "rgb product",
        );
    }
}

#[test]
fn cosine_convolution_of_delta_is_clamped_cosine() {
    let mut rng = Rng(21);
    for _ in 0..5 {
        let dir = rng.dir();
        // Irradiance from a unit delta light = max(0, n·dir); its SH projection is the reference.
        let e = irradiance(&ShL2::delta(dir, 1.0));
        // The kink of max(0, ·) limits quadrature accuracy, hence the fine grid and 3e-4.
        let reference: ShL2 = project_fn_quadrature(|n| n.dot(dir).max(0.0), 200, 400);
        for i in 0..9 {
            assert_close(
                e.coeffs[i] as f64,
                reference.coeffs[i] as f64,
                3e-4,
                "irradiance of delta",
            );
        }
        // Same through the generic zonal convolution with the clamped cosine's zonal coefficients.
        let z = [
            (PI.sqrt() / 2.0) as f32,
            (PI / 3.0).sqrt() as f32,
            ((5.0 * PI).sqrt() / 8.0) as f32,
        ];
        let e2 = convolve_zonal(&ShL2::delta(dir, 1.0), z);
        for i in 0..9 {
            assert_close(
                e2.coeffs[i] as f64,
                e.coeffs[i] as f64,
                1e-5,
                "zonal convolution",
            );
        }
    }
    // Constant radiance L: irradiance π L everywhere.
    let l: ShL2 = project_fn(|_| 2.0);
    assert_close(
        irradiance(&l).eval(Vec3::new(0.6, 0.0, 0.8)) as f64,
        2.0 * PI,
        1e-4,
        "white furnace",
    );
    assert_close(CLAMPED_COSINE_BANDS[1] as f64, 2.0 * PI / 3.0, 1e-6, "A1");
}

#[test]
fn windows() {
    assert_eq!(sloan2017(0.0), [1.0, 1.0, 1.0]);
    let s = sloan2017(0.1);
    assert_close(s[1] as f64, 1.0 / 1.4, 1e-6, "sloan l1");
    assert_close(s[2] as f64, 1.0 / 4.6, 1e-6, "sloan l2");
    let h = hanning(3.0);
    assert_close(h[1] as f64, 0.5 * (1.0 + (PI / 3.0).cos()), 1e-6, "hanning");
    let l = lanczos(4.0);
    assert_close(l[2] as f64, (PI / 2.0).sin() / (PI / 2.0), 1e-6, "lanczos");
    assert_eq!(hanning(f32::NAN), [1.0; 3]);
}

#[test]
fn dering_makes_random_inputs_non_negative() {
    let dirs = dense_dirs(3000);
    let mut rng = Rng(1234);
    let mut worst = 0.0f32;
    let mut misses = 0;
    for _ in 0..2000 {
        let mut f = random_l2(&mut rng);
        f.coeffs[0] = rng.range(0.0, 2.0);
        let d = dering(&f);
        let true_min = dirs
            .iter()
            .map(|&v| d.sh.eval(v))
            .fold(f32::INFINITY, f32::min);
        worst = worst.min(true_min / f.coeffs[0].max(1e-3));
        // The Newton estimate must be close to the dense minimum of the input.
        let dense = dirs
            .iter()
            .map(|&v| f.eval(v))
            .fold(f32::INFINITY, f32::min);
        if find_minimum(&f).1 > dense + 1e-2 {
            misses += 1;
        }
    }
    assert!(worst > -1e-2, "deringed minimum relative to mean: {worst}");
    assert!(
        misses < 20,
        "Newton minimum missed in {misses} of 2000 cases"
    );
}

#[test]
fn dering_leaves_non_ringing_inputs_alone() {
    let mut rng = Rng(77);
    for _ in 0..100 {
        let dir = rng.dir();
        // A smooth positive lobe: 1 + 0.8 max(0, cos) projected is positive, no windowing needed.
        let f: ShL2 = project_fn(|d| 1.0 + 0.8 * d.dot(dir).max(0.0));
        let d = dering(&f);
        assert_eq!(d.strength, 0.0);
        assert_eq!(d.sh, f);
    }
    // A projected delta rings; deringing fixes it, and by a moderate amount.
    let delta = ShL2::delta(Vec3::Z, 1.0);
    assert!(find_minimum(&delta).1 < 0.0);
    let d = dering(&delta);
    assert!(
        d.strength > 0.0 && d.strength <= 0.5,
        "strength {}",
        d.strength
    );
    assert!(dense_dirs(2000).iter().all(|&v| d.sh.eval(v) >= -1e-6));
}

#[test]
fn rgb_dering_uses_one_strength() {
    let dirs = dense_dirs(2000);
    let mut rng = Rng(99);
    for _ in 0..200 {
        let mut ch: [ShL2; 3] = std::array::from_fn(|_| random_l2(&mut rng));
        for c in ch.iter_mut() {
            c.coeffs[0] = rng.range(0.2, 2.0);
        }
        let rgb = ShL2Rgb::from_channels(&ch[0], &ch[1], &ch[2]);
        let d = dering(&rgb);
        for k in 0..3 {
            let min = dirs
                .iter()
                .map(|&v| d.sh.eval(v)[k])
                .fold(f32::INFINITY, f32::min);
            assert!(min > -1e-2 * ch[k].coeffs[0], "channel {k}: {min}");
            // One window for all channels: each channel is the input channel windowed the same.
            let w = hikari_math::sh::dering::dering_window(d.strength);
            let expect = ch[k].scale_bands(w);
            for i in 0..9 {
                assert_close(
                    d.sh.coeffs[i][k] as f64,
                    expect.coeffs[i] as f64,
                    1e-6,
                    "same window",
                );
            }
        }
    }
    // A quaternion and its matrix give the same SH rotation.
    let q = glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let a = ShRotation::from_quat(q);
    let b = ShRotation::new(glam::Mat3::from_quat(q));
    for i in 0..5 {
        for j in 0..5 {
            assert_close(a.band2[i][j], b.band2[i][j], 1e-6, "quat vs matrix");
        }
    }
}

#[test]
fn directionality_boost_keeps_mean_and_direction() {
    let f: ShL2 = project_fn(|d| 1.0 + d.dot(Vec3::new(0.0, 0.6, 0.8)).max(0.0));
    let dir = linear_max_direction(&f).unwrap();
    assert!((dir - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-4);
    let b = directionality_boost(&f, 0.25);
    assert_close(b.coeffs[0] as f64, f.coeffs[0] as f64, 1e-6, "mean kept");
    assert!(b.eval(dir) > f.eval(dir));
    assert_eq!(directionality_boost(&f, 0.0), f);
    let full = directionality_boost(&f, 1.0);
    let delta = ShL2::delta(dir, f.coeffs[0] / basis::C0 as f32);
    for i in 0..9 {
        assert_close(
            full.coeffs[i] as f64,
            delta.coeffs[i] as f64,
            1e-5,
            "boost 1 = delta",
        );
    }
}

#[test]
fn metro_ycocg_encoding() {
    let mut rng = Rng(31);
    for _ in 0..100 {
        let c = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 10.0;
        let v = rgb_to_ycocg(c);
        assert_close(
            v.x as f64,
            (0.25 * c.x + 0.5 * c.y + 0.25 * c.z) as f64,
            1e-5,
            "Y",
        );
        assert!((ycocg_to_rgb(v) - c).length() < 1e-5);
        assert!((ShL1YCoCg::encode(c, rng.dir()).to_color() - c).length() < 1e-4);
    }
    // Uniform radiance L over the hemisphere around n, sampled uniformly: a white Lambertian
    // surface facing n reflects exactly L.
    let n = Vec3::new(0.0, 0.0, 1.0);
    let l = Vec3::new(1.0, 0.5, 0.25);
    let mut acc = ShL1YCoCg::default();
    let dirs = dense_dirs(20_000);
    let hemi: Vec<Vec3> = dirs.into_iter().filter(|d| d.z > 0.0).collect();
    for d in &hemi {
        acc = acc.add(&ShL1YCoCg::encode(l, *d));
    }
    let acc = acc.scale(1.0 / hemi.len() as f32);
    assert!(
        (acc.resolve_diffuse(n) - l).length() < 2e-3,
        "{}",
        acc.resolve_diffuse(n)
    );
    // Facing away from the hemisphere: the L1 irradiance estimate is 0.
    assert!(acc.resolve_diffuse(-n).length() < 2e-3);
    assert!((acc.dominant_direction().unwrap() - n).length() < 1e-3);
    // A single direction: fully directional, specular keeps the material roughness.
    let one = ShL1YCoCg::encode(l, Vec3::X);
    assert_close(
        one.directionality() as f64,
        1.0,
        1e-5,
        "delta directionality",
    );
    assert!(one.specular_alpha(0.2) < 0.21);
    // Uniform over the sphere: no direction, fully rough.
    let mut all = ShL1YCoCg::default();
    for d in dense_dirs(4000) {
        all = all.add(&ShL1YCoCg::encode(l, d));
    }
    assert!(all.directionality() < 1e-3);
    assert!(all.specular_alpha(0.1) > 0.99);
    let _ = DVec3::ZERO;
}
