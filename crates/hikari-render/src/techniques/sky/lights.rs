//! The sun and the moon for a date, time and place: where they are (hikari-math's `astro`),
//! how much light reaches the ground through the atmosphere (its transmittance, integrated
//! along the ray to space in the atmosphere's working space, no table needed), and which of
//! them is the frame's directional light.

use glam::Vec3;

use hikari_atmosphere::{AtmosphereParams, transmittance_to_top};
use hikari_math::astro::{SunAndMoon, sun_and_moon};
use hikari_scene::Sun;

use super::settings::SkySettings;
use crate::settings::SettingError;

/// Steps of the transmittance integral along the ray to space (converged to 1e-4 for the
/// Earth's atmosphere at the horizon).
const TRANSMITTANCE_STEPS: usize = 500;

/// The sun's angular radius seen from the Earth at 1 au, radians (959.63 arcseconds).
pub const SUN_ANGULAR_RADIUS_1AU: f32 = 4.6524e-3;
/// The moon's radius, km (IAU).
pub const MOON_RADIUS_KM: f64 = 1737.4;

/// One body as the sky sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Unit vector towards it, world axes (Y up, +Z north, −X east).
    pub direction: Vec3,
    pub azimuth_deg: f64,
    pub elevation_deg: f64,
    /// Illuminance above the atmosphere on a plane facing it, lux.
    pub extraterrestrial_lux: f32,
    /// Angular radius of its disk, radians.
    pub angular_radius: f32,
    /// Illuminance at the ground on a plane facing it, linear Rec.709 lux (0 below the horizon).
    pub ground_lux: Vec3,
}

impl Body {
    /// Illuminance at the ground on a horizontal plane: the photometric (Rec.709 luminance)
    /// value of [`Body::ground_lux`] times the sine of the elevation.
    pub fn horizontal_lux(&self) -> f32 {
        luminance(self.ground_lux) * (self.elevation_deg.to_radians().sin().max(0.0) as f32)
    }
}

/// The sun and the moon of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyLights {
    pub sun: Body,
    pub moon: Body,
    /// Illuminated fraction of the moon's disk, 0 to 1.
    pub moon_illuminated_fraction: f32,
}

pub fn luminance(c: Vec3) -> f32 {
    hikari_math::color::luminance(c)
}

fn mat_mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// `lux` of white (D65) light after the path from the ground to space along `cos_zenith`, in
/// linear Rec.709: the filter applies in the atmosphere's working space. Zero below the
/// horizon.
pub fn attenuated(p: &AtmosphereParams, cos_zenith: f32, lux: f32) -> Vec3 {
    if cos_zenith <= 0.0 || lux <= 0.0 {
        return Vec3::ZERO;
    }
    let t = transmittance_to_top(
        p,
        p.bottom_radius_km,
        f64::from(cos_zenith),
        TRANSMITTANCE_STEPS,
    );
    let white = mat_mul(&p.color_space.from_rec709(), [f64::from(lux); 3]);
    let out = mat_mul(
        &p.color_space.to_rec709(),
        std::array::from_fn(|c| t[c] * white[c]),
    );
    Vec3::from_array(out.map(|v| {
        if v.is_finite() {
            v.max(0.0) as f32
        } else {
            0.0
        }
    }))
}

impl SkyLights {
    /// The sun and moon for the settings' date, time, place and weather.
    pub fn new(s: &SkySettings) -> Result<Self, SettingError> {
        let when = s.date_time()?;
        let place = s.place()?;
        let atmosphere = s.atmosphere()?;
        Ok(Self::from_ephemeris(
            &sun_and_moon(&when, &place),
            &atmosphere,
        ))
    }

