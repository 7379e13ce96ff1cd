//! From a geocentric apparent place to the place seen from the observer: parallax (as a
//! vector difference, exact) and horizon coordinates.

/// WGS84 equatorial radius, km.
pub const EARTH_EQUATORIAL_RADIUS_KM: f64 = 6378.137;
/// WGS84 polar-to-equatorial axis ratio, 1 − f with f = 1 / 298.257223563.
const AXIS_RATIO: f64 = 1.0 - 1.0 / 298.257223563;

/// A body relative to the observer, in the hour-angle frame: x towards the local meridian on
/// the equator, y towards the east point, z towards the north celestial pole; km.
pub(super) type HourAngleVector = [f64; 3];

/// The observer's geocentric position in the hour-angle frame, km (Meeus ch. 11: ρ sin φ′,
/// ρ cos φ′ from the geodetic latitude; sea level).
pub(super) fn observer_position(latitude: f64) -> HourAngleVector {
    let u = (AXIS_RATIO * latitude.tan()).atan();
    // tan blows up at the poles; there u = ±90° exactly.
    let u = if latitude.abs() >= std::f64::consts::FRAC_PI_2 - 1e-12 {
        latitude
    } else {
        u
    };
    [
        EARTH_EQUATORIAL_RADIUS_KM * u.cos(),
        0.0,
        EARTH_EQUATORIAL_RADIUS_KM * AXIS_RATIO * u.sin(),
    ]
}

/// Geocentric vector of a body at hour angle `h` (radians, west positive), declination `dec`
/// and distance `distance_km`.
pub(super) fn geocentric(h: f64, dec: f64, distance_km: f64) -> HourAngleVector {
    // The hour angle grows westward, so the east component is −sin h.
    [
        distance_km * dec.cos() * h.cos(),
        -distance_km * dec.cos() * h.sin(),
        distance_km * dec.sin(),
    ]
}

/// The same body seen from an observer at geodetic `latitude` (on the meridian h = 0).
pub(super) fn topocentric(geocentric: &HourAngleVector, latitude: f64) -> HourAngleVector {
    let o = observer_position(latitude);
    [
        geocentric[0] - o[0],
        geocentric[1] - o[1],
        geocentric[2] - o[2],
    ]
}

/// Horizon coordinates of a topocentric vector for an observer at geodetic `latitude`:
/// `(azimuth, elevation)` in radians, azimuth clockwise from north in [0, 2π), and the
/// (east, north, up) unit vector.
pub(super) fn horizon(v: &HourAngleVector, latitude: f64) -> (f64, f64, [f64; 3]) {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let [x, y, z] = [v[0] / n, v[1] / n, v[2] / n];
    let (sp, cp) = latitude.sin_cos();
    let up = cp * x + sp * z;
    let north = -sp * x + cp * z;
    let east = y;
    let azimuth = east.atan2(north).rem_euclid(std::f64::consts::TAU);
    let elevation = up.atan2(east.hypot(north));
    (azimuth, elevation, [east, north, up])
}

/// Length of a vector, km.
pub(super) fn length(v: &HourAngleVector) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Angle between two vectors, radians.
pub(super) fn angle_between(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    // atan2 of |a × b| and a · b stays accurate near 0 and π, where acos does not.
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    length(&c).atan2(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    // Reda & Andreas (2004), table A5.1: at latitude 39.742476°, 1830.14 m, the sun at
    // H = 11.105900°, δ = −9.31434°, R = 0.9965422974 au is seen at H′ = 11.10629°,
    // δ′ = −9.316179°, elevation 39.872046° (no refraction), azimuth 194.340241°. Sea level
    // here instead of 1830 m moves δ′ by ~1e-6°.
    #[test]
    fn spa_worked_example_topocentric() {
        let lat = 39.742476f64.to_radians();
        let g = geocentric(
            11.105900f64.to_radians(),
            (-9.31434f64).to_radians(),
            0.9965422974 * 149597870.7,
        );
        let v = topocentric(&g, lat);
        let (az, el, _) = horizon(&v, lat);
        assert!(
            (el.to_degrees() - 39.872046).abs() < 3e-5,
            "{}",
            el.to_degrees()
        );
        assert!(
            (az.to_degrees() - 194.340241).abs() < 3e-5,
            "{}",
            az.to_degrees()
        );
    }
}
