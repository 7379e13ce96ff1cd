//! The sun's geocentric apparent place, nutation and sidereal time, after NREL's Solar
//! Position Algorithm (Reda & Andreas 2004, NREL/TP-560-34302), whose Earth series is a
//! truncation of VSOP87 (Bretagnon & Francou 1988) and whose nutation is the 63-term
//! IAU 1980 series. Stated accuracy ±0.0003° over −2000..6000.

use super::spa_data::*;

/// Julian day of J2000.0.
pub(super) const J2000: f64 = 2451545.0;

/// Nutation and the true obliquity for one instant, radians.
#[derive(Debug, Clone, Copy)]
pub(super) struct Nutation {
    /// Nutation in longitude Δψ.
    pub dpsi: f64,
    /// True obliquity of the ecliptic ε = ε₀ + Δε.
    pub epsilon: f64,
}

/// Nutation (IAU 1980, 63 terms) and the true obliquity at `jce` Julian centuries of TT from
/// J2000.
pub(super) fn nutation(jce: f64) -> Nutation {
    let t = jce;
    let poly = |c: [f64; 4]| c[0] + t * (c[1] + t * (c[2] + t * c[3]));
    // Mean elongation of the Moon, mean anomalies of the Sun and the Moon, the Moon's argument
    // of latitude and the longitude of its ascending node, degrees (SPA eqs. 15-19).
    let x = [
        poly([297.85036, 445267.111480, -0.0019142, 1.0 / 189474.0]),
        poly([357.52772, 35999.050340, -0.0001603, -1.0 / 300000.0]),
        poly([134.96298, 477198.867398, 0.0086972, 1.0 / 56250.0]),
        poly([93.27191, 483202.017538, -0.0036825, 1.0 / 327270.0]),
        poly([125.04452, -1934.136261, 0.0020708, 1.0 / 450000.0]),
    ];
    let (mut dpsi, mut deps) = (0.0, 0.0);
    for (args, c) in NUTATION_ARGS.iter().zip(NUTATION_COEFFS.iter()) {
        let arg: f64 = args
            .iter()
            .zip(x.iter())
            .map(|(&k, &xi)| k as f64 * xi)
            .sum::<f64>()
            .to_radians();
        dpsi += (c[0] + c[1] * t) * arg.sin();
        deps += (c[2] + c[3] * t) * arg.cos();
    }
    let arcsec_1e4 = |v: f64| (v / 36_000_000.0).to_radians();
    // Mean obliquity (Laskar 1986, as in SPA eq. 24), U in units of 10 000 years.
    let u = jce / 100.0;
    let eps0_arcsec = [
        84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67, -39.05, 7.12, 27.87, 5.79, 2.45,
    ]
    .iter()
    .rev()
    .fold(0.0, |acc, c| acc * u + c);
    Nutation {
        dpsi: arcsec_1e4(dpsi),
        epsilon: (eps0_arcsec / 3600.0).to_radians() + arcsec_1e4(deps),
    }
}

/// Σ A cos(B + C τ) over a table of rows `[A, B, C]`.
fn series(rows: &[[f64; 3]], tau: f64) -> f64 {
    rows.iter().map(|r| r[0] * (r[1] + r[2] * tau).cos()).sum()
}

/// Σ Xᵢ τⁱ / 1e8 for the tables X₀, X₁, ….
fn vsop(tables: &[&[[f64; 3]]], tau: f64) -> f64 {
    tables
        .iter()
        .rev()
        .fold(0.0, |acc, rows| acc * tau + series(rows, tau))
        / 1e8
}

/// The Earth's heliocentric ecliptic longitude L and latitude B (radians, mean equinox of
/// date) and radius vector R (au) at `jme` Julian millennia of TT from J2000.
pub(super) fn earth_heliocentric(jme: f64) -> (f64, f64, f64) {
    let l = vsop(&[&L0, &L1, &L2, &L3, &L4, &L5], jme);
    let b = vsop(&[&B0, &B1], jme);
    let r = vsop(&[&R0, &R1, &R2, &R3, &R4], jme);
    (l.rem_euclid(std::f64::consts::TAU), b, r)
}

