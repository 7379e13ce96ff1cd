//! Local tonemapping: the bilateral grid's shape and the talk's detail-preserving contrast,
//! with looks per weather and time of day.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};
use crate::techniques::sky::weather::KEY_ELEVATIONS_DEG;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LocalTonemapSettings {
    /// Off: `local_tonemap.log2_gain` is 0 everywhere and no grid is built.
    pub enabled: bool,
    /// Contrast scale c of the base layer above the midpoint (highlights, skies); absent: the
    /// weather's look at this sun elevation ([`look`]).
    pub contrast: Option<f32>,
    /// Contrast scale of the base layer below the midpoint (shadows, interiors); absent: the
    /// weather's look.
    pub shadow_contrast: Option<f32>,
    /// Detail strength d; absent: the weather's look.
    pub detail: Option<f32>,
    /// Midpoint M that contrast pulls towards, log2 of exposed luminance: -3 is a grey card
    /// of 18 % under the light the exposure meters (exposed 0.66 × 0.18).
    pub midpoint: f32,
    /// Share of the bilateral grid in the base layer; the rest is the wide Gaussian that
    /// hides the grid's ringing on smooth gradients (the talk: 0.4).
    pub bilateral_weight: f32,
    /// The grid's log2 luminance range (exposed), lower end; 64 slices span `grid_range_ev`.
    pub grid_min_ev: f32,
    pub grid_range_ev: f32,
    /// Gaussian blur of the grid, in cells along x and y, and in slices along z (0: none).
    pub blur_sigma_xy: f32,
    pub blur_sigma_z: f32,
    /// Sigma in 64x32 cells of the wide Gaussian (13 taps).
    pub wide_sigma: f32,
    /// The gain never exceeds this many EV either way.
    pub max_gain_ev: f32,
    /// Highlight fit: where the scene's highlight (the exposure's `highlight_percentile` of
    /// all pixels, exposed log2 luminance) lies above this, the contrast above the midpoint
    /// is lowered to (target − M) / (highlight − M), the contrast that brings a base layer at
    /// the highlight to the target, but not below `min_contrast` nor above the look's. A room
    /// looking out onto noon gets more compression; an open noon view, whose highlights sit
    /// below the target, keeps the look. −0.5 (exposed 0.7, where Uchimura's shoulder has
    /// begun): the brightest percent of the frame stays below display white. 8 or more: off
    /// in practice.
    pub highlight_target_ev: f32,
    /// The least contrast the highlight fit may choose.
    pub min_contrast: f32,
}

impl Default for LocalTonemapSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            contrast: None,
            shadow_contrast: None,
            detail: None,
            midpoint: -3.0,
            bilateral_weight: 0.4,
            grid_min_ev: -16.0,
            grid_range_ev: 24.0,
            blur_sigma_xy: 1.0,
            blur_sigma_z: 1.0,
            wide_sigma: 2.5,
            max_gain_ev: 8.0,
            highlight_target_ev: -0.5,
            min_contrast: 0.35,
        }
    }
}

/// Contrast above and below the midpoint and detail of one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    pub contrast: f32,
    pub shadow_contrast: f32,
    pub detail: f32,
}

/// The looks of each weather at the sky's keys ([`KEY_ELEVATIONS_DEG`]: night, twilight,
/// golden, day). Bright clear days have the widest range and take the most compression;
/// overcast light is flat already and gets a little detail instead; nights keep most of
/// their contrast, so that they stay night. The talk's typical in-game setting (75 % above,
/// 100 % below) sits between golden and day.
fn looks(weather: &str) -> [Look; 4] {
    let l = |contrast, shadow_contrast, detail| Look {
        contrast,
        shadow_contrast,
        detail,
    };
    match weather {
        "hazy" => [
            l(0.9, 1.0, 1.0),
            l(0.8, 0.95, 1.0),
            l(0.75, 0.95, 1.05),
            l(0.7, 0.9, 1.05),
        ],
        "overcast" => [
            l(0.95, 1.0, 1.0),
            l(0.9, 1.0, 1.05),
            l(0.85, 0.95, 1.1),
            l(0.85, 0.95, 1.1),
        ],
        _ => [
            l(0.9, 1.0, 1.0),
            l(0.8, 0.95, 1.0),
            l(0.7, 0.9, 1.0),
            l(0.6, 0.85, 1.0),
        ],
    }
}

