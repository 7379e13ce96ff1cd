//! Settings of the GI and AO denoisers (`[gi_denoiser]`).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GiDenoiserSettings {
    /// The first GI pass (no normal weight, wide radius). Off: its input goes on unchanged.
    pub pass1: bool,
    /// The second GI pass (normal weight, narrower radius). Off: its input goes on unchanged.
    pub pass2: bool,
    /// The AO denoiser. Off: the accumulated AO goes on unchanged.
    pub ao: bool,
    /// The talk's recurrent denoiser: the next frame's temporal accumulation blends with this
    /// frame's denoised output (a mix of the blur's low and the input's high frequencies)
    /// instead of with its own undenoised output. Off: the history is the undenoised one.
    pub recurrent: bool,
    /// Base blur radius of the first pass, in metres (the talk: 6 m).
    pub pass1_radius_m: f32,
    /// Base blur radius of the second pass, in metres (the talk: 3 m).
    pub pass2_radius_m: f32,
    /// Base blur radius of the AO denoiser, in metres.
    pub ao_radius_m: f32,
    /// Cap on the AO denoiser's world radius, as a multiple of the harmonic mean distance of
    /// the 5x5 neighbourhood's ray hits (AO changes over about the distance to the occluders);
    /// 0 turns the cap off. Unitless.
    pub ao_hit_distance_scale: f32,
    /// Cap on the GI passes' world radius at a fresh pixel, as a multiple of the 5x5
    /// neighbourhood's harmonic mean hit distance; the cap shrinks as 1 / sqrt(history length).
    /// 0 turns the cap off. Unitless.
    pub gi_hit_distance_scale: f32,
    /// Poisson-disk samples a GI pass takes at most (the talk: up to 32).
    pub samples: u32,
    /// Poisson-disk samples the AO denoiser takes at most (the talk: up to 64).
    pub ao_samples: u32,
    /// Smallest blur radius on screen, in pixels.
    pub min_radius_px: f32,
    /// Largest blur radius on screen, in pixels: the world radius is clamped to it.
    pub max_radius_px: f32,
    /// View depth in metres at which F(viewZ) = 1/2 (F(z) = z / (z + this)).
    pub radius_half_distance_m: f32,
    /// Distance to the centre's tangent plane at which the geometry weight reaches 0, as a
    /// fraction of the centre's view depth.
    pub plane_tolerance: f32,
    /// Geometry weight as a step (1 within the tolerance, else 0) instead of a linear falloff.
    pub step_falloff: bool,
    /// Coefficient of variation (std. dev. / mean over 3x3) of the input at which
    /// F(variance) reaches 1; below it the radius shrinks in proportion.
    pub variance_reference: f32,
    /// Floor of F(variance) and F(AO), so that no pixel's radius collapses to nothing.
    pub min_radius_scale: f32,
    /// Largest accumulation speed fed to the combiner (the talk: 0.93 with no motion).
    pub max_accumulation_speed: f32,
}

impl Default for GiDenoiserSettings {
    fn default() -> Self {
        Self {
            pass1: true,
            pass2: true,
            ao: true,
            recurrent: false,
            pass1_radius_m: 6.0,
            pass2_radius_m: 3.0,
            ao_radius_m: 2.0,
            ao_hit_distance_scale: 0.4,
            gi_hit_distance_scale: 0.5,
            samples: 32,
            ao_samples: 64,
            min_radius_px: 2.0,
            max_radius_px: 40.0,
            radius_half_distance_m: 10.0,
            plane_tolerance: 0.01,
            step_falloff: false,
            variance_reference: 0.5,
            min_radius_scale: 0.1,
            max_accumulation_speed: 0.93,
        }
    }
}

impl TechniqueSettings for GiDenoiserSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "pass1_radius_m",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "pass2_radius_m",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "ao_radius_m",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "ao_hit_distance_scale",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "gi_hit_distance_scale",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "samples",
                range: Range::Int { lo: 1, hi: 32 },
            },
            Field {
                key: "ao_samples",
                range: Range::Int { lo: 1, hi: 64 },
            },
            Field {
                key: "min_radius_px",
                range: Range::Float { lo: 0.0, hi: 64.0 },
            },
            Field {
                key: "max_radius_px",
                range: Range::Float { lo: 1.0, hi: 256.0 },
            },
            Field {
                key: "radius_half_distance_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "plane_tolerance",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "variance_reference",
                range: Range::Float {
                    lo: 0.0625,
                    hi: 100.0,
                },
            },
            Field {
                key: "min_radius_scale",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "max_accumulation_speed",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
        ];
        F
    }

    fn preset(preset: Preset) -> Self {
        let (samples, ao_samples) = match preset {
            Preset::Low => (12, 16),
            Preset::Medium => (20, 32),
            Preset::High | Preset::Ultra => (32, 64),
        };
        Self {
            samples,
            ao_samples,
            ..Self::default()
        }
    }
}
