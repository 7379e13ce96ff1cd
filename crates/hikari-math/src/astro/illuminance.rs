//! Illuminance of the sun and the full-disk moon at the top of the atmosphere, on a plane
//! facing the body (normal incidence). The atmosphere's transmittance and the cosine of the
//! elevation are the caller's.

/// Extraterrestrial solar illuminance at 1 au, lux: the value of the IES Lighting Handbook and
/// CIE daylight work (127.5 klx). Darula, Kittler & Gueymard (2005, Solar Energy 79) derive a
/// higher value, about 133 klx, from newer extraterrestrial spectra; the two differ by 4 %.
pub const SOLAR_ILLUMINANCE_CONSTANT_LUX: f64 = 127_500.0;

/// Mean Earth–Moon distance used by Krisciunas & Schaefer (1991), km.
pub const MOON_MEAN_DISTANCE_KM: f64 = 384_400.0;

/// Lux per foot-candle.
const LUX_PER_FOOTCANDLE: f64 = 10.763_910_416_709_722;

/// The sun's illuminance at the top of the atmosphere, lux, at `distance_au` from it.
pub fn sun_extraterrestrial_lux(distance_au: f64) -> f64 {
    SOLAR_ILLUMINANCE_CONSTANT_LUX / (distance_au * distance_au)
}

/// The Moon's visual magnitude at the mean distance for a phase angle in degrees (0 = full),
/// Krisciunas & Schaefer (1991, PASP 103, after Allen's table):
/// m = −12.73 + 0.026 |α| + 4·10⁻⁹ α⁴. Includes the opposition surge near full; no earthshine.
pub fn moon_magnitude(phase_angle_deg: f64) -> f64 {
    let a = phase_angle_deg.abs().min(180.0);
    -12.73 + 0.026 * a + 4e-9 * a.powi(4)
}

/// The Moon's illuminance at the top of the atmosphere, lux, for a phase angle in degrees and
/// a distance in km: Krisciunas & Schaefer's I* = 10^(−0.4 (m + 16.57)) foot-candles, scaled
/// by the inverse square of the distance. About 0.31 lux for a full moon at the mean distance
/// (0.27 to 0.36 from apogee to perigee); 0.03 lux at quarter.
pub fn moon_extraterrestrial_lux(phase_angle_deg: f64, distance_km: f64) -> f64 {
    let fc = 10f64.powf(-0.4 * (moon_magnitude(phase_angle_deg) + 16.57));
    let r = MOON_MEAN_DISTANCE_KM / distance_km;
    fc * LUX_PER_FOOTCANDLE * r * r
}
