//! Weather states: what each does to the atmosphere (its tables, rebuilt when the weather
//! changes) and the talk's artist knobs, keyed by the sun's elevation and interpolated between
//! the keys every frame (no rebuild).
//!
//! The keys are placed by the sun's elevation, not by clock time: the look of the sky follows
//! where the sun is, and one clock time puts the sun at very different heights across
//! latitudes, seasons and time zones (and a polar summer has no night at all). Elevation also
//! follows a scene's own directional light when it replaces the sun. Dawn and dusk share their
//! keys: at one elevation the physical sky is the same morning and evening.

use hikari_atmosphere::AtmosphereParams;

/// The artist knobs of one moment: multipliers on the physical result, 1 is physical.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArtistKnobs {
    /// Scales the sky's radiance (drawn and ambient).
    pub sky_brightness: f32,
    /// Scales the sky's diffuse ambient light.
    pub ambient_diffuse: f32,
    /// Scales the sky's specular ambient light.
    pub ambient_specular: f32,
    /// Exposure compensation hint, EV (stops), for the exposure issue: negative keeps night
    /// and twilight darker than a meter that fully adapts would make them.
    pub exposure_bias_ev: f32,
}

impl ArtistKnobs {
    /// Every knob physical (1, and no exposure bias).
    pub const NEUTRAL: Self = Self {
        sky_brightness: 1.0,
        ambient_diffuse: 1.0,
        ambient_specular: 1.0,
        exposure_bias_ev: 0.0,
    };

    fn as_array(self) -> [f32; 4] {
        [
            self.sky_brightness,
            self.ambient_diffuse,
            self.ambient_specular,
            self.exposure_bias_ev,
        ]
    }

    fn from_array(a: [f32; 4]) -> Self {
        Self {
            sky_brightness: a[0],
            ambient_diffuse: a[1],
            ambient_specular: a[2],
            exposure_bias_ev: a[3],
        }
    }
}

/// One time-of-day key of a weather.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeKey {
    pub name: &'static str,
    /// The sun's elevation at which the key holds exactly, degrees above the horizon.
    pub sun_elevation_deg: f32,
    pub knobs: ArtistKnobs,
}

/// Names and sun elevations of the keys, lowest first: `night` where the atmosphere's tables
/// end (12° below the horizon, `MU_S_MIN`: the sun lights no sky, the moon takes over),
/// `twilight` in the blue hour, `golden` just after sunrise or before sunset, `day` from where
/// the sun is high enough that the sky hardly changes any more.
pub const KEY_ELEVATIONS_DEG: [(&str, f32); 4] = [
    ("night", -12.0),
    ("twilight", -4.0),
    ("golden", 6.0),
    ("day", 30.0),
];

/// A weather state: what it does to the atmosphere (rebuilds the tables) and the artist knobs
/// the talk names per time-of-day key (interpolated every frame, no rebuild).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weather {
    pub name: &'static str,
    /// Multiplies the Earth's aerosol (Mie) scattering and extinction at sea level.
    pub mie_density_scale: f64,
    /// Cornette-Shanks asymmetry of the aerosols.
    pub mie_g: f64,
    /// Lambertian ground albedo.
    pub ground_albedo: f64,
    /// The artist knobs at [`KEY_ELEVATIONS_DEG`], in that order.
    pub keys: [TimeKey; 4],
}

