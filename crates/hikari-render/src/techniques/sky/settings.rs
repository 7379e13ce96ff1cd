//! Settings of the sky: when and where (date, time, time zone, latitude, longitude), the
//! weather, and the switches of the directional light and the sky's light.

use serde::{Deserialize, Serialize};

use hikari_atmosphere::{AtmosphereParams, ColorSpace, TableSizes};
use hikari_math::astro::{DateTime, Place};

use crate::settings::{Field, Preset, Range, SettingError, TechniqueSettings};

pub use super::weather::{ArtistKnobs, KEY_ELEVATIONS_DEG, TimeKey, Weather};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkySettings {
    /// The atmosphere's passes (tables, resample, sky drawing, sky SH). Off: the frame keeps
    /// the flat placeholder sky and ambient of `direct_lighting.placeholder_ambient`.
    pub enabled: bool,
    /// The sun (or, at night, the moon) as the directional light.
    pub sun: bool,
    /// The sky's light: the sky drawn behind the scene and its ambient light (sky SH).
    pub sky: bool,
    /// Local date, `YYYY-MM-DD`, 1900-01-01 to 2100-12-31.
    pub date: String,
    /// Local time, `HH:MM` or `HH:MM:SS`, 00:00 to 23:59:59.
    pub time: String,
    /// Hours east of Greenwich of the local time (Japan: 9), -14 to 14.
    pub utc_offset_h: f64,
    /// Geodetic latitude, degrees, north positive, -90 to 90.
    pub latitude_deg: f64,
    /// Longitude, degrees, east positive, -180 to 180.
    pub longitude_deg: f64,
    /// A weather preset: `clear`, `hazy` or `overcast` ([`Weather::NAMES`]).
    pub weather: String,
    /// The colour space the atmosphere is computed in: `lms_rayleigh` (the talk's LMS Rayleigh
    /// space, the default) or `rec709` (linear Rec.709 with Bruneton's coefficients, to compare
    /// the two as the talk does). Changing it rebuilds the tables.
    pub color_space: String,
    /// Resolution of the atmosphere's tables: 0 the smallest (tests), 1 medium, 2 the
    /// atmosphere crate's defaults. The tables are built on the CPU when the weather changes.
    pub table_quality: u32,
    /// Build the tables with the GPU passes `sky.tables.*` (true) or on the CPU with
    /// hikari-atmosphere and upload them (false: the twin, as a fallback). Either way they are
    /// rebuilt only when the weather or the table quality changes.
    pub tables_on_gpu: bool,
    /// Multiplies the weather's sky brightness at every time-of-day key, 0 to 16.
    pub sky_brightness_scale: f32,
    /// Multiplies the weather's ambient diffuse balance at every key, 0 to 16.
    pub ambient_diffuse_scale: f32,
    /// Multiplies the weather's ambient specular balance at every key, 0 to 16.
    pub ambient_specular_scale: f32,
}

impl Default for SkySettings {
    /// Tsushima (34.4° N, 129.3° E, UTC+9) at noon on the astro module's summer day
    /// (2024-07-21, a full moon that night), clear weather.
    fn default() -> Self {
        let when = DateTime::default_summer();
        let (y, mo, d) = when.date();
        let (h, mi, _) = when.time();
        Self {
            enabled: true,
            sun: true,
            sky: true,
            date: format!("{y:04}-{mo:02}-{d:02}"),
            time: format!("{h:02}:{mi:02}"),
            utc_offset_h: when.utc_offset_h(),
            latitude_deg: Place::TSUSHIMA.latitude_deg(),
            longitude_deg: Place::TSUSHIMA.longitude_deg(),
            weather: "clear".into(),
            color_space: "lms_rayleigh".into(),
            table_quality: 2,
            tables_on_gpu: true,
            sky_brightness_scale: 1.0,
            ambient_diffuse_scale: 1.0,
            ambient_specular_scale: 1.0,
        }
    }
}

impl SkySettings {
    /// The validated instant; the error names the field and what it allows.
    pub fn date_time(&self) -> Result<DateTime, SettingError> {
        DateTime::parse(&self.date, &self.time, self.utc_offset_h).map_err(|e| {
            let field = match e {
                hikari_math::astro::AstroError::Date { .. } => "sky.date",
                hikari_math::astro::AstroError::Time { .. } => "sky.time",
                _ => "sky.utc_offset_h",
            };
            SettingError {
                field: field.into(),
                value: match field {
                    "sky.date" => format!("{:?}", self.date),
                    "sky.time" => format!("{:?}", self.time),
                    _ => self.utc_offset_h.to_string(),
                },
                allowed: e.to_string(),
            }
        })
    }

