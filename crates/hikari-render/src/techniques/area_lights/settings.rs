//! Settings of the polygonal area lights and of the ray-traced shadows of point and spot
//! lights (docs/area-lights.md).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AreaLightsSettings {
    /// The pass runs: polygonal lights, and point and spot lights when `punctual_shadows`.
    pub enabled: bool,
    /// Shadow rays per pixel per frame, in total over every area, point and spot light the
    /// pixel shades (0: all unshadowed). They go to at most [`MAX_SHADOW_PICKS`] lights picked
    /// at random in proportion to each light's unshadowed radiance there
    /// (docs/area-lights.md, "The shadow-ray budget").
    pub ray_budget: u32,
    /// Area lights shaded per pixel at most: the ones of largest flux / distance² there.
    pub lights_per_pixel: u32,
    /// Point and spot lights are shaded by this pass, with ray-traced shadows, instead of
    /// unshadowed by the deferred lighting.
    pub punctual_shadows: bool,
    /// Radius in metres of the point and spot lights that give none of their own
    /// (`Light::radius_m`, glTF light `extras` `hikari.radius`): the softness of their shadows.
    pub punctual_radius_m: f32,
    /// An emissive mesh instance without an `area_light` flag becomes an area light only if it
    /// emits at least this luminous flux (π × luminance × area, lumens).
    pub min_flux_lm: f32,
    /// Denoise the shadows: the visibility (shadowed over unshadowed light) accumulated over
    /// frames and filtered spatially, times the noise-free unshadowed light
    /// (docs/area-lights.md, "Denoising the shadows").
    pub denoise: bool,
    /// Frames the accumulated visibility averages at most (its history length's cap).
    pub denoise_history: u32,
    /// Radius in pixels of the spatial filter on a fresh history; it shrinks as
    /// radius / sqrt(history length) while the history grows (0: no spatial filter).
    pub denoise_radius_px: f32,
}

impl Default for AreaLightsSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            ray_budget: 2,
            lights_per_pixel: 4,
            punctual_shadows: true,
            punctual_radius_m: 0.05,
            min_flux_lm: 50.0,
            denoise: true,
            denoise_history: 16,
            denoise_radius_px: 3.0,
        }
    }
}

/// Most lights per pixel the shader keeps (its selection arrays' length).
pub const MAX_LIGHTS_PER_PIXEL: u32 = 8;

/// Most lights a pixel picks for its shadow rays per frame (the shader's arrays): a
/// budget above this splits its rays over the picks.
pub const MAX_SHADOW_PICKS: u32 = 8;

/// Largest `ray_budget`.
pub const MAX_RAY_BUDGET: u32 = 32;

/// Largest `denoise_history`.
pub const MAX_DENOISE_HISTORY: u32 = 64;

/// Largest `denoise_radius_px` (the spatial filter's taps are a square of side 2 × 8 + 1).
pub const MAX_DENOISE_RADIUS_PX: f32 = 8.0;

impl TechniqueSettings for AreaLightsSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "ray_budget",
                range: Range::Int {
                    lo: 0,
                    hi: MAX_RAY_BUDGET as i64,
                },
            },
            Field {
                key: "lights_per_pixel",
                range: Range::Int {
                    lo: 1,
                    hi: MAX_LIGHTS_PER_PIXEL as i64,
                },
            },
            Field {
                key: "punctual_radius_m",
                range: Range::Float { lo: 0.0, hi: 10.0 },
            },
            Field {
                key: "min_flux_lm",
                range: Range::Float { lo: 0.0, hi: 1e12 },
            },
            Field {
                key: "denoise_history",
                range: Range::Int {
                    lo: 1,
                    hi: MAX_DENOISE_HISTORY as i64,
                },
            },
            Field {
                key: "denoise_radius_px",
                range: Range::Float {
                    lo: 0.0,
                    hi: MAX_DENOISE_RADIUS_PX as f64,
                },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            Preset::Low => Self {
                ray_budget: 1,
                lights_per_pixel: 2,
                ..d
            },
            Preset::Medium => Self {
                ray_budget: 1,
                lights_per_pixel: 3,
                ..d
            },
            Preset::High => d,
            Preset::Ultra => Self {
                ray_budget: 8,
                lights_per_pixel: 8,
                ..d
            },
        }
    }
}
