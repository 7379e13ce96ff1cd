//! Analytic checks: closed-form optical depth, phase normalisation, no scattering → no light,
//! parameter validation.

use glam::Vec3;
use hikari_atmosphere::{
    Atmosphere, AtmosphereError, AtmosphereParams, TableSizes, phase, transmittance_to_top,
};

fn small() -> TableSizes {
    TableSizes {
        scattering: [32, 16, 8],
        density: [16, 16, 8],
        sphere: [8, 8],
        ray_steps: 20,
        ..TableSizes::default()
    }
}

fn rayleigh_only() -> AtmosphereParams {
    AtmosphereParams {
        mie_scattering_per_km: 0.0,
        mie_extinction_per_km: 0.0,
        ozone_absorption_per_km: Some([0.0; 3]),
        ..AtmosphereParams::default()
    }
}

/// Vertical optical depth of an exponential layer from altitude h to the top at height `top`:
/// `β H (exp(−h/H) − exp(−top/H))`.
fn closed_form(beta: f64, h: f64, top: f64) -> f64 {
    beta * 8.0 * ((-h / 8.0).exp() - (-top / 8.0).exp())
}

#[test]
fn vertical_transmittance_matches_closed_form() {
    let p = rayleigh_only();
    let a = Atmosphere::with_sizes(p.clone(), small()).unwrap();
    let beta = p.rayleigh();
    for h in [0.0f64, 1.0, 5.0, 12.0, 30.0, 55.0] {
        let direct = transmittance_to_top(&p, p.bottom_radius_km + h, 1.0, 500);
        let table = a.transmittance(h as f32, 1.0);
        for c in 0..3 {
            let exact = (-closed_form(beta[c], h, 60.0)).exp();
            // Trapezoid rule, 500 steps of 0.12 km: error ≈ τ Δ² / (12 H²) ≈ 1e-6.
            assert!(
                (direct[c] - exact).abs() < 4e-6 * exact,
                "integrator h={h} c={c}: {} vs {exact}",
                direct[c]
            );
            // The table interpolates linearly in sqrt(r² − bottom²) between 64 rows.
            assert!(
                (table[c] - exact).abs() < 2e-3 * exact,
                "table h={h} c={c}: {} vs {exact}",
                table[c]
            );
        }
    }
}

#[test]
fn phase_functions_integrate_to_one() {
    let n = 200_000;
    for g in [0.0, 0.3, 0.8, 0.95, -0.5] {
        let (mut r, mut m) = (0.0, 0.0);
        for i in 0..n {
            let nu = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
            r += phase::rayleigh(nu);
            m += phase::cornette_shanks(nu, g);
        }
        let w = 2.0 * std::f64::consts::PI * 2.0 / n as f64;
        assert!((r * w - 1.0).abs() < 1e-6, "rayleigh {}", r * w);
        assert!(
            (m * w - 1.0).abs() < 1e-4,
            "cornette-shanks g={g}: {}",
            m * w
        );
    }
}

#[test]
fn no_scattering_no_inscatter() {
    let p = AtmosphereParams {
        rayleigh_scattering_per_km: Some([0.0; 3]),
        mie_scattering_per_km: 0.0,
        ..AtmosphereParams::default()
    };
    let a = Atmosphere::with_sizes(p, small()).unwrap();
    for t in [
        &a.tables.rayleigh,
        &a.tables.mie,
        &a.tables.ground_irradiance,
    ] {
        assert!(t.data.iter().all(|v| *v == [0.0; 3]));
    }
    let sun = Vec3::new(0.3, 0.9, 0.1).normalize();
    for v in [Vec3::Y, Vec3::X, Vec3::new(0.2, -0.3, 0.9).normalize()] {
        assert_eq!(
            a.sky_radiance(0.5, v, sun, a.solar_illuminance()),
            Vec3::ZERO
        );
    }
}

#[test]
fn clear_noon_near_100_klux() {
    let a = Atmosphere::with_sizes(AtmosphereParams::default(), small()).unwrap();
    let z = 10f32.to_radians();
    let direct = a.sun_illuminance_at_ground(z) * z.cos();
    let sky = a.sky_irradiance(0.0, z, a.solar_illuminance());
    let y = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let total = y(direct) + y(sky);
    assert!((80_000.0..130_000.0).contains(&total), "noon: {total} lux");
    assert_eq!(a.sun_illuminance_at_ground(95f32.to_radians()), Vec3::ZERO);
}

#[test]
fn bad_parameters_name_the_field() {
    let cases: Vec<(AtmosphereParams, &str)> = vec![
        (
            AtmosphereParams {
                mie_scattering_per_km: f64::NAN,
                ..Default::default()
            },
            "mie_scattering_per_km",
        ),
        (
            AtmosphereParams {
                rayleigh_scattering_per_km: Some([1e-3, -1.0, 0.0]),
                ..Default::default()
            },
            "rayleigh_scattering_per_km",
        ),
        (
            AtmosphereParams {
                top_radius_km: 6000.0,
                ..Default::default()
            },
            "top_radius_km",
        ),
        (
            AtmosphereParams {
                mie_g: 1.0,
                ..Default::default()
            },
            "mie_g",
        ),
        (
            AtmosphereParams {
                ground_albedo: 1.5,
                ..Default::default()
            },
            "ground_albedo",
        ),
        (
            AtmosphereParams {
                ozone_absorption_per_km: Some([f64::INFINITY, 0.0, 0.0]),
                ..Default::default()
            },
            "ozone_absorption_per_km",
        ),
        (
            AtmosphereParams {
                mie_extinction_per_km: 1e-3,
                ..Default::default()
            },
            "mie_extinction_per_km",
        ),
    ];
    for (p, field) in cases {
        match Atmosphere::with_sizes(p, small()) {
            Err(e @ AtmosphereError::OutOfRange { field: f, .. }) => {
                assert_eq!(f, field);
                assert!(e.to_string().contains(field));
            }
            Ok(_) => panic!("{field} accepted"),
        }
    }
    let toml_like: Result<AtmosphereParams, _> = serde_json::from_str(r#"{"mie_gee": 0.5}"#);
    assert!(toml_like.is_err(), "unknown fields are refused");
}

#[test]
fn every_table_name_finds_its_own_table() {
    let a = Atmosphere::with_sizes(AtmosphereParams::default(), small()).unwrap();
    let t = &a.tables;
    let fields = [
        &t.transmittance,
        &t.rayleigh,
        &t.rayleigh_single,
        &t.mie,
        &t.scattering_distance,
        &t.irradiance_rayleigh,
        &t.irradiance_mie,
        &t.ground_irradiance,
    ];
    assert_eq!(hikari_atmosphere::Tables::NAMES.len(), fields.len());
    for (name, field) in hikari_atmosphere::Tables::NAMES.iter().zip(fields) {
        let got = t.by_name(name).unwrap_or_else(|| panic!("{name}"));
        assert!(std::ptr::eq(got, field), "{name} names another table");
    }
    assert!(t.by_name("Rayleigh").is_none() && t.by_name("").is_none());
}
