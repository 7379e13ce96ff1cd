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
}

impl Default for TaaSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            jitter_samples: 8,
            max_history: 16,
            clip: true,
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
        ]
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}
