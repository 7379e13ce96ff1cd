//! Test helpers: a tiny deterministic RNG and an independent f64 sphere quadrature.
#![allow(dead_code)]

use glam::{DVec3, Mat3, Quat, Vec3};

/// xorshift64* — deterministic, dependency-free.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn f32(&mut self) -> f32 {
        self.f64() as f32
    }
    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f32()
    }
    pub fn dir(&mut self) -> Vec3 {
        let z = 2.0 * self.f64() - 1.0;
        let phi = 2.0 * std::f64::consts::PI * self.f64();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3()
    }
    pub fn rotation(&mut self) -> Mat3 {
        let q = Quat::from_xyzw(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
        .normalize();
        Mat3::from_quat(q)
    }
}

/// Midpoint rule on an equal-angle (θ, φ) grid, weights sin θ Δθ Δφ: deliberately a different
/// quadrature from the crate's Gauss-Legendre one.
pub fn integrate_sphere(n_theta: usize, mut f: impl FnMut(DVec3) -> f64) -> f64 {
    let n_phi = 2 * n_theta;
    let dt = std::f64::consts::PI / n_theta as f64;
    let dp = 2.0 * std::f64::consts::PI / n_phi as f64;
    let mut acc = 0.0;
    for i in 0..n_theta {
        let t = (i as f64 + 0.5) * dt;
        // Exact solid angle of the ring cell instead of sin θ Δθ, so constants integrate exactly.
        let w = ((t - 0.5 * dt).cos() - (t + 0.5 * dt).cos()) * dp;
        for j in 0..n_phi {
            let p = (j as f64 + 0.5) * dp;
            acc += w * f(DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()));
        }
    }
    acc
}

/// Independent evaluation of the documented basis from spherical coordinates
/// (associated Legendre form, written from the table in the crate docs, not the crate code).
pub fn y_ref(i: usize, d: DVec3) -> f64 {
    use std::f64::consts::PI;
    let theta = d.z.clamp(-1.0, 1.0).acos();
    let phi = d.y.atan2(d.x);
    let (st, ct) = (theta.sin(), theta.cos());
    match i {
        0 => 0.5 * (1.0 / PI).sqrt(),
        1 => (3.0 / (4.0 * PI)).sqrt() * st * phi.sin(),
        2 => (3.0 / (4.0 * PI)).sqrt() * ct,
        3 => (3.0 / (4.0 * PI)).sqrt() * st * phi.cos(),
        4 => 0.25 * (15.0 / PI).sqrt() * st * st * (2.0 * phi).sin(),
        5 => 0.5 * (15.0 / PI).sqrt() * st * ct * phi.sin(),
        6 => 0.25 * (5.0 / PI).sqrt() * (3.0 * ct * ct - 1.0),
        7 => 0.5 * (15.0 / PI).sqrt() * st * ct * phi.cos(),
        8 => 0.25 * (15.0 / PI).sqrt() * st * st * (2.0 * phi).cos(),
        _ => unreachable!(),
    }
}

pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tol {tol})");
}

/// Fibonacci sphere points (test-only copy-free construction: golden-angle spiral).
pub fn dense_dirs(n: usize) -> Vec<Vec3> {
    let ga = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let p = ga * i as f64;
            DVec3::new(r * p.cos(), r * p.sin(), z).as_vec3()
        })
        .collect()
}

/// A WGSL module of `hikari-render/shaders/common/` (the twins of this crate).
pub fn wgsl_module(name: &str) -> String {
    let path = format!(
        "{}/../hikari-render/shaders/common/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).expect("shader present")
}

/// naga_oil's `#define_import_path` is not WGSL; drop it to validate the module on its own.
pub fn validate_wgsl(src: &str, name: &str) {
    let body: String = src
        .lines()
        .filter(|l| !l.starts_with("#define_import_path"))
        .collect::<Vec<_>>()
        .join("\n");
    let module = naga::front::wgsl::parse_str(&body)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&body)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {e:?}"));
}
