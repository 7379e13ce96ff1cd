//! What a user may tune about a frame, with the ranges each value must lie in. The CLI reads
//! these from a TOML file (`--config`, see docs/config.example.toml); `validate` names the offending
//! field and its allowed range.

use serde::{Deserialize, Serialize};

/// Every tunable of the frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    pub shadows: ShadowSettings,
    pub lighting: LightingSettings,
    pub exposure: ExposureSettings,
}

/// Cascaded shadow maps of the sun (or moon).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    pub enabled: bool,
    /// Number of cascades, 1 to 4.
    pub cascades: u32,
    /// Texels along each side of a cascade, a power of two from 64 to 8192.
    pub resolution: u32,
    /// Distance from the camera the last cascade reaches, in metres.
    pub max_distance_m: f32,
    /// Blend of logarithmic (1) and uniform (0) cascade splits.
    pub split_lambda: f32,
    /// Spacing of the 3x3 bilinear PCF taps in texels; 0 gives one hard bilinear tap.
    pub filter_radius_texels: f32,
    /// Depth bias, in texels of the cascade's world-space size.
    pub depth_bias_texels: f32,
    /// Receiver offset along its normal, in texels of the cascade's world-space size.
    pub normal_bias_texels: f32,
    /// Keep the maps across frames: a still view draws nothing, a moving one only the strips
    /// its cascades uncover as they scroll; a cascade is drawn whole when the sun or the
    /// settings change its shape. Off: every cascade is drawn whole every frame.
    pub cache: bool,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            cascades: 4,
            resolution: 2048,
            max_distance_m: 250.0,
            split_lambda: 0.85,
            filter_radius_texels: 1.0,
            depth_bias_texels: 1.0,
            normal_bias_texels: 1.5,
            cache: true,
        }
    }
}

/// Which direct lights the deferred lighting adds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightingSettings {
    pub sun: bool,
    /// Point and spot lights.
    pub punctual: bool,
    pub emissive: bool,
    /// The placeholder sky and ambient light that the atmosphere and probe issues replace.
    pub placeholder_ambient: bool,
}

impl Default for LightingSettings {
    fn default() -> Self {
        Self {
            sun: true,
            punctual: true,
            emissive: true,
            placeholder_ambient: true,
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExposureSettings {
    /// Exposure value at ISO 100 of the placeholder exposure; `None`: chosen from the sun.
    pub ev100: Option<f32>,
}

/// A setting outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{field}` is {value}; allowed: {allowed}")]
pub struct SettingError {
    pub field: String,
    pub value: String,
    pub allowed: String,
}

fn range(field: &str, v: f32, lo: f32, hi: f32) -> Result<(), SettingError> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(SettingError {
            field: field.into(),
            value: v.to_string(),
            allowed: format!("{lo} to {hi}"),
        })
    }
}

impl Settings {
    pub fn validate(&self) -> Result<(), SettingError> {
        let s = &self.shadows;
        if !(1..=4).contains(&s.cascades) {
            return Err(SettingError {
                field: "shadows.cascades".into(),
                value: s.cascades.to_string(),
                allowed: "1 to 4".into(),
            });
        }
        if !s.resolution.is_power_of_two() || !(64..=8192).contains(&s.resolution) {
            return Err(SettingError {
                field: "shadows.resolution".into(),
                value: s.resolution.to_string(),
                allowed: "a power of two from 64 to 8192".into(),
            });
        }
        range("shadows.max_distance_m", s.max_distance_m, 1.0, 100_000.0)?;
        range("shadows.split_lambda", s.split_lambda, 0.0, 1.0)?;
        range(
            "shadows.filter_radius_texels",
            s.filter_radius_texels,
            0.0,
            8.0,
        )?;
        range("shadows.depth_bias_texels", s.depth_bias_texels, 0.0, 16.0)?;
        range(
            "shadows.normal_bias_texels",
            s.normal_bias_texels,
            0.0,
            16.0,
        )?;
        if let Some(ev) = self.exposure.ev100 {
            range("exposure.ev100", ev, -10.0, 30.0)?;
        }
        Ok(())
    }
}
