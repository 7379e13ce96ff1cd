//! Settings of the sun's (or moon's) cascaded shadow maps.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SunShadowsSettings {
    pub enabled: bool,
    /// Number of cascades.
    pub cascades: u32,
    /// Texels along each side of a cascade.
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

impl Default for SunShadowsSettings {
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

impl TechniqueSettings for SunShadowsSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "cascades",
                range: Range::Int { lo: 1, hi: 4 },
            },
            Field {
                key: "resolution",
                range: Range::PowerOfTwo { lo: 64, hi: 8192 },
            },
            Field {
                key: "max_distance_m",
                range: Range::Float {
                    lo: 1.0,
                    hi: 100_000.0,
                },
            },
            Field {
                key: "split_lambda",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "filter_radius_texels",
                range: Range::Float { lo: 0.0, hi: 8.0 },
            },
            Field {
                key: "depth_bias_texels",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
            Field {
                key: "normal_bias_texels",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let (cascades, resolution, max_distance_m) = match p {
            Preset::Low => (2, 1024, 150.0),
            Preset::Medium => (3, 1024, 200.0),
            Preset::High => (4, 2048, 250.0),
            Preset::Ultra => (4, 4096, 400.0),
        };
        Self {
            cascades,
            resolution,
            max_distance_m,
            ..Self::default()
        }
    }
}
