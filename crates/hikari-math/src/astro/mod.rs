//! The sun and the moon seen from a place on the Earth at a date and time: topocentric
//! azimuth and elevation, distance, the moon's phase, the bodies' illuminance above the
//! atmosphere and their direction in hikari's world axes. Pure `f64` math.
//!
//! # Algorithms
//!
//! * Time: the local date and time minus the UTC offset is read as UT (UT1 = UTC). TT = UT +
//!   ΔT, ΔT from Espenak & Meeus's polynomials ([`delta_t_seconds`]).
//! * Sun: NREL's Solar Position Algorithm (Reda & Andreas 2004): the Earth's heliocentric
//!   place from their truncated VSOP87 tables, 63-term nutation, annual aberration.
//! * Moon: Meeus (1998) chapter 47, the truncated ELP-2000/82 series, plus the same nutation.
//! * Both: apparent sidereal time (Meeus eq. 12.4 with the equation of the equinoxes),
//!   parallax as the exact vector difference between the body's and the observer's
//!   geocentric positions (WGS84, sea level), then azimuth and elevation. Elevations are
//!   geometric: no refraction.
//! * Moon phase: phase angle and illuminated fraction (1 + cos i) / 2 at the Earth's centre
//!   (Meeus ch. 48, from the geocentric vectors), the almanac convention; the illuminance
//!   uses the phase angle and distance seen from the place.
//!
//! Measured against PyEphem (`tools/ephemeris_reference.py`, 102 cases over 1900–2100): see
//! `docs/sun-and-moon.md`.
//!
//! # Axes
//!
//! [`SunPosition::direction`] and [`MoonPosition::direction`] point from the place towards
//! the body in hikari's world axes (as hikari-scene's scenes): Y up, +Z north,
//! −X east, +X west. For azimuth A (clockwise from north) and elevation e the direction is
//! `(−sin A cos e, sin e, cos A cos e)`.
//!
//! ```
//! use hikari_math::astro::{sun_and_moon, DateTime, Place};
//!
//! let when = DateTime::parse("2024-07-21", "12:00", 9.0)?;
//! let sky = sun_and_moon(&when, &Place::TSUSHIMA);
//! assert!(sky.sun.elevation_deg > 70.0); // near the summer noon at 34.4° N
//! assert!(sky.moon.illuminated_fraction > 0.99); // full that day
//! # Ok::<(), hikari_math::astro::AstroError>(())
//! ```

pub mod calendar;
pub mod illuminance;
mod moon;
mod moon_data;
mod spa_data;
mod sun;
pub mod time;
mod topocentric;

use glam::Vec3;

pub use illuminance::{
    SOLAR_ILLUMINANCE_CONSTANT_LUX, moon_extraterrestrial_lux, sun_extraterrestrial_lux,
};
pub use time::{AstroError, DateTime, Place, delta_t_seconds};

/// Kilometres per astronomical unit (IAU 2012).
pub const AU_KM: f64 = 149_597_870.7;

/// The sun seen from the place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Azimuth, degrees clockwise from north, in [0, 360).
    pub azimuth_deg: f64,
    /// Topocentric geometric elevation (no refraction), degrees, in [−90, 90].
    pub elevation_deg: f64,
    /// Distance from the Earth's centre, au.
    pub distance_au: f64,
    /// Illuminance at the top of the atmosphere on a plane facing the sun, lux.
    pub extraterrestrial_lux: f64,
    /// Unit vector towards the sun in world axes (Y up, +Z north, −X east).
    pub direction: Vec3,
}

/// The moon seen from the place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoonPosition {
    /// Azimuth, degrees clockwise from north, in [0, 360).
    pub azimuth_deg: f64,
    /// Topocentric geometric elevation (no refraction), degrees, in [−90, 90].
    pub elevation_deg: f64,
    /// Distance from the place to the moon's centre, km.
    pub distance_km: f64,
    /// Distance between the Earth's and the moon's centres, km.
    pub geocentric_distance_km: f64,
    /// Sun–moon–Earth angle at the moon, degrees (0 = full, 180 = new), geocentric.
    pub phase_angle_deg: f64,
    /// Illuminated fraction of the disk, 0 to 1, geocentric.
    pub illuminated_fraction: f64,
    /// Illuminance at the top of the atmosphere on a plane facing the moon, lux (from the
    /// phase angle and distance seen from the place).
    pub extraterrestrial_lux: f64,
    /// Unit vector towards the moon in world axes (Y up, +Z north, −X east).
    pub direction: Vec3,
}