    /// The validated place.
    pub fn place(&self) -> Result<Place, SettingError> {
        Place::new(self.latitude_deg, self.longitude_deg).map_err(|e| SettingError {
            field: if self.latitude_deg.is_finite() && self.latitude_deg.abs() <= 90.0 {
                "sky.longitude_deg".into()
            } else {
                "sky.latitude_deg".into()
            },
            value: format!("{}, {}", self.latitude_deg, self.longitude_deg),
            allowed: e.to_string(),
        })
    }

    /// The weather preset named by [`SkySettings::weather`].
    pub fn weather(&self) -> Result<Weather, SettingError> {
        Weather::by_name(&self.weather).ok_or_else(|| SettingError {
            field: "sky.weather".into(),
            value: format!("{:?}", self.weather),
            allowed: Weather::NAMES.join(", "),
        })
    }

    /// The colour space named by [`SkySettings::color_space`].
    pub fn color_space(&self) -> Result<ColorSpace, SettingError> {
        match self.color_space.as_str() {
            "lms_rayleigh" => Ok(ColorSpace::LmsRayleigh),
            "rec709" => Ok(ColorSpace::Rec709),
            _ => Err(SettingError {
                field: "sky.color_space".into(),
                value: format!("{:?}", self.color_space),
                allowed: "lms_rayleigh, rec709".into(),
            }),
        }
    }

    /// The atmosphere's parameters: the weather's, computed in [`SkySettings::color_space`].
    pub fn atmosphere(&self) -> Result<AtmosphereParams, SettingError> {
        let mut p = self.weather()?.atmosphere();
        p.color_space = self.color_space()?;
        Ok(p)
    }

    /// The artist knobs of the weather with the sun `sun_elevation_deg` above the horizon
    /// ([`Weather::knobs_at`]), times this file's scales.
    pub fn knobs(&self, sun_elevation_deg: f64) -> Result<ArtistKnobs, SettingError> {
        let k = self.weather()?.knobs_at(sun_elevation_deg);
        Ok(ArtistKnobs {
            sky_brightness: k.sky_brightness * self.sky_brightness_scale,
            ambient_diffuse: k.ambient_diffuse * self.ambient_diffuse_scale,
            ambient_specular: k.ambient_specular * self.ambient_specular_scale,
            exposure_bias_ev: k.exposure_bias_ev,
        })
    }

    /// What the sky's tables are built from and cached by: the weather's atmosphere in the
    /// chosen colour space, and the table sizes. Neither the time nor the knobs enter it.
    pub fn table_key(&self) -> Result<(AtmosphereParams, TableSizes), SettingError> {
        Ok((self.atmosphere()?, self.table_sizes()))
    }

    /// The atmosphere's table sizes for [`SkySettings::table_quality`].
    pub fn table_sizes(&self) -> TableSizes {
        table_sizes(self.table_quality)
    }
}

/// Table sizes by quality: 0 small enough for tests (well under a second to build), 2 the
/// atmosphere crate's defaults.
pub fn table_sizes(quality: u32) -> TableSizes {
    match quality {
        0 => TableSizes {
            transmittance: [64, 16],
            scattering: [32, 16, 8],
            density: [16, 16, 8],
            ground_irradiance: [32, 8],
            ray_steps: 20,
            sphere: [8, 8],
        },
        1 => TableSizes {
            transmittance: [128, 32],
            scattering: [64, 32, 16],
            density: [16, 16, 16],
            ground_irradiance: [64, 16],
            ray_steps: 30,
            sphere: [12, 12],
        },
        _ => TableSizes::default(),
    }
}

