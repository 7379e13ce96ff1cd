//! Settings of temporal anti-aliasing.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TaaSettings {
    pub enabled: bool,
    /// Sub-pixel camera positions in one jitter cycle (Halton 2, 3), the first at the pixel
    /// centre; 1 turns the jitter off.
    pub jitter_samples: u32,
    /// The most frames the history averages: a pixel's blend weight falls as 1 / (frames
    /// seen + 1) and never below 1 / `max_history`.
    pub max_history: u32,
    /// Clip the history to the current frame's 3x3 neighbourhood in YCoCg (what keeps moving
    /// scenes from ghosting); off, a still view converges to the exact supersampled average.
    pub clip: bool,
    /// The frame is rendered at this fraction of the output's width and height (0.5 to 1)
    /// and upsampled to it temporally (`taa.upsample`; docs/scaling.md). Below 1 the jitter
    /// cycle grows by 1 / scale^2; with TAA off the upsampling has no history.
    pub render_scale: f32,
}

impl Default for TaaSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            jitter_samples: 8,
            max_history: 16,
            clip: true,
            render_scale: 1.0,
        }
    }
}

impl TechniqueSettings for TaaSettings {
    fn fields() -> &'static [Field] {
        &[
            Field {
                key: "jitter_samples",
                range: Range::Int { lo: 1, hi: 64 },
            },
            Field {
                key: "max_history",
                range: Range::Int { lo: 1, hi: 256 },
            },
            Field {
                key: "render_scale",
                range: Range::Float { lo: 0.5, hi: 1.0 },
            },
        ]
    }

    /// Render scale is where the presets' cost goes first: `low` renders a quarter of the
    /// pixels, `medium` under half.
    fn preset(p: Preset) -> Self {
        Self {
            render_scale: match p {
                Preset::Low => 0.5,
                Preset::Medium => 0.67,
                Preset::High | Preset::Ultra => 1.0,
            },
            ..Self::default()
        }
    }
}
