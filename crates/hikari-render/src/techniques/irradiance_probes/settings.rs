//! The irradiance probes' switches and update budget (`[irradiance_probes]`).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IrradianceProbesSettings {
    /// Ambient diffuse light from the probes where a bake covers the surface; off: the sky's
    /// SH, unoccluded.
    pub enabled: bool,
    /// The bounced sky light (bounced sky visibility times the sky's average colour).
    pub bounce: bool,
    /// The sun's (or moon's) light bounced by an imaginary ground and wall.
    pub sun_bounce: bool,
    /// Multiplier of the sun bounce's strength (1: the imaginary ground's albedo is the
    /// probe's mean bounced visibility, see docs/irradiance-probes.md).
    pub sun_bounce_scale: f32,
    /// The directionality boost, applied to the direct and the bounced parts separately.
    pub boost: bool,
    /// How far the boost moves towards a delta (the talk: 0.25).
    pub boost_amount: f32,
    /// Deringing of each probe's final irradiance.
    pub dering: bool,
    /// Tetrahedral and grid weights by the G-buffer's interior mask (w for interior probes,
    /// 1 - w for exterior ones); off: plain barycentric and trilinear weights.
    pub interior_mask: bool,
    /// Grid tiles relit per frame in round robin (the talk: 8x8 = 64).
    pub tiles_per_frame: u32,
    /// Also relight the 3x3 tiles around the camera every frame.
    pub camera_tiles: bool,
}

impl Default for IrradianceProbesSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            bounce: true,
            sun_bounce: true,
            sun_bounce_scale: 1.0,
            boost: true,
            boost_amount: 0.25,
            dering: true,
            interior_mask: true,
            tiles_per_frame: 64,
            camera_tiles: true,
        }
    }
}

impl TechniqueSettings for IrradianceProbesSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "sun_bounce_scale",
                range: Range::Float { lo: 0.0, hi: 16.0 },
            },
            Field {
                key: "boost_amount",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "tiles_per_frame",
                range: Range::Int { lo: 1, hi: 4096 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        Self {
            tiles_per_frame: match p {
                Preset::Low => 16,
                Preset::Medium => 32,
                _ => 64,
            },
            ..Self::default()
        }
    }
}
