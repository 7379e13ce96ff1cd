//! The final image's settings (`[tonemap]`): Purkinje shift, white balance, the tone curve in
//! the tonemapping space, the LUT grade and the dither. Exposure and the local tonemap have
//! tables of their own (`[exposure]`, `[local_tonemap]`).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, SettingError, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TonemapSettings {
    /// The rods' colour shift at low light (Cao et al. 2008, as in Ghost of Tsushima), computed
    /// at absolute scene luminance before exposure; negligible in daylight.
    pub purkinje: bool,
    /// Scale of the Purkinje colour change (1: the talk's constants as they are). The talk
    /// does not give its receptor normalisation; with hikari-math's (a white of 1 cd/m² gives
    /// LMSR ≈ 1) strength 1 turns a moonlit grey into (1, 8.5, 36) times itself, so the
    /// default is 0.05: moonlight clearly blue and readable, lamplight still warm (at 0.1 the
    /// lamp-lit trees of the village at 23:00 turn pink; docs/tonemapping.md).
    pub purkinje_strength: f32,
    /// Rod response, in cd/m² of scotopic-weighted luminance, at which the shift is halved:
    /// the change is multiplied by `sat / (sat + rod)`, so the rods fade out of daylight as
    /// they saturate (Cao et al. 2008 let the rods' input fall with light; the talk keeps it
    /// constant, which still moves a 5 000 cd/m² grey by 2 %). The mesopic range is
    /// 0.005 to 5 cd/m² (CIE 191:2010); 0.5 keeps night scenes (below 0.05) within 10 % of
    /// the talk and lamp-lit streets (a few cd/m²) mildly shifted. 0 turns the fade off
    /// (the talk's formula unchanged).
    pub purkinje_rod_saturation: f32,
    /// Whether `white` is applied.
    pub white_balance: bool,
    /// The colour, linear Rec.709, that white becomes (the artist's pick, brightness
    /// included: (1, 1, 1) is no change). Every component finite and > 0.
    pub white: [f32; 3],
    /// The tone curve (off: the tonemapping space's values are clipped at 1 instead).
    pub curve: bool,
    /// Uchimura's curve: the largest output, the shoulder's asymptote.
    pub curve_max: f32,
    /// Slope of the linear middle section.
    pub curve_contrast: f32,
    /// Where the toe ends and the linear section starts (exposed linear input).
    pub curve_linear_start: f32,
    /// Length of the linear section, as a fraction of `curve_max - curve_linear_start`.
    pub curve_linear_length: f32,
    /// Toe exponent ("black tightness"): 1 straight, larger a darker, longer toe.
    pub curve_toe: f32,
    /// Added to the toe's output ("pedestal"), lifting black.
    pub curve_black: f32,
    /// A `.cube` 3D LUT (Adobe Cube LUT 1.0) graded on sRGB-encoded values, applied after the
    /// curve; absent: no grade (identity). A relative path is taken from the working folder.
    pub lut: Option<String>,
    /// Whether the `lut` grades the image (off: no grade, the file is not read).
    pub grade: bool,
    /// Triangular-distributed dither of ±0.5/255 before the 8-bit store, against banding.
    pub dither: bool,
}

impl Default for TonemapSettings {
    fn default() -> Self {
        Self {
            purkinje: true,
            purkinje_strength: 0.05,
            purkinje_rod_saturation: 0.5,
            white_balance: true,
            white: [1.0, 1.0, 1.0],
            curve: true,
            // Uchimura's published defaults (Gran Turismo Sport, CEDEC 2017).
            curve_max: 1.0,
            curve_contrast: 1.0,
            curve_linear_start: 0.22,
            curve_linear_length: 0.4,
            curve_toe: 1.33,
            curve_black: 0.0,
            lut: None,
            grade: true,
            dither: true,
        }
    }
}

impl TechniqueSettings for TonemapSettings {
    fn fields() -> &'static [Field] {
        &[
            Field {
                key: "purkinje_strength",
                range: Range::Float { lo: 0.0, hi: 4.0 },
            },
            Field {
                key: "purkinje_rod_saturation",
                range: Range::Float {
                    lo: 0.0,
                    hi: 1000.0,
                },
            },
            Field {
                key: "curve_max",
                range: Range::Float { lo: 0.5, hi: 4.0 },
            },
            Field {
                key: "curve_contrast",
                range: Range::Float { lo: 0.1, hi: 4.0 },
            },
            Field {
                key: "curve_linear_start",
                range: Range::Float {
                    lo: 0.015625,
                    hi: 0.45,
                },
            },
            Field {
                key: "curve_linear_length",
                range: Range::Float { lo: 0.0, hi: 0.95 },
            },
            Field {
                key: "curve_toe",
                range: Range::Float { lo: 0.5, hi: 4.0 },
            },
            Field {
                key: "curve_black",
                range: Range::Float { lo: 0.0, hi: 0.25 },
            },
        ]
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }

    fn validate(&self, table: &str) -> Result<(), SettingError> {
        self.check_fields(table)?;
        if let Some(i) = self.white.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(SettingError {
                field: format!("{table}.white"),
                value: format!("{:?} (component {i})", self.white),
                allowed: "three finite numbers > 0, the linear Rec.709 colour white becomes".into(),
            });
        }
        if let Some(p) = &self.lut
            && p.trim().is_empty()
        {
            return Err(SettingError {
                field: format!("{table}.lut"),
                value: "\"\"".into(),
                allowed: "a path to a .cube file, or no key for no grade".into(),
            });
        }
        Ok(())
    }
}