impl Weather {
    pub const NAMES: [&'static str; 3] = ["clear", "hazy", "overcast"];

    /// Clear: Bruneton's aerosols. Hazy: four times the aerosols, a wider forward lobe.
    /// Overcast: a thick aerosol layer standing in for cloud until the cloud issue, greyer
    /// and dimmer, with a more diffuse ambient.
    ///
    /// The knobs (sky brightness, ambient diffuse, ambient specular, exposure bias EV) per key
    /// night, twilight, golden, day: the day keys are the weather's old single values; towards
    /// night the ambient leans diffuse (moonlit shadows read better lifted a little, and a dim
    /// sky's SH makes broad, unconvincing highlights) and the exposure hint keeps the night
    /// dark.
    pub fn by_name(name: &str) -> Option<Self> {
        let k = |v: [[f32; 4]; 4]| {
            std::array::from_fn(|i| TimeKey {
                name: KEY_ELEVATIONS_DEG[i].0,
                sun_elevation_deg: KEY_ELEVATIONS_DEG[i].1,
                knobs: ArtistKnobs::from_array(v[i]),
            })
        };
        let w = |name, mie_density_scale, mie_g, ground_albedo, keys| Weather {
            name,
            mie_density_scale,
            mie_g,
            ground_albedo,
            keys,
        };
        Some(match name {
            "clear" => w(
                "clear",
                1.0,
                0.8,
                0.1,
                k([
                    [1.0, 1.2, 0.8, -2.0],
                    [1.1, 1.1, 0.9, -1.0],
                    [1.05, 1.0, 1.0, -0.3],
                    [1.0, 1.0, 1.0, 0.0],
                ]),
            ),
            "hazy" => w(
                "hazy",
                4.0,
                0.76,
                0.15,
                k([
                    [1.0, 1.2, 0.7, -2.0],
                    [1.05, 1.1, 0.8, -1.0],
                    [1.0, 1.0, 0.9, -0.3],
                    [1.0, 1.0, 0.9, 0.0],
                ]),
            ),
            "overcast" => w(
                "overcast",
                25.0,
                0.7,
                0.2,
                k([
                    [0.9, 1.3, 0.5, -2.0],
                    [0.9, 1.2, 0.55, -1.0],
                    [0.9, 1.1, 0.6, -0.5],
                    [0.9, 1.1, 0.6, 0.0],
                ]),
            ),
            _ => return None,
        })
    }

    /// The Earth's atmosphere under this weather (LMS Rayleigh space). The knobs take no part
    /// in it, so that moving through the day never rebuilds the tables.
    pub fn atmosphere(&self) -> AtmosphereParams {
        let mut p = AtmosphereParams::default();
        p.mie_scattering_per_km *= self.mie_density_scale;
        p.mie_extinction_per_km *= self.mie_density_scale;
        p.mie_g = self.mie_g;
        p.ground_albedo = self.ground_albedo;
        p
    }

    /// The knobs with the sun `sun_elevation_deg` degrees above the horizon: each knob eased
    /// between the two keys around it with a smoothstep of the elevation (exact at the keys,
    /// monotone between them, no kink as the sun crosses a key), held at the first and the last
    /// key beyond them. A non-finite elevation takes the day key.
    pub fn knobs_at(&self, sun_elevation_deg: f64) -> ArtistKnobs {
        let e = if sun_elevation_deg.is_finite() {
            sun_elevation_deg as f32
        } else {
            f32::INFINITY
        };
        let (first, last) = (&self.keys[0], &self.keys[self.keys.len() - 1]);
        if e <= first.sun_elevation_deg {
            return first.knobs;
        }
        if e >= last.sun_elevation_deg {
            return last.knobs;
        }
        let i = self
            .keys
            .windows(2)
            .position(|p| e < p[1].sun_elevation_deg)
            .unwrap_or(self.keys.len() - 2);
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        let t = ((e - a.sun_elevation_deg) / (b.sun_elevation_deg - a.sun_elevation_deg))
            .clamp(0.0, 1.0);
        let s = t * t * (3.0 - 2.0 * t);
        let (ka, kb) = (a.knobs.as_array(), b.knobs.as_array());
        ArtistKnobs::from_array(std::array::from_fn(|c| ka[c] + (kb[c] - ka[c]) * s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn weathers() -> impl Iterator<Item = Weather> {
        Weather::NAMES
            .into_iter()
            .map(|n| Weather::by_name(n).unwrap())
    }

    #[test]
    fn keys_are_ordered_and_hit_exactly_at_their_elevations() {
        for w in weathers() {
            for p in w.keys.windows(2) {
                assert!(
                    p[0].sun_elevation_deg < p[1].sun_elevation_deg,
                    "{}",
                    w.name
                );
            }
            for k in &w.keys {
                assert_eq!(
                    w.knobs_at(f64::from(k.sun_elevation_deg)),
                    k.knobs,
                    "{} at {}",
                    w.name,
                    k.name
                );
            }
            // Held beyond the ends, and NaN takes the day key.
            assert_eq!(w.knobs_at(-90.0), w.keys[0].knobs);
            assert_eq!(w.knobs_at(90.0), w.keys[3].knobs);
            assert_eq!(w.knobs_at(f64::NAN), w.keys[3].knobs);
        }
    }

    /// Between two keys every knob moves one way only (towards the next key's value) and no
    /// faster than the smoothstep's steepest slope, 1.5 × the difference over the gap: a jump
    /// (a discontinuity) or an overshoot fails.
    #[test]
    fn interpolation_is_continuous_and_monotone_between_keys() {
        let step = 1e-3f32;
        for w in weathers() {
            for p in w.keys.windows(2) {
                let (a, b) = (&p[0], &p[1]);
                let (ka, kb) = (a.knobs.as_array(), b.knobs.as_array());
                let gap = b.sun_elevation_deg - a.sun_elevation_deg;
                let n = (gap / step) as usize;
                let mut prev = ka;
                for i in 1..=n {
                    let e = a.sun_elevation_deg + gap * i as f32 / n as f32;
                    let now = w.knobs_at(f64::from(e)).as_array();
                    for c in 0..4 {
                        let d = now[c] - prev[c];
                        let dir = kb[c] - ka[c];
                        assert!(
                            d * dir >= -1e-6 && (dir != 0.0 || d.abs() <= 1e-6),
                            "{} {}..{} knob {c} at {e}°: moves against the keys ({d})",
                            w.name,
                            a.name,
                            b.name
                        );
                        let bound = 1.5 * dir.abs() / gap * (gap / n as f32) + 1e-5;
                        assert!(
                            d.abs() <= bound,
                            "{} knob {c} at {e}°: jumps {d} (at most {bound})",
                            w.name
                        );
                        let (lo, hi) = (ka[c].min(kb[c]), ka[c].max(kb[c]));
                        assert!(now[c] >= lo - 1e-6 && now[c] <= hi + 1e-6);
                    }
                    prev = now;
                }
                // The last sample is the next key, so the segments join.
                assert_eq!(prev, kb);
            }
        }
    }

    /// The midpoint of a segment is the mean of its keys (the smoothstep's value at ½),
    /// checked independently of the implementation's easing.
    #[test]
    fn midpoint_is_the_mean_of_the_keys() {
        for w in weathers() {
            for p in w.keys.windows(2) {
                let mid = 0.5 * (p[0].sun_elevation_deg + p[1].sun_elevation_deg);
                let got = w.knobs_at(f64::from(mid)).as_array();
                let (ka, kb) = (p[0].knobs.as_array(), p[1].knobs.as_array());
                for c in 0..4 {
                    assert!((got[c] - 0.5 * (ka[c] + kb[c])).abs() < 1e-6);
                }
            }
        }
    }
}
