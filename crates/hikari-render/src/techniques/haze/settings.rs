//! Settings of the volumetric haze: its two analytic density layers, how it scatters, what
//! lights it, and its froxel grid.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, SettingError, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HazeSettings {
    /// The haze needs the atmosphere (`sky.enabled`): the placeholder sky has no SH to light
    /// it, and a haze lit by the sun alone would darken that sky.
    pub enabled: bool,
    /// Extinction of the exponential layer at `height_m`, per metre (1e-4: a visibility of
    /// about 40 km at that height).
    pub density: f32,
    /// Scale height of the exponential layer in metres: the density falls by e every
    /// `falloff_m` upwards (the talk's k_e).
    pub falloff_m: f32,
    /// World height (y, metres) at which the exponential layer has `density`.
    pub height_m: f32,
    /// Extinction of the sigmoidal layer far below `layer_height_m`, per metre (the talk's
    /// d_0; 0 turns the layer off). Ground fog: 0.005 to 0.05.
    pub layer_density: f32,
    /// Extinction of the sigmoidal layer far above `layer_height_m` (the talk's d_1, "zero in
    /// almost all cases").
    pub layer_top_density: f32,
    /// World height (y, metres) of the sigmoidal layer's middle.
    pub layer_height_m: f32,
    /// Half-width of the sigmoid's transition in metres (the talk's k_s).
    pub layer_thickness_m: f32,
    /// Single-scattering albedo: scattering over extinction (the talk's c).
    pub albedo: f32,
    /// Henyey-Greenstein asymmetry of the haze's phase function (positive: forward, Mie-like).
    pub anisotropy: f32,
    /// Multiplies both layers' densities in `hazy` (x4) and `overcast` (x3) weather as well:
    /// the weather's factor times this.
    pub weather_scale: f32,
    /// Light the haze by the sun or moon.
    pub sun: bool,
    /// Look the sun up in the sun shadow maps per froxel (light shafts); off, the haze is lit
    /// as if nothing cast a shadow.
    pub sun_shadows: bool,
    /// Light the haze by the sky (its L2 SH convolved with the phase function).
    pub sky: bool,
    /// Darken the sky's light by the sky visibility the irradiance probes give at each froxel
    /// (the talk's haze AO: no skylit haze inside a house); off, or where no probe covers the
    /// froxel, the haze sees the whole sky.
    pub sky_occlusion: bool,
    /// Points along each froxel's depth at which the sky visibility is looked up and averaged:
    /// the probes' visibility changes over less than a distant slice's thickness, and one
    /// lookup at the middle draws the slices as bands.
    pub sky_occlusion_samples: u32,
    /// Light the haze by point and spot lights (unshadowed).
    pub local_lights: bool,
    /// Store inscattered light over opacity (L / alpha) and re-apply each pixel's exact
    /// opacity (the talk's density anti-aliasing); off, the grid's own opacity is used.
    pub density_aa: bool,
    /// Sample the grid with a tricubic B-spline (8 trilinear taps); off, trilinearly.
    pub tricubic: bool,
    /// The talk's temporal filtering: each frame lights every froxel at a jittered point
    /// (Halton, a 16-frame cycle) and blends it with last frame's grid, reprojected; off, at the
    /// froxel's centre, alone.
    pub temporal: bool,
    /// The history's weight in that blend (0 to 0.95).
    pub temporal_blend: f32,
    /// Froxels across the screen.
    pub grid_width: u32,
    /// Froxels down the screen.
    pub grid_height: u32,
    /// Depth slices.
    pub slices: u32,
    /// Depth where the first slice starts, metres.
    pub near_m: f32,
    /// Depth where the last slice ends, metres; the sky is taken at this distance.
    pub far_m: f32,
    /// Each slice is this much thicker than the one before (1.2: 20 %, as in the talk). With
    /// many slices and a large growth the first slices would be thinner than a millionth of
    /// the range; they are held at that thickness (and the last ends beyond `far_m`).
    pub slice_growth: f32,
}

impl Default for HazeSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            density: 1e-4,
            falloff_m: 400.0,
            height_m: 0.0,
            layer_density: 0.0,
            layer_top_density: 0.0,
            layer_height_m: 2.0,
            layer_thickness_m: 3.0,
            albedo: 0.9,
            anisotropy: 0.6,
            weather_scale: 1.0,
            sun: true,
            sun_shadows: true,
            sky: true,
            sky_occlusion: true,
            sky_occlusion_samples: 4,
            local_lights: true,
            density_aa: true,
            tricubic: true,
            temporal: true,
            temporal_blend: 0.9,
            grid_width: 128,
            grid_height: 64,
            slices: 64,
            near_m: 0.1,
            far_m: 100_000.0,
            slice_growth: 1.2,
        }
    }
}

impl HazeSettings {
    /// The density factor of a weather preset: hazy and overcast air hold more aerosol.
    pub fn weather_factor(weather: &str) -> f32 {
        match weather {
            "hazy" => 4.0,
            "overcast" => 3.0,
            _ => 1.0,
        }
    }
}

impl TechniqueSettings for HazeSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "density",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "falloff_m",
                range: Range::Float {
                    lo: 0.1,
                    hi: 100_000.0,
                },
            },
            Field {
                key: "height_m",
                range: Range::Float {
                    lo: -10_000.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "layer_density",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "layer_top_density",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "layer_height_m",
                range: Range::Float {
                    lo: -10_000.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "layer_thickness_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "albedo",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "anisotropy",
                range: Range::Float {
                    lo: -0.95,
                    hi: 0.95,
                },
            },
            Field {
                key: "weather_scale",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "grid_width",
                range: Range::Int { lo: 1, hi: 512 },
            },
            Field {
                key: "grid_height",
                range: Range::Int { lo: 1, hi: 512 },
            },
            Field {
                key: "slices",
                range: Range::Int { lo: 2, hi: 256 },
            },
            Field {
                key: "sky_occlusion_samples",
                range: Range::Int { lo: 1, hi: 16 },
            },
            Field {
                key: "near_m",
                // Bounds that f32 holds exactly.
                range: Range::Float {
                    lo: 0.015625,
                    hi: 1000.0,
                },
            },
            Field {
                key: "far_m",
                range: Range::Float {
                    lo: 1.0,
                    hi: 1_000_000.0,
                },
            },
            Field {
                key: "temporal_blend",
                range: Range::Float { lo: 0.0, hi: 0.95 },
            },
            Field {
                key: "slice_growth",
                range: Range::Float {
                    lo: 1.0078125,
                    hi: 2.0,
                },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            Preset::Low => Self {
                grid_width: 64,
                grid_height: 32,
                slices: 48,
                slice_growth: 1.27,
                tricubic: false,
                ..d
            },
            Preset::Medium => Self {
                grid_width: 96,
                grid_height: 48,
                slices: 64,
                ..d
            },
            Preset::High => d,
            Preset::Ultra => Self {
                grid_width: 160,
                grid_height: 90,
                slices: 96,
                slice_growth: 1.13,
                ..d
            },
        }
    }

    fn validate(&self, table: &str) -> Result<(), SettingError> {
        self.check_fields(table)?;
        if self.far_m <= self.near_m * 2.0 {
            return Err(SettingError {
                field: format!("{table}.far_m"),
                value: self.far_m.to_string(),
                allowed: format!("more than twice near_m ({})", self.near_m),
            });
        }
        Ok(())
    }
}
