//! Sun and moon positions against PyEphem (tests/fixtures/ephemeris.json, written by
//! tools/ephemeris_reference.py and cross-checked there against ERFA), the inputs' validation
//! and the illuminance model.

use glam::Vec3;
use hikari_math::astro::illuminance::{MOON_MEAN_DISTANCE_KM, moon_magnitude};
use hikari_math::astro::*;
use serde_json::Value;

fn fixture() -> Value {
    let path = format!(
        "{}/tests/fixtures/ephemeris.json",
        env!("CARGO_MANIFEST_DIR")
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("fixture present"))
        .expect("valid JSON")
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

/// Angle on the sky between two (azimuth, elevation) pairs, degrees.
fn separation_deg(az1: f64, el1: f64, az2: f64, el2: f64) -> f64 {
    let (a1, e1, a2, e2) = (
        az1.to_radians(),
        el1.to_radians(),
        az2.to_radians(),
        el2.to_radians(),
    );
    let v = |a: f64, e: f64| [a.sin() * e.cos(), a.cos() * e.cos(), e.sin()];
    let (p, q) = (v(a1, e1), v(a2, e2));
    let cross = [
        p[1] * q[2] - p[2] * q[1],
        p[2] * q[0] - p[0] * q[2],
        p[0] * q[1] - p[1] * q[0],
    ];
    let sin = (cross[0].powi(2) + cross[1].powi(2) + cross[2].powi(2)).sqrt();
    sin.atan2(p[0] * q[0] + p[1] * q[1] + p[2] * q[2])
        .to_degrees()
}

#[test]
fn sun_and_moon_match_pyephem() {
    let doc = fixture();
    let cases = doc["cases"].as_array().expect("cases");
    assert!(cases.len() >= 100);
    let (mut sun_worst, mut moon_worst, mut frac_worst) = (0.0f64, 0.0f64, 0.0f64);
    let (mut sun_dist_worst, mut moon_dist_worst) = (0.0f64, 0.0f64);
    for c in cases {
        let what = format!(
            "{} {} UTC{:+} at ({}, {})",
            c["date"], c["time"], c["utc_offset_h"], c["lat_deg"], c["lon_deg"]
        );
        let when = DateTime::parse(
            c["date"].as_str().unwrap(),
            c["time"].as_str().unwrap(),
            f(&c["utc_offset_h"]),
        )
        .unwrap_or_else(|e| panic!("{what}: {e}"));
        let place = Place::new(f(&c["lat_deg"]), f(&c["lon_deg"])).unwrap();
        let got = sun_and_moon(&when, &place);

        let (s, m) = (&c["sun"], &c["moon"]);
        let ds = separation_deg(
            got.sun.azimuth_deg,
            got.sun.elevation_deg,
            f(&s["azimuth_deg"]),
            f(&s["elevation_deg"]),
        );
        let dm = separation_deg(
            got.moon.azimuth_deg,
            got.moon.elevation_deg,
            f(&m["azimuth_deg"]),
            f(&m["elevation_deg"]),
        );
        let dk = (got.moon.illuminated_fraction - f(&m["illuminated_fraction"])).abs();
        let dr = (got.sun.distance_au / f(&s["distance_au"]) - 1.0).abs();
        let dd = (got.moon.geocentric_distance_km - f(&m["geocentric_distance_km"]))
            .abs()
            .max((got.moon.distance_km - f(&m["distance_km"])).abs());
        assert!(ds < 0.01, "{what}: sun off by {ds}° ({got:?})");
        assert!(dm < 0.1, "{what}: moon off by {dm}° ({got:?})");
        assert!(dk < 0.01, "{what}: illuminated fraction off by {dk}");
        assert!(dr < 1e-5, "{what}: sun distance off by {dr} (relative)");
        assert!(dd < 30.0, "{what}: moon distance off by {dd} km");
        sun_worst = sun_worst.max(ds);
        moon_worst = moon_worst.max(dm);
        frac_worst = frac_worst.max(dk);
        sun_dist_worst = sun_dist_worst.max(dr);
        moon_dist_worst = moon_dist_worst.max(dd);
    }
    println!(
        "worst over {} cases: sun {sun_worst:.5}°, moon {moon_worst:.5}°, illuminated fraction \
         {frac_worst:.5}, sun distance {sun_dist_worst:.2e} (relative), moon distance \
         {moon_dist_worst:.2} km",
        cases.len()
    );
}

#[test]
fn direction_follows_the_world_axes() {
    let tsushima = Place::TSUSHIMA;
    let at = |time: &str| {
        sun_and_moon(
            &DateTime::parse("2024-07-21", time, 9.0).unwrap(),
            &tsushima,
        )
    };
    // Summer at 34.4° N: the noon sun culminates in the south (−Z), high; the morning sun is in
    // the east (−X), the evening sun in the west (+X).
    let noon = at("12:30");
    assert!(noon.sun.direction.z < 0.0 && noon.sun.direction.y > 0.9);
    assert!(at("07:00").sun.direction.x < -0.5);
    assert!(at("17:30").sun.direction.x > 0.5);
    // The direction is the unit vector for the azimuth and elevation, everywhere.
    let doc = fixture();
    for c in doc["cases"].as_array().unwrap() {
        let when = DateTime::parse(
            c["date"].as_str().unwrap(),
            c["time"].as_str().unwrap(),
            f(&c["utc_offset_h"]),
        )
        .unwrap();
        let place = Place::new(f(&c["lat_deg"]), f(&c["lon_deg"])).unwrap();
        let got = sun_and_moon(&when, &place);
        for (az, el, d) in [
            (
                got.sun.azimuth_deg,
                got.sun.elevation_deg,
                got.sun.direction,
            ),
            (
                got.moon.azimuth_deg,
                got.moon.elevation_deg,
                got.moon.direction,
            ),
        ] {
            let (a, e) = (az.to_radians(), el.to_radians());
            let want = Vec3::new(
                (-a.sin() * e.cos()) as f32,
                e.sin() as f32,
                (a.cos() * e.cos()) as f32,
            );
            assert!((d - want).length() < 1e-5, "{d} vs {want}");
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }
}

#[test]
fn edges_of_the_allowed_inputs_give_finite_results() {
    for (date, time, offset) in [
        ("1900-01-01", "00:00", 14.0),
        ("2100-12-31", "23:59:59", -14.0),
        ("2000-02-29", "12:00", 0.0),
    ] {
        for (lat, lon) in [
            (90.0, 180.0),
            (-90.0, -180.0),
            (0.0, 0.0),
            (89.999, -179.999),
        ] {
            let r = sun_and_moon(
                &DateTime::parse(date, time, offset).unwrap(),
                &Place::new(lat, lon).unwrap(),
            );
            let all = [
                r.sun.azimuth_deg,
                r.sun.elevation_deg,
                r.sun.extraterrestrial_lux,
                r.moon.azimuth_deg,
                r.moon.elevation_deg,
                r.moon.distance_km,
                r.moon.illuminated_fraction,
                r.moon.extraterrestrial_lux,
            ];
            assert!(
                all.iter().all(|v| v.is_finite()),
                "{date} {lat} {lon}: {r:?}"
            );
            assert!(r.sun.direction.is_finite() && r.moon.direction.is_finite());
            assert!((0.0..360.0).contains(&r.sun.azimuth_deg));
        }
    }
}

#[test]
fn bad_input_names_the_field_and_its_range() {
    let msg = |e: AstroError| e.to_string();
    let date = |d: &str| msg(DateTime::parse(d, "12:00", 0.0).unwrap_err());
    for bad in ["1899-12-31", "2101-01-01"] {
        let m = date(bad);
        assert!(
            m.contains(bad) && m.contains("1900-01-01 to 2100-12-31"),
            "{m}"
        );
    }
    for bad in [
        "2023-02-29",
        "2024-13-01",
        "2024-7-1",
        "tomorrow",
        "1900-02-29",
    ] {
        assert!(
            date(bad).starts_with(&format!("date `{bad}`")),
            "{}",
            date(bad)
        );
    }
    let time = |t: &str| msg(DateTime::parse("2024-07-21", t, 0.0).unwrap_err());
    for bad in ["24:00", "23:60", "12:00:60", "25:00", "noon", "12", "1:2"] {
        let m = time(bad);
        assert!(
            m.starts_with(&format!("time `{bad}`")) && m.contains("23:59:59"),
            "{m}"
        );
    }
    for bad in [14.5, -14.01, f64::NAN] {
        let m = msg(DateTime::parse("2024-07-21", "12:00", bad).unwrap_err());
        assert!(m.contains("utc_offset") && m.contains("-14..=14"), "{m}");
    }
    for bad in [90.01, -91.0, f64::NAN, f64::INFINITY] {
        let m = msg(Place::new(bad, 0.0).unwrap_err());
        assert!(m.contains("latitude") && m.contains("-90..=90"), "{m}");
    }
    for bad in [180.5, -181.0, f64::NAN] {
        let m = msg(Place::new(0.0, bad).unwrap_err());
        assert!(m.contains("longitude") && m.contains("-180..=180"), "{m}");
    }
    // The limits themselves are allowed.
    assert!(DateTime::parse("2100-12-31", "23:59:59", 14.0).is_ok());
    assert!(DateTime::parse("1900-01-01", "0:00", -14.0).is_ok());
    assert!(Place::new(-90.0, 180.0).is_ok());
}

#[test]
fn illuminance_at_the_top_of_the_atmosphere() {
    // The lunar magnitude scale and the solar constant agree: the same magnitude-to-lux
    // conversion (Krisciunas & Schaefer's 16.57 for foot-candles) applied to the sun's
    // V = −26.74 (Allen) gives the solar constant within 2 %.
    let sun_from_magnitude = 10f64.powf(-0.4 * (-26.74 + 16.57)) * 10.7639;
    assert!((sun_from_magnitude / SOLAR_ILLUMINANCE_CONSTANT_LUX - 1.0).abs() < 0.02);
    assert!((sun_extraterrestrial_lux(1.0) - SOLAR_ILLUMINANCE_CONSTANT_LUX).abs() < 1e-9);
    // Perihelion is brighter than aphelion by (1.0167 / 0.9833)² ≈ 6.9 %.
    let ratio = sun_extraterrestrial_lux(0.9833) / sun_extraterrestrial_lux(1.0167);
    assert!((ratio - 1.069).abs() < 0.001);

    // A full moon at the mean distance: about 0.3 lux above the air, so 0.1 to 0.3 lux on the
    // ground through a clear sky's 0.6 to 0.9 transmittance when high.
    let full = moon_extraterrestrial_lux(0.0, MOON_MEAN_DISTANCE_KM);
    assert!((0.27..0.35).contains(&full), "{full}");
    assert!(full * 0.6 > 0.1 && full * 0.9 < 0.32);
    // Fainter with the phase angle, inverse square with the distance.
    let mut last = full;
    for a in (10..=180).step_by(10) {
        let e = moon_extraterrestrial_lux(a as f64, MOON_MEAN_DISTANCE_KM);
        assert!(e < last && e > 0.0);
        last = e;
    }
    let near = moon_extraterrestrial_lux(30.0, MOON_MEAN_DISTANCE_KM / 2.0);
    assert!((near / moon_extraterrestrial_lux(30.0, MOON_MEAN_DISTANCE_KM) - 4.0).abs() < 1e-9);
    // Quarter moon is about 2.5 magnitudes fainter than full (Allen: −10.1 vs −12.7).
    assert!((moon_magnitude(90.0) - moon_magnitude(0.0) - 2.6).abs() < 0.1);

    // The default night: Tsushima, 2024-07-21 23:00, the day of a full moon, moon up.
    let night = sun_and_moon(
        &DateTime::parse("2024-07-21", "23:00", 9.0).unwrap(),
        &Place::TSUSHIMA,
    );
    assert!(night.sun.elevation_deg < -10.0 && night.moon.elevation_deg > 15.0);
    assert!(night.moon.phase_angle_deg < 10.0);
    assert!(
        (0.25..0.4).contains(&night.moon.extraterrestrial_lux),
        "{night:?}"
    );
}

#[test]
fn julian_day_and_delta_t() {
    // Meeus's example 7.a: 1957 October 4.81 UT (Sputnik 1) is JD 2436116.31.
    let sputnik = DateTime::new(1957, 10, 4, 19, 26, 24, 0.0).unwrap();
    assert!((sputnik.julian_day_ut() - 2436116.31).abs() < 1e-6);
    // The same instant in another zone is the same Julian day.
    let tokyo = DateTime::new(1957, 10, 5, 4, 26, 24, 9.0).unwrap();
    assert!((tokyo.julian_day_ut() - sputnik.julian_day_ut()).abs() < 1e-9);
    // J2000.0 is 2000-01-01 12:00 TT, JD 2451545.0 (TT); at 12:00 UT it is JD 2451545.0 (UT).
    let j2000 = DateTime::new(2000, 1, 1, 12, 0, 0, 0.0).unwrap();
    assert_eq!(j2000.julian_day_ut(), 2451545.0);

    // ΔT against the observed values (seconds; Espenak & Meeus's table of historical ΔT from
    // IERS / USNO): the polynomials fit them within a second.
    for (year, observed) in [
        (1900.0, -2.72),
        (1950.0, 29.15),
        (1980.0, 50.54),
        (2000.0, 63.83),
    ] {
        let dt = delta_t_seconds(year);
        assert!((dt - observed).abs() < 1.0, "{year}: {dt} vs {observed}");
    }
    // The pieces join: no jump over half a second at their boundaries (a mistyped coefficient
    // would make one).
    for y in [1900.0, 1920.0, 1941.0, 1961.0, 1986.0, 2005.0, 2050.0] {
        let jump = delta_t_seconds(y + 1e-9) - delta_t_seconds(y - 1e-9);
        assert!(jump.abs() < 0.5, "ΔT jumps by {jump} s at {y}");
    }
}
