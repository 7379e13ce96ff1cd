//! The sun (or the moon) for a time of day: a simple stand-in until a real solar position and
//! atmosphere model arrives.
//!
//! # Axes
//!
//! Y is up, -Z is south, +Z north, -X east and +X west. (Right-handed with Y up: standing
//! facing south (-Z), +X is on the right, which is west.)
//!
//! # Model
//!
//! The sun moves along the equinox path at latitude 30° north: it rises due east at 06:00,
//! culminates due south at 12:00 at 60° elevation and sets due west at 18:00. With
//! θ = π (hours - 6) / 12, its direction is
//!
//! `cos θ · east + sin θ · (cos 60° · south + sin 60° · up)`,
//!
//! a great circle, so the elevation is `asin(sin θ · sin 60°)`.
//!
//! Illuminance ([`Sun::illuminance_lux`], on a surface facing the sun, so without the cosine
//! of the elevation: the renderer applies that to each surface) is
//! [`Sun::DEFAULT_LUX`] at the zenith times the direct-beam transmittance of the atmosphere
//! relative to the zenith's, `T(m) / T(1)`, with Meinel and Meinel's clear-sky
//! `T(m) = 0.7^(m^0.678)` and the air mass `m` of Kasten and Young (1989),
//! `m = 1 / (sin h + 0.50572 (h + 6.07995°)^-1.6364)` (h in degrees in the second term), which
//! stays finite at the horizon (m ≈ 38). That gives about 96 000 lux at noon and 2 000 lux at
//! sunrise. The sky's own light (twilight) is not modelled: at the horizon the light switches
//! from sun to moon.
//!
//! Colour: Rayleigh extinction `exp(-τ_c (m - 1))` per channel, relative to the zenith (so the
//! zenith sun is white, like [`Sun::default`]), with τ = 0.0965 (550 nm / λ_c)^4 (Rayleigh
//! optical depth of a sea-level atmosphere at 550 nm, λ^-4 law) at λ = 612, 549 and 465 nm for
//! R, G and B; then scaled to luminance 1. Reddens strongly towards the horizon.
//!
//! Night (sun below the horizon): the moon, placed opposite the sun (so it is up all night),
//! [`MOON_LUX`] at the zenith with the same extinction, and a slightly bluish colour. (Real
//! moonlight is, if anything, slightly redder than sunlight; the blue is the usual rendering
//! convention for how night scenes look to dark-adapted eyes.)

use glam::Vec3;
use thiserror::Error;

use crate::Sun;

/// Moonlight at the zenith, lux (a full moon high in a clear sky gives a few tenths of a lux).
pub const MOON_LUX: f32 = 0.3;

/// Elevation of the sun at noon, degrees.
pub const NOON_ELEVATION_DEG: f32 = 60.0;

const EAST: Vec3 = Vec3::NEG_X;
const SOUTH: Vec3 = Vec3::NEG_Z;

#[derive(Debug, Error, PartialEq)]
#[error("time `{text}`: {why}; expected HH:MM from 00:00 to 23:59")]
pub struct TimeError {
    pub text: String,
    pub why: String,
}

/// Parses "HH:MM" (one or two hour digits, two minute digits, 00:00 to 23:59) into hours.
pub fn parse_time(s: &str) -> Result<f32, TimeError> {
    let err = |why: &str| TimeError {
        text: s.into(),
        why: why.into(),
    };
    let (h, m) = s.split_once(':').ok_or_else(|| err("no `:`"))?;
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    if !(digits(h) && h.len() <= 2) {
        return Err(err("the hour must be one or two digits"));
    }
    if !(digits(m) && m.len() == 2) {
        return Err(err("the minutes must be two digits"));
    }
    let (h, m): (u32, u32) = (
        h.parse().map_err(|_| err("bad hour"))?,
        m.parse().map_err(|_| err("bad minutes"))?,
    );
    if h > 23 {
        return Err(err("the hour is past 23"));
    }
    if m > 59 {
        return Err(err("the minutes are past 59"));
    }
    Ok(h as f32 + m as f32 / 60.0)
}

/// Direction towards the sun at `hours` (any real number, taken modulo 24), unit length; below
/// the horizon at night.
pub fn sun_direction(hours: f32) -> Vec3 {
    let hours = if hours.is_finite() {
        hours.rem_euclid(24.0)
    } else {
        12.0
    };
    let theta = std::f32::consts::PI * (hours - 6.0) / 12.0;
    let noon = NOON_ELEVATION_DEG.to_radians();
    let arc = SOUTH * noon.cos() + Vec3::Y * noon.sin();
    let d = EAST * theta.cos() + arc * theta.sin();
    // Exactly on the horizon at 06:00 and 18:00 despite the rounding of θ, so that both are
    // the sun (and the day is symmetric about noon).
    if d.y.abs() < 1e-6 {
        d.with_y(0.0).normalize()
    } else {
        d.normalize()
    }
}

/// Kasten and Young's (1989) relative air mass for an elevation in radians (clamped at 0).
fn air_mass(elevation: f32) -> f32 {
    let h = elevation.max(0.0);
    1.0 / (h.sin() + 0.50572 * (h.to_degrees() + 6.07995).powf(-1.6364))
}

