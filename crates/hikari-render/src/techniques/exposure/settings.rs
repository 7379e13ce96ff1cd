//! Exposure: the illuminance meter, the highlight rule, compensation and adaptation.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExposureSettings {
    /// A fixed exposure value at ISO 100 that overrides everything below (meter, highlights,
    /// compensation, adaptation); absent: metered.
    pub ev100: Option<f32>,
    /// Off: the exposure the CPU meter gives (the sun and the sky on the ground,
    /// `FrameSettings::metered_lux_with_sky`), no metering of the image.
    pub enabled: bool,
    /// Exposure compensation in EV (stops): +1 makes the image twice as bright.
    pub compensation_ev: f32,
    /// Adds the weather's exposure hint for the sun's elevation (the sky's knobs: negative at
    /// night and twilight, so that night stays darker than a meter that fully adapts).
    pub weather_bias: bool,
    /// The metered illuminance is the mean of log2 illuminance between these two fractions
    /// of the surface pixels, darkest first (0 to 0.25 and 0.5 to 1, so they never cross):
    /// the tails (a deep shadow, a sunlit patch) do not swing the exposure.
    pub low_percentile: f32,
    pub high_percentile: f32,
    /// The highlight rule: luminance takes part only where highlights are too bright.
    pub highlights: bool,
    /// The highlight is the luminance at this fraction of all pixels, darkest first.
    pub highlight_percentile: f32,
    /// The highlight may reach 2^this in exposed linear units (1 = display white before the
    /// curve) before it darkens the exposure.
    pub highlight_limit_ev: f32,
    /// How much of the excess over the limit the exposure takes back: 0 none, 1 all.
    pub highlight_strength: f32,
    /// Speed at which EV100 rises (the scene got brighter), EV per second.
    pub adapt_up_ev_per_s: f32,
    /// Speed at which EV100 falls (the scene got darker), EV per second: eyes adapt to dark
    /// more slowly than to light.
    pub adapt_down_ev_per_s: f32,
    /// Seconds between frames that adaptation assumes; 0: every frame snaps to its target
    /// (still renders). An interactive renderer (`Renderer::set_interactive`) leaves 0 and
    /// measures each frame's wall-clock time itself.
    pub frame_seconds: f32,
    /// The exposure never goes outside these EV100 (-10 to 0 and 8 to 30, so a 0.05 lux night,
    /// EV100 -5.6, and noon, about 15, always fit).
    pub min_ev100: f32,
    pub max_ev100: f32,
}

impl Default for ExposureSettings {
    fn default() -> Self {
        Self {
            ev100: None,
            enabled: true,
            compensation_ev: 0.0,
            weather_bias: true,
            low_percentile: 0.1,
            high_percentile: 0.9,
            highlights: true,
            highlight_percentile: 0.99,
            highlight_limit_ev: 4.0,
            highlight_strength: 0.5,
            adapt_up_ev_per_s: 3.0,
            adapt_down_ev_per_s: 1.0,
            frame_seconds: 0.0,
            min_ev100: -8.0,
            max_ev100: 20.0,
        }
    }
}

const fn float(key: &'static str, lo: f64, hi: f64) -> Field {
    Field {
        key,
        range: Range::Float { lo, hi },
    }
}

impl TechniqueSettings for ExposureSettings {
    fn fields() -> &'static [Field] {
        const FIELDS: &[Field] = &[
            float("ev100", -10.0, 30.0),
            float("compensation_ev", -10.0, 10.0),
            float("low_percentile", 0.0, 0.25),
            float("high_percentile", 0.5, 1.0),
            float("highlight_percentile", 0.5, 1.0),
            float("highlight_limit_ev", -4.0, 16.0),
            float("highlight_strength", 0.0, 1.0),
            float("adapt_up_ev_per_s", 0.0625, 64.0),
            float("adapt_down_ev_per_s", 0.0625, 64.0),
            float("frame_seconds", 0.0, 8.0),
            float("min_ev100", -10.0, 0.0),
            float("max_ev100", 8.0, 30.0),
        ];
        FIELDS
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}
