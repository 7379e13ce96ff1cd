//! Settings of the polygonal area lights and of the ray-traced shadows of point and spot
//! lights (docs/area-lights.md).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AreaLightsSettings {
    /// The pass runs: polygonal lights, and point and spot lights when `punctual_shadows`.
    pub enabled: bool,
    /// Shadow rays per pixel towards each shaded area light.
    pub shadow_rays: u32,
    /// Area lights shaded per pixel at most: the ones of largest flux / distance² there.
    pub lights_per_pixel: u32,
    /// Point and spot lights are shaded by this pass, with ray-traced shadows, instead of
    /// unshadowed by the deferred lighting.
    pub punctual_shadows: bool,
    /// Point and spot lights that get shadow rays per pixel: the ones of largest illuminance
    /// there; the others are added unshadowed.
    pub shadowed_punctual_per_pixel: u32,
    /// Shadow rays per pixel towards each shadowed point or spot light.
    pub punctual_shadow_rays: u32,
    /// Radius of point and spot lights in metres (the scene model gives them none): the
    /// softness of their shadows.
    pub punctual_radius_m: f32,
    /// An emissive mesh instance without an `area_light` flag becomes an area light only if it
    /// emits at least this luminous flux (π × luminance × area, lumens).
    pub min_flux_lm: f32,
}

impl Default for AreaLightsSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            shadow_rays: 4,
            lights_per_pixel: 4,
            punctual_shadows: true,
            shadowed_punctual_per_pixel: 2,
            punctual_shadow_rays: 2,
            punctual_radius_m: 0.05,
            min_flux_lm: 50.0,
        }
    }
}

/// Most lights per pixel the shader keeps (its selection arrays' length).
pub const MAX_LIGHTS_PER_PIXEL: u32 = 8;

impl TechniqueSettings for AreaLightsSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "shadow_rays",
                range: Range::Int { lo: 0, hi: 32 },
            },
            Field {
                key: "lights_per_pixel",
                range: Range::Int {
                    lo: 1,
                    hi: MAX_LIGHTS_PER_PIXEL as i64,
                },
            },
            Field {
                key: "shadowed_punctual_per_pixel",
                range: Range::Int {
                    lo: 0,
                    hi: MAX_LIGHTS_PER_PIXEL as i64,
                },
            },
            Field {
                key: "punctual_shadow_rays",
                range: Range::Int { lo: 0, hi: 32 },
            },
            Field {
                key: "punctual_radius_m",
                range: Range::Float { lo: 0.0, hi: 10.0 },
            },
            Field {
                key: "min_flux_lm",
                range: Range::Float { lo: 0.0, hi: 1e12 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            Preset::Low => Self {
                shadow_rays: 1,
                lights_per_pixel: 2,
                shadowed_punctual_per_pixel: 1,
                punctual_shadow_rays: 1,
                ..d
            },
            Preset::Medium => Self {
                shadow_rays: 2,
                lights_per_pixel: 3,
                shadowed_punctual_per_pixel: 1,
                punctual_shadow_rays: 1,
                ..d
            },
            Preset::High => d,
            Preset::Ultra => Self {
                shadow_rays: 8,
                lights_per_pixel: 8,
                shadowed_punctual_per_pixel: 4,
                punctual_shadow_rays: 4,
                ..d
            },
        }
    }
}
