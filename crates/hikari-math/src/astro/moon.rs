//! The Moon's geocentric place from Meeus, *Astronomical Algorithms* (2nd ed., 1998),
//! chapter 47: the truncated ELP-2000/82 series (tables 47.A and 47.B) with the additive
//! terms for Venus, Jupiter and the Earth's flattening. About 10″ in longitude and 4″ in
//! latitude.

use super::moon_data::{LATITUDE, LONGITUDE_DISTANCE};

/// Geocentric ecliptic place of the Moon.
#[derive(Debug, Clone, Copy)]
pub(super) struct GeocentricMoon {
    /// Ecliptic longitude, mean equinox of date (no nutation), radians.
    pub longitude: f64,
    /// Ecliptic latitude, radians.
    pub latitude: f64,
    /// Distance between the centres of the Earth and the Moon, km.
    pub distance_km: f64,
}

/// Polynomial in `t` with coefficients from the constant term up.
fn poly(t: f64, c: &[f64]) -> f64 {
    c.iter().rev().fold(0.0, |acc, k| acc * t + k)
}

/// The Moon at `t` Julian centuries of TT from J2000.
pub(super) fn geocentric_moon(t: f64) -> GeocentricMoon {
    // Mean longitude, mean elongation, the Sun's and the Moon's mean anomalies and the
    // argument of latitude, degrees (Meeus eqs. 47.1-47.5).
    let lp = poly(
        t,
        &[
            218.3164477,
            481267.88123421,
            -0.0015786,
            1.0 / 538841.0,
            -1.0 / 65194000.0,
        ],
    );
    let d = poly(
        t,
        &[
            297.8501921,
            445267.1114034,
            -0.0018819,
            1.0 / 545868.0,
            -1.0 / 113065000.0,
        ],
    );
    let m = poly(
        t,
        &[357.5291092, 35999.0502909, -0.0001536, 1.0 / 24490000.0],
    );
    let mp = poly(
        t,
        &[
            134.9633964,
            477198.8675055,
            0.0087414,
            1.0 / 69699.0,
            -1.0 / 14712000.0,
        ],
    );
    let f = poly(
        t,
        &[
            93.2720950,
            483202.0175233,
            -0.0036539,
            -1.0 / 3526000.0,
            1.0 / 863310000.0,
        ],
    );
    let a1 = (119.75 + 131.849 * t).to_radians();
    let a2 = (53.09 + 479264.290 * t).to_radians();
    let a3 = (313.45 + 481266.484 * t).to_radians();
    // The Earth's orbital eccentricity decreases: terms in M scale by E per unit of |M|.
    let e = 1.0 - 0.002516 * t - 0.0000074 * t * t;
    let args = [d, m, mp, f].map(|v| v.rem_euclid(360.0).to_radians());
    let argument = |k: &[i8; 4]| -> (f64, f64) {
        let a: f64 = k.iter().zip(args.iter()).map(|(&n, &x)| n as f64 * x).sum();
        (a, e.powi(k[1].unsigned_abs() as i32))
    };

    let (mut sl, mut sr, mut sb) = (0.0, 0.0, 0.0);
    for (k, l, r) in LONGITUDE_DISTANCE.iter() {
        let (a, scale) = argument(k);
        sl += *l as f64 * scale * a.sin();
        sr += *r as f64 * scale * a.cos();
    }
    for (k, b) in LATITUDE.iter() {
        let (a, scale) = argument(k);
        sb += *b as f64 * scale * a.sin();
    }
    let (lpr, fr, mpr) = (lp.to_radians(), args[3], args[2]);
    sl += 3958.0 * a1.sin() + 1962.0 * (lpr - fr).sin() + 318.0 * a2.sin();
    sb += -2235.0 * lpr.sin()
        + 382.0 * a3.sin()
        + 175.0 * (a1 - fr).sin()
        + 175.0 * (a1 + fr).sin()
        + 127.0 * (lpr - mpr).sin()
        - 115.0 * (lpr + mpr).sin();

    GeocentricMoon {
        longitude: (lp + sl / 1e6).rem_euclid(360.0).to_radians(),
        latitude: (sb / 1e6).to_radians(),
        distance_km: 385000.56 + sr / 1000.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Meeus's example 47.a: 1992 April 12, 0h TD (JDE 2448724.5), his published results.
    #[test]
    fn meeus_example_47a() {
        let t = (2448724.5 - 2451545.0) / 36525.0;
        let m = geocentric_moon(t);
        assert!((m.longitude.to_degrees() - 133.162655).abs() < 2e-6);
        assert!((m.latitude.to_degrees() - -3.229126).abs() < 2e-6);
        assert!((m.distance_km - 368409.7).abs() < 0.1);
    }
}
