//! Settings of the particles: the talk's haze lighting mode and its multiple-scattering term,
//! the bicubic switch, the soft-particle fade.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ParticlesSettings {
    /// Draw the scene's particle emitters.
    pub enabled: bool,
    /// The talk's haze lighting for the emitters that ask for it (off: every particle takes the
    /// standard lighting, the talk's A/B comparison). Needs the haze.
    pub haze_lighting: bool,
    /// The talk's multiple-scattering approximation for haze-lit particles.
    pub multiple_scattering: bool,
    /// HG asymmetry of the back-scattering phase it compares the haze's with (the talk: -0.15,
    /// as for the clouds).
    pub ms_asymmetry: f32,
    /// How much of the ratio applies with the eye on the light's side (back scattering; the
    /// talk reduced it there), 0 to 1; facing the light it applies whole.
    pub ms_back_strength: f32,
    /// Opacity above which the haze light is read with a bicubic B-spline in x and y (below:
    /// trilinear), the talk's optimisation.
    pub bicubic_opacity: f32,
    /// Soft particles: a sprite fades over this fraction of its radius before the surface
    /// behind it.
    pub soft_fade: f32,
}

impl Default for ParticlesSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            haze_lighting: true,
            multiple_scattering: true,
            ms_asymmetry: -0.15,
            ms_back_strength: 0.5,
            bicubic_opacity: 0.1,
            soft_fade: 0.5,
        }
    }
}

impl TechniqueSettings for ParticlesSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "ms_asymmetry",
                range: Range::Float {
                    lo: -0.95,
                    hi: 0.95,
                },
            },
            Field {
                key: "ms_back_strength",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "bicubic_opacity",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "soft_fade",
                range: Range::Float { lo: 0.0, hi: 10.0 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            // Trilinear everywhere: the bicubic read costs four taps.
            Preset::Low => Self {
                bicubic_opacity: 1.0,
                ..d
            },
            _ => d,
        }
    }
}