/// Meinel and Meinel's clear-sky direct-beam transmittance relative to the zenith's.
fn relative_transmittance(m: f32) -> f32 {
    0.7f32.powf(m.powf(0.678)) / 0.7
}

fn unit_luminance(c: Vec3) -> Vec3 {
    c / c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The sun at `hours` (e.g. from [`parse_time`]), or the moon when the sun is below the
/// horizon; see the module documentation for the model. Non-finite hours are read as noon.
pub fn sun_at(hours: f32) -> Sun {
    let d = sun_direction(hours);
    let up = d.y >= 0.0;
    let direction = if up { d } else { -d };
    let m = air_mass(direction.y.clamp(-1.0, 1.0).asin());
    let t = relative_transmittance(m);
    if up {
        let tau = Vec3::new(612.0, 549.0, 465.0).map(|l| 0.0965 * (550.0 / l).powi(4));
        Sun {
            direction,
            illuminance_lux: Sun::DEFAULT_LUX * t,
            color: unit_luminance((-tau * (m - 1.0)).exp()),
        }
    } else {
        Sun {
            direction,
            illuminance_lux: MOON_LUX * t,
            color: unit_luminance(Vec3::new(0.85, 0.95, 1.15)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn elevation_deg(s: &Sun) -> f32 {
        s.direction.y.asin().to_degrees()
    }

    #[test]
    fn parses_times_and_names_bad_text() {
        assert_eq!(parse_time("00:00"), Ok(0.0));
        assert_eq!(parse_time("12:30"), Ok(12.5));
        assert_eq!(parse_time("7:15"), Ok(7.25));
        assert!((parse_time("23:59").unwrap() - (23.0 + 59.0 / 60.0)).abs() < 1e-6);
        for bad in [
            "24:00", "12:60", "12", "", "ab:cd", "12:5", "12:345", "-1:00", "123:00", " 1:00",
            "12:30:00", "+1:00",
        ] {
            let e = parse_time(bad).unwrap_err();
            assert!(e.to_string().contains(&format!("`{bad}`")), "{e}");
        }
    }

    #[test]
    fn sun_rises_east_culminates_south_at_60_degrees_and_sets_west() {
        let rise = sun_at(6.0);
        assert!(
            rise.direction.abs_diff_eq(Vec3::NEG_X, 1e-6),
            "{:?}",
            rise.direction
        );
        let set = sun_direction(18.0);
        assert!(set.abs_diff_eq(Vec3::X, 1e-5), "{set}");
        let noon = sun_at(12.0);
        assert!((elevation_deg(&noon) - 60.0).abs() < 1e-3);
        assert!(noon.direction.x.abs() < 1e-6 && noon.direction.z < 0.0);
        // Morning sun in the east (-x), afternoon in the west.
        assert!(sun_direction(9.0).x < 0.0 && sun_direction(15.0).x > 0.0);
    }

    #[test]
    fn directions_are_unit_and_illuminance_rises_to_noon() {
        let mut last = 0.0;
        for k in 0..=36 {
            let s = sun_at(6.0 + k as f32 / 6.0);
            assert!(s.illuminance_lux > last, "at step {k}");
            last = s.illuminance_lux;
        }
        for k in 0..24 * 12 {
            let h = k as f32 / 12.0;
            let s = sun_at(h);
            assert!((s.direction.length() - 1.0).abs() < 1e-5);
            assert!(s.direction.y >= 0.0, "the light comes from above at {h}");
            let lum = s.color.dot(Vec3::new(0.2126, 0.7152, 0.0722));
            assert!((lum - 1.0).abs() < 1e-4);
            assert!(s.illuminance_lux.is_finite() && s.illuminance_lux > 0.0);
            // Symmetric about noon.
            let mirror = sun_at(24.0 - h);
            assert!((mirror.illuminance_lux - s.illuminance_lux).abs() <= 1e-3 * s.illuminance_lux);
        }
        // Noon: 100 klx scaled by the transmittance at air mass 1/sin 60° (independently:
        // 0.7^(1.1547^0.678) / 0.7 = 0.9656).
        let noon = sun_at(12.0).illuminance_lux;
        assert!((noon / 100_000.0 - 0.9656).abs() < 2e-3, "{noon}");
        // Low sun is much dimmer and redder.
        let low = sun_at(6.5);
        assert!(low.illuminance_lux < 0.5 * noon);
        let warmth = |s: &Sun| s.color.x / s.color.z;
        assert!(warmth(&low) > 2.0 * warmth(&sun_at(12.0)));
    }

    #[test]
    fn night_is_moonlight() {
        for h in [0.0, 2.5, 19.0, 23.5] {
            let s = sun_at(h);
            assert!(
                s.illuminance_lux > 0.0 && s.illuminance_lux <= MOON_LUX,
                "{h}"
            );
            assert!(s.direction.y > 0.0);
            assert!(s.color.z > s.color.x, "bluish");
            // Opposite the sun.
            assert!(s.direction.abs_diff_eq(-sun_direction(h), 1e-6));
        }
        assert!((sun_at(0.0).illuminance_lux - MOON_LUX * 0.9656).abs() < 1e-3);
        assert!(sun_at(f32::NAN).illuminance_lux > 50_000.0);
    }
}