/// The weather's look with the sun `sun_elevation_deg` above the horizon, eased between keys
/// with a smoothstep of the elevation as the sky's knobs are (an unknown weather is clear).
pub fn look(weather: &str, sun_elevation_deg: f32) -> Look {
    let keys = looks(weather);
    let e = if sun_elevation_deg.is_finite() {
        sun_elevation_deg
    } else {
        f32::INFINITY
    };
    let el: [f32; 4] = KEY_ELEVATIONS_DEG.map(|(_, e)| e);
    if e <= el[0] {
        return keys[0];
    }
    if e >= el[3] {
        return keys[3];
    }
    let i = (0..3).find(|&i| e < el[i + 1]).unwrap_or(2);
    let t = ((e - el[i]) / (el[i + 1] - el[i])).clamp(0.0, 1.0);
    let s = t * t * (3.0 - 2.0 * t);
    let (a, b) = (keys[i], keys[i + 1]);
    let mix = |x: f32, y: f32| x + (y - x) * s;
    Look {
        contrast: mix(a.contrast, b.contrast),
        shadow_contrast: mix(a.shadow_contrast, b.shadow_contrast),
        detail: mix(a.detail, b.detail),
    }
}

impl LocalTonemapSettings {
    /// The look of this frame: the file's values where given, else the weather's.
    pub fn look_for(&self, weather: &str, sun_elevation_deg: f32) -> Look {
        let w = look(weather, sun_elevation_deg);
        Look {
            contrast: self.contrast.unwrap_or(w.contrast),
            shadow_contrast: self.shadow_contrast.unwrap_or(w.shadow_contrast),
            detail: self.detail.unwrap_or(w.detail),
        }
    }
}

const fn float(key: &'static str, lo: f64, hi: f64) -> Field {
    Field {
        key,
        range: Range::Float { lo, hi },
    }
}

impl TechniqueSettings for LocalTonemapSettings {
    fn fields() -> &'static [Field] {
        const FIELDS: &[Field] = &[
            float("contrast", 0.0, 2.0),
            float("shadow_contrast", 0.0, 2.0),
            float("detail", 0.0, 4.0),
            float("midpoint", -16.0, 8.0),
            float("bilateral_weight", 0.0, 1.0),
            float("grid_min_ev", -32.0, 0.0),
            float("grid_range_ev", 4.0, 48.0),
            float("blur_sigma_xy", 0.25, 4.0),
            float("blur_sigma_z", 0.0, 4.0),
            float("wide_sigma", 0.5, 4.0),
            float("max_gain_ev", 0.0, 16.0),
            float("highlight_target_ev", -8.0, 16.0),
            float("min_contrast", 0.0, 2.0),
        ];
        FIELDS
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looks_hit_their_keys_and_the_file_overrides_them() {
        for w in crate::techniques::sky::weather::Weather::NAMES {
            for (i, (_, e)) in KEY_ELEVATIONS_DEG.iter().enumerate() {
                assert_eq!(look(w, *e), looks(w)[i], "{w} key {i}");
            }
            assert_eq!(look(w, f32::NAN), looks(w)[3]);
        }
        let s = LocalTonemapSettings {
            detail: Some(1.5),
            ..Default::default()
        };
        let l = s.look_for("clear", 60.0);
        assert_eq!((l.contrast, l.detail), (looks("clear")[3].contrast, 1.5));
    }
}