impl TechniqueSettings for SkySettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "utc_offset_h",
                range: Range::Float {
                    lo: -14.0,
                    hi: 14.0,
                },
            },
            Field {
                key: "latitude_deg",
                range: Range::Float {
                    lo: -90.0,
                    hi: 90.0,
                },
            },
            Field {
                key: "longitude_deg",
                range: Range::Float {
                    lo: -180.0,
                    hi: 180.0,
                },
            },
            Field {
                key: "table_quality",
                range: Range::Int { lo: 0, hi: 2 },
            },
            Field {
                key: "sky_brightness_scale",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
            Field {
                key: "ambient_diffuse_scale",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
            Field {
                key: "ambient_specular_scale",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        Self {
            table_quality: match p {
                Preset::Low => 1,
                _ => 2,
            },
            ..Self::default()
        }
    }

    /// The ranges of [`Self::fields`], then the date, time and weather name.
    fn validate(&self, table: &str) -> Result<(), SettingError> {
        self.check_fields(table)?;
        self.date_time()?;
        self.place()?;
        self.weather()?;
        self.color_space()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_field() {
        SkySettings::default().validate("sky").unwrap();
        let bad = |f: fn(&mut SkySettings), field: &str| {
            let mut s = SkySettings::default();
            f(&mut s);
            let e = s.validate("sky").unwrap_err();
            assert_eq!(e.field, field, "{e}");
        };
        bad(|s| s.date = "1899-12-31".into(), "sky.date");
        bad(|s| s.date = "2101-01-01".into(), "sky.date");
        bad(|s| s.time = "24:00".into(), "sky.time");
        bad(|s| s.latitude_deg = 90.5, "sky.latitude_deg");
        bad(|s| s.longitude_deg = -180.5, "sky.longitude_deg");
        bad(|s| s.latitude_deg = f64::NAN, "sky.latitude_deg");
        bad(|s| s.utc_offset_h = 15.0, "sky.utc_offset_h");
        bad(|s| s.weather = "snowy".into(), "sky.weather");
        bad(|s| s.color_space = "srgb".into(), "sky.color_space");
        bad(|s| s.table_quality = 3, "sky.table_quality");
        bad(
            |s| s.sky_brightness_scale = -0.1,
            "sky.sky_brightness_scale",
        );
        bad(
            |s| s.ambient_diffuse_scale = f32::NAN,
            "sky.ambient_diffuse_scale",
        );
        bad(
            |s| s.ambient_specular_scale = 17.0,
            "sky.ambient_specular_scale",
        );
    }

    #[test]
    fn every_weather_gives_a_valid_atmosphere() {
        for name in Weather::NAMES {
            let w = Weather::by_name(name).unwrap();
            assert_eq!(w.name, name);
            w.atmosphere().validate().unwrap();
        }
    }

    fn at(time: &str, weather: &str) -> SkySettings {
        SkySettings {
            time: time.into(),
            weather: weather.into(),
            ..SkySettings::default()
        }
    }

    fn sun_elevation(s: &SkySettings) -> f64 {
        hikari_math::astro::sun_and_moon(&s.date_time().unwrap(), &s.place().unwrap())
            .sun
            .elevation_deg
    }

    /// Through a whole day within one weather the tables' cache key stays the same while the
    /// knobs follow the sun; another weather changes the key.
    #[test]
    fn time_within_a_weather_changes_the_knobs_not_the_tables() {
        for name in Weather::NAMES {
            let noon = at("12:00", name);
            let key = noon.table_key().unwrap();
            let mut seen = Vec::new();
            for m in (0..24 * 60).step_by(20) {
                let s = at(&format!("{:02}:{:02}", m / 60, m % 60), name);
                assert_eq!(s.table_key().unwrap(), key, "{name} {}", s.time);
                seen.push(s.knobs(sun_elevation(&s)).unwrap());
            }
            let night = Weather::by_name(name).unwrap().keys[0].knobs;
            let day = Weather::by_name(name).unwrap().keys[3].knobs;
            assert!(seen.contains(&night) && seen.contains(&day), "{name}");
            assert!(seen.iter().any(|k| *k != night && *k != day), "{name}");
        }
        assert_ne!(
            at("12:00", "clear").table_key().unwrap(),
            at("12:00", "hazy").table_key().unwrap()
        );
    }

    /// `color_space = "rec709"` computes the same weather with Bruneton's Rec.709
    /// coefficients (the talk's comparison): another table key, the same weather otherwise.
    #[test]
    fn the_colour_space_setting_reaches_the_atmosphere() {
        let lms = at("12:00", "hazy");
        let rec = SkySettings {
            color_space: "rec709".into(),
            ..lms.clone()
        };
        rec.validate("sky").unwrap();
        let (a, b) = (lms.atmosphere().unwrap(), rec.atmosphere().unwrap());
        assert_eq!(a.color_space, ColorSpace::LmsRayleigh);
        assert_eq!(b.color_space, ColorSpace::Rec709);
        assert_eq!(
            b.rayleigh(),
            hikari_math::color::rayleigh::RAYLEIGH_REC709_BRUNETON
        );
        assert_eq!(
            AtmosphereParams {
                color_space: ColorSpace::LmsRayleigh,
                ..b.clone()
            },
            a
        );
        assert_ne!(lms.table_key().unwrap(), rec.table_key().unwrap());
    }

    #[test]
    fn the_file_scales_multiply_the_keys() {
        let mut s = at("23:30", "overcast");
        let e = sun_elevation(&s);
        let k = Weather::by_name("overcast").unwrap().knobs_at(e);
        s.sky_brightness_scale = 2.0;
        s.ambient_diffuse_scale = 0.5;
        s.ambient_specular_scale = 0.0;
        s.validate("sky").unwrap();
        let got = s.knobs(e).unwrap();
        assert_eq!(got.sky_brightness, 2.0 * k.sky_brightness);
        assert_eq!(got.ambient_diffuse, 0.5 * k.ambient_diffuse);
        assert_eq!(got.ambient_specular, 0.0);
        assert_eq!(got.exposure_bias_ev, k.exposure_bias_ev);
        assert_eq!(s.table_key(), at("23:30", "overcast").table_key());
    }
}