    pub fn from_ephemeris(sm: &SunAndMoon, p: &AtmosphereParams) -> Self {
        let sun_lux = sm.sun.extraterrestrial_lux as f32;
        let moon_lux = sm.moon.extraterrestrial_lux as f32;
        Self {
            sun: Body {
                direction: sm.sun.direction,
                azimuth_deg: sm.sun.azimuth_deg,
                elevation_deg: sm.sun.elevation_deg,
                extraterrestrial_lux: sun_lux,
                angular_radius: SUN_ANGULAR_RADIUS_1AU / sm.sun.distance_au as f32,
                ground_lux: attenuated(p, sm.sun.direction.y, sun_lux),
            },
            moon: Body {
                direction: sm.moon.direction,
                azimuth_deg: sm.moon.azimuth_deg,
                elevation_deg: sm.moon.elevation_deg,
                extraterrestrial_lux: moon_lux,
                angular_radius: (MOON_RADIUS_KM / sm.moon.distance_km).asin() as f32,
                ground_lux: attenuated(p, sm.moon.direction.y, moon_lux),
            },
            moon_illuminated_fraction: sm.moon.illuminated_fraction as f32,
        }
    }

    /// The directional light: the sun while it is above the horizon, else the moon while it
    /// is, else none. Its colour is the transmitted light's, scaled to luminance 1.
    pub fn directional(&self) -> Option<Sun> {
        let body = if self.sun.direction.y > 0.0 {
            &self.sun
        } else if self.moon.direction.y > 0.0 {
            &self.moon
        } else {
            return None;
        };
        let lum = luminance(body.ground_lux);
        if !(lum > 0.0 && lum.is_finite()) {
            return None;
        }
        Some(Sun {
            direction: body.direction.normalize(),
            illuminance_lux: lum,
            color: body.ground_lux / lum,
        })
    }
}

/// The frame's directional light for `s`: [`SkyLights::directional`], or none when the
/// settings turn the sun off.
pub fn directional_light(s: &SkySettings) -> Result<Option<Sun>, SettingError> {
    if !s.sun {
        return Ok(None);
    }
    Ok(SkyLights::new(s)?.directional())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(date: &str, time: &str) -> SkySettings {
        SkySettings {
            date: date.into(),
            time: time.into(),
            ..SkySettings::default()
        }
    }

    #[test]
    fn a_clear_summer_noon_gives_about_100_klux_and_a_full_moon_a_fraction_of_a_lux() {
        let noon = SkyLights::new(&at("2024-07-21", "12:30")).unwrap();
        let sun = noon.directional().unwrap();
        assert_eq!(sun.direction, noon.sun.direction.normalize());
        // Normal incidence at ~78° elevation; horizontal a little less.
        let h = noon.sun.horizontal_lux();
        assert!((85_000.0..125_000.0).contains(&h), "noon sun {h} lux");
        assert!(sun.color.z < sun.color.x, "the direct sun is yellowish");
        // That night's full moon high in the south.
        let night = SkyLights::new(&at("2024-07-21", "23:50")).unwrap();
        assert!(
            night.sun.direction.y < 0.0 && night.moon.elevation_deg > 25.0,
            "{night:?}"
        );
        let moon = night.directional().unwrap();
        assert_eq!(moon.direction, night.moon.direction.normalize());
        let h = night.moon.horizontal_lux();
        assert!((0.1..0.3).contains(&h), "full moon {h} lux");
        assert!(night.moon_illuminated_fraction > 0.98);
    }

    #[test]
    fn the_hazier_the_weather_the_less_direct_sun() {
        let mut s = at("2024-07-21", "09:00");
        let mut last = f32::INFINITY;
        for w in ["clear", "hazy", "overcast"] {
            s.weather = w.into();
            let lux = SkyLights::new(&s).unwrap().sun.horizontal_lux();
            assert!(lux < last, "{w}: {lux} lux");
            last = lux;
        }
    }

    #[test]
    fn the_disks_have_their_real_angular_sizes() {
        let l = SkyLights::new(&SkySettings::default()).unwrap();
        // About 0.53° and 0.49-0.56° across.
        let sun = l.sun.angular_radius.to_degrees() * 2.0;
        let moon = l.moon.angular_radius.to_degrees() * 2.0;
        assert!((0.52..0.54).contains(&sun), "{sun}");
        assert!((0.48..0.57).contains(&moon), "{moon}");
    }
}