/// Geocentric apparent place of the sun.
#[derive(Debug, Clone, Copy)]
pub(super) struct ApparentSun {
    /// Apparent ecliptic longitude λ (nutation and aberration applied), radians.
    pub longitude: f64,
    /// Ecliptic latitude β, radians.
    pub latitude: f64,
    /// Distance, au.
    pub distance_au: f64,
}

/// The sun's apparent geocentric ecliptic place at `jce` Julian centuries of TT from J2000.
pub(super) fn apparent_sun(jce: f64, nut: &Nutation) -> ApparentSun {
    let (l, b, r) = earth_heliocentric(jce / 10.0);
    // Annual aberration, −20.4898″ / R (SPA eq. 25).
    let aberration = (-20.4898 / (3600.0 * r)).to_radians();
    ApparentSun {
        longitude: l + std::f64::consts::PI + nut.dpsi + aberration,
        latitude: -b,
        distance_au: r,
    }
}

/// Greenwich apparent sidereal time, radians, for a Julian day on the UT scale (SPA eqs.
/// 12-14; Meeus eq. 12.4 plus the equation of the equinoxes Δψ cos ε).
pub(super) fn apparent_sidereal_time(jd_ut: f64, nut: &Nutation) -> f64 {
    let d = jd_ut - J2000;
    let jc = d / 36525.0;
    let mean_deg =
        280.46061837 + 360.98564736629 * d + 0.000387933 * jc * jc - jc * jc * jc / 38710000.0;
    (mean_deg.rem_euclid(360.0)).to_radians() + nut.dpsi * nut.epsilon.cos()
}

/// Ecliptic (λ, β) to equatorial (α, δ) with obliquity ε, radians (Meeus eqs. 13.3, 13.4).
pub(super) fn ecliptic_to_equatorial(lambda: f64, beta: f64, epsilon: f64) -> (f64, f64) {
    let (sl, cl) = lambda.sin_cos();
    let (se, ce) = epsilon.sin_cos();
    let alpha = (sl * ce - beta.tan() * se).atan2(cl);
    let delta = (beta.sin() * ce + beta.cos() * se * sl)
        .clamp(-1.0, 1.0)
        .asin();
    (alpha.rem_euclid(std::f64::consts::TAU), delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    // The worked example of Reda & Andreas (2004), table A5.1: 2003-10-17 12:30:30 at UTC−7,
    // ΔT = 67 s. Their published intermediate values, to their printed digits.
    #[test]
    fn spa_worked_example() {
        let when = crate::astro::DateTime::new(2003, 10, 17, 12, 30, 30, -7.0).unwrap();
        let jd = when.julian_day_ut();
        assert!((jd - 2452930.312847).abs() < 1e-6);
        let jde = jd + 67.0 / 86400.0;
        let jce = (jde - J2000) / 36525.0;
        let (l, b, r) = earth_heliocentric(jce / 10.0);
        assert!((l.to_degrees() - 24.0182616917).abs() < 2e-9);
        assert!((b.to_degrees() - -0.0001011219).abs() < 2e-10);
        assert!((r - 0.9965422974).abs() < 2e-10);
        let nut = nutation(jce);
        assert!((nut.dpsi.to_degrees() - -0.00399840).abs() < 2e-8);
        assert!((nut.epsilon.to_degrees() - 23.440465).abs() < 2e-6);
        let sun = apparent_sun(jce, &nut);
        assert!((sun.longitude.to_degrees() - 204.0085519281).abs() < 2e-9);
        let (ra, dec) = ecliptic_to_equatorial(sun.longitude, sun.latitude, nut.epsilon);
        assert!((ra.to_degrees() - 202.22741).abs() < 2e-5);
        assert!((dec.to_degrees() - -9.31434).abs() < 2e-5);
        let gast = apparent_sidereal_time(jd, &nut);
        let h = (gast.to_degrees() - 105.1786 - ra.to_degrees()).rem_euclid(360.0);
        assert!((h - 11.105900).abs() < 2e-5, "{h}");
    }
}