/// Both bodies for one instant and place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunAndMoon {
    /// The sun.
    pub sun: SunPosition,
    /// The moon.
    pub moon: MoonPosition,
    /// Julian day of the instant, UT.
    pub julian_day_ut: f64,
    /// ΔT = TT − UT used, seconds.
    pub delta_t_s: f64,
}

/// World direction (Y up, +Z north, −X east) from (east, north, up) components.
fn world(enu: [f64; 3]) -> Vec3 {
    Vec3::new(-enu[0] as f32, enu[2] as f32, enu[1] as f32).normalize_or(Vec3::Y)
}

/// The sun and the moon at `when`, seen from `place` (see the module docs for the methods).
/// Inputs are validated at construction, so this cannot fail; outputs are finite.
pub fn sun_and_moon(when: &DateTime, place: &Place) -> SunAndMoon {
    let jd = when.julian_day_ut();
    let delta_t_s = delta_t_seconds(time::decimal_year(jd));
    let jce = (jd + delta_t_s / 86400.0 - sun::J2000) / 36525.0;
    let lat = place.latitude_deg().to_radians();
    let lon = place.longitude_deg().to_radians();

    let nut = sun::nutation(jce);
    let local_sidereal = sun::apparent_sidereal_time(jd, &nut) + lon;

    // Sun: geocentric apparent place, then seen from the place.
    let s = sun::apparent_sun(jce, &nut);
    let (sun_ra, sun_dec) = sun::ecliptic_to_equatorial(s.longitude, s.latitude, nut.epsilon);
    let sun_km = s.distance_au * AU_KM;
    let sun_geo = topocentric::geocentric(local_sidereal - sun_ra, sun_dec, sun_km);
    let sun_top = topocentric::topocentric(&sun_geo, lat);
    let (sun_az, sun_el, sun_enu) = topocentric::horizon(&sun_top, lat);

    // Moon: nutation in longitude makes the mean-equinox longitude apparent. Its aberration
    // and light time nearly cancel (both come from the Earth's and the Moon's common motion),
    // leaving under 1″.
    let m = moon::geocentric_moon(jce);
    let (moon_ra, moon_dec) =
        sun::ecliptic_to_equatorial(m.longitude + nut.dpsi, m.latitude, nut.epsilon);
    let moon_geo = topocentric::geocentric(local_sidereal - moon_ra, moon_dec, m.distance_km);
    let moon_top = topocentric::topocentric(&moon_geo, lat);
    let (moon_az, moon_el, moon_enu) = topocentric::horizon(&moon_top, lat);

    // Phase angle: at the moon, between the directions to the sun and to the viewer (the
    // Earth's centre for the almanac value, the place for the light it receives).
    let phase_angle = |sun: &[f64; 3], moon: &[f64; 3]| {
        let to_sun = [sun[0] - moon[0], sun[1] - moon[1], sun[2] - moon[2]];
        let to_viewer = [-moon[0], -moon[1], -moon[2]];
        topocentric::angle_between(&to_sun, &to_viewer)
    };
    let i_geo = phase_angle(&sun_geo, &moon_geo);
    let i_top = phase_angle(&sun_top, &moon_top);

    SunAndMoon {
        sun: SunPosition {
            azimuth_deg: sun_az.to_degrees(),
            elevation_deg: sun_el.to_degrees(),
            distance_au: s.distance_au,
            extraterrestrial_lux: sun_extraterrestrial_lux(s.distance_au),
            direction: world(sun_enu),
        },
        moon: MoonPosition {
            azimuth_deg: moon_az.to_degrees(),
            elevation_deg: moon_el.to_degrees(),
            distance_km: topocentric::length(&moon_top),
            geocentric_distance_km: m.distance_km,
            phase_angle_deg: i_geo.to_degrees(),
            illuminated_fraction: 0.5 * (1.0 + i_geo.cos()),
            extraterrestrial_lux: moon_extraterrestrial_lux(
                i_top.to_degrees(),
                topocentric::length(&moon_top),
            ),
            direction: world(moon_enu),
        },
        julian_day_ut: jd,
        delta_t_s,
    }
}
