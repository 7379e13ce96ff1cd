//! Settings of the sky: when and where (date, time, time zone, latitude, longitude), the
//! weather, and the switches of the directional light and the sky's light.

use serde::{Deserialize, Serialize};

use hikari_atmosphere::{AtmosphereParams, TableSizes};
use hikari_math::astro::{DateTime, Place};

use crate::settings::{Field, Preset, Range, SettingError, TechniqueSettings};

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
    /// Resolution of the atmosphere's tables: 0 the smallest (tests), 1 medium, 2 the
    /// atmosphere crate's defaults. The tables are built on the CPU when the weather changes.
    pub table_quality: u32,
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
            table_quality: 2,
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

/// A weather state: what it does to the atmosphere (rebuilds the tables) and the artist knobs
/// the talk names (applied every frame, no rebuild).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weather {
    pub name: &'static str,
    /// Multiplies the Earth's aerosol (Mie) scattering and extinction at sea level.
    pub mie_density_scale: f64,
    /// Cornette-Shanks asymmetry of the aerosols.
    pub mie_g: f64,
    /// Lambertian ground albedo.
    pub ground_albedo: f64,
    /// Scales the sky's radiance (drawn and ambient); 1 is physical.
    pub sky_brightness: f32,
    /// Scales the sky's diffuse ambient light.
    pub ambient_diffuse: f32,
    /// Scales the sky's specular ambient light.
    pub ambient_specular: f32,
}

impl Weather {
    pub const NAMES: [&'static str; 3] = ["clear", "hazy", "overcast"];

    /// Clear: Bruneton's aerosols. Hazy: four times the aerosols, a wider forward lobe.
    /// Overcast: a thick aerosol layer standing in for cloud until the cloud issue, greyer
    /// and dimmer, with a more diffuse ambient.
    pub fn by_name(name: &str) -> Option<Self> {
        let w = |name, mie_density_scale, mie_g, ground_albedo, sky, diffuse, specular| Weather {
            name,
            mie_density_scale,
            mie_g,
            ground_albedo,
            sky_brightness: sky,
            ambient_diffuse: diffuse,
            ambient_specular: specular,
        };
        Some(match name {
            "clear" => w("clear", 1.0, 0.8, 0.1, 1.0, 1.0, 1.0),
            "hazy" => w("hazy", 4.0, 0.76, 0.15, 1.0, 1.0, 0.9),
            "overcast" => w("overcast", 25.0, 0.7, 0.2, 0.9, 1.1, 0.6),
            _ => return None,
        })
    }

    /// The Earth's atmosphere under this weather (LMS Rayleigh space).
    pub fn atmosphere(&self) -> AtmosphereParams {
        let mut p = AtmosphereParams::default();
        p.mie_scattering_per_km *= self.mie_density_scale;
        p.mie_extinction_per_km *= self.mie_density_scale;
        p.mie_g = self.mie_g;
        p.ground_albedo = self.ground_albedo;
        p
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
        bad(|s| s.table_quality = 3, "sky.table_quality");
    }

    #[test]
    fn every_weather_gives_a_valid_atmosphere() {
        for name in Weather::NAMES {
            let w = Weather::by_name(name).unwrap();
            assert_eq!(w.name, name);
            w.atmosphere().validate().unwrap();
        }
    }
}
