//! Settings of the clouds: the layer, its coverage and density, the phase function of the
//! talk, and the paraboloid map's size, march and time slicing.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CloudsSettings {
    /// Clouds need the atmosphere (`sky.enabled`): they are lit by its sun and sky.
    pub enabled: bool,
    /// Fraction of the sky covered in clear weather, 0 to 1; `hazy` adds 0.1, `overcast` 0.55.
    pub coverage: f32,
    /// Extinction inside a cloud at full density, per metre.
    pub density: f32,
    /// Altitude of the layer's base above the ground, and its thickness, metres.
    pub bottom_m: f32,
    pub thickness_m: f32,
    /// Size of the largest noise features, metres.
    pub feature_m: f32,
    /// Where the noise's origin lies, world metres (the wind's offset: move it to move the
    /// clouds).
    pub offset_x_m: f32,
    pub offset_z_m: f32,
    /// Wind speed at the clouds, m/s: the noise moves this far every second of the day (the
    /// sky's clock), so a time-lapse shows the clouds drift.
    pub wind_mps: f32,
    /// Where the wind blows towards, degrees clockwise from north (+Z; east is -X).
    pub wind_towards_deg: f32,
    /// Single-scattering albedo of the droplets.
    pub albedo: f32,
    /// The talk's phase: HG with `forward_g` where light passes mostly unscattered, with
    /// `backward_g` scaled by `backward_scale` (multiple scattering) deep in the cloud.
    pub forward_g: f32,
    pub backward_g: f32,
    pub backward_scale: f32,
    /// Add light scattered more than once as octaves of weaker extinction (Wrenninge 2013), so
    /// that the bases of thick clouds are not black; off, the talk's phase alone.
    pub multiple_scattering: bool,
    /// Shadow the sun's light on the ground and in the haze.
    pub shadows: bool,
    /// The clouds enter the sky's SH: the sky's ambient light, the irradiance probes' and the
    /// haze's sky light see them (off: the clear sky's).
    pub ambient: bool,
    /// Texels along each side of the shadow map, which holds the sun's transmittance through
    /// the layer on a square of the layer's base around the camera; 0: every pass marches the
    /// layer itself at each point.
    pub shadow_map_size: u32,
    /// Side of the shadow map's square, metres. Points whose path to the sun enters the layer
    /// outside it march the layer themselves.
    pub shadow_map_extent_m: f32,
    /// Fade the noise octaves a map texel's footprint would alias (the talk's cloud density
    /// anti-aliasing).
    pub density_aa: bool,
    /// Texels along each side of the paraboloid map, at most: a view that needs fewer (a
    /// texel a pixel at the zenith, `clouds::map_size_for`) marches a smaller map.
    pub map_size: u32,
    /// Samples along each view ray, and towards the light from each.
    pub steps: u32,
    pub light_steps: u32,
    /// The most metres a view ray marches through the layer (rays near the horizon graze it).
    pub max_march_m: f32,
    /// The map is redrawn a row in this many each frame (the talk: 60); it is drawn whole
    /// when anything that shapes or lights it changes.
    pub time_slices: u32,
}

impl Default for CloudsSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            coverage: 0.35,
            density: 0.005,
            bottom_m: 1500.0,
            thickness_m: 2500.0,
            feature_m: 6000.0,
            offset_x_m: 0.0,
            offset_z_m: 0.0,
            wind_mps: 8.0,
            wind_towards_deg: 70.0,
            albedo: 0.9,
            forward_g: 0.85,
            backward_g: -0.15,
            backward_scale: 2.16,
            multiple_scattering: true,
            shadows: true,
            ambient: true,
            shadow_map_size: 512,
            shadow_map_extent_m: 4096.0,
            density_aa: true,
            map_size: 768,
            steps: 48,
            light_steps: 6,
            max_march_m: 40_000.0,
            time_slices: 60,
        }
    }
}

impl CloudsSettings {
    /// Where the noise's origin lies `seconds` into the day: the offset moved by the wind.
    pub fn offset_at(&self, seconds: f64) -> [f32; 2] {
        let a = f64::from(self.wind_towards_deg).to_radians();
        let d = f64::from(self.wind_mps) * seconds;
        [
            (f64::from(self.offset_x_m) - a.sin() * d) as f32,
            (f64::from(self.offset_z_m) + a.cos() * d) as f32,
        ]
    }

    /// Coverage in a weather preset.
    pub fn coverage_in(&self, weather: &str) -> f32 {
        let extra = match weather {
            "hazy" => 0.1,
            "overcast" => 0.55,
            _ => 0.0,
        };
        (self.coverage + extra).clamp(0.0, 1.0)
    }
}

impl TechniqueSettings for CloudsSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "coverage",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "density",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "bottom_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 20_000.0,
                },
            },
            Field {
                key: "thickness_m",
                range: Range::Float {
                    lo: 1.0,
                    hi: 20_000.0,
                },
            },
            Field {
                key: "feature_m",
                range: Range::Float {
                    lo: 10.0,
                    hi: 1_000_000.0,
                },
            },
            Field {
                key: "offset_x_m",
                range: Range::Float { lo: -1e7, hi: 1e7 },
            },
            Field {
                key: "offset_z_m",
                range: Range::Float { lo: -1e7, hi: 1e7 },
            },
            Field {
                key: "wind_mps",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "wind_towards_deg",
                range: Range::Float { lo: 0.0, hi: 360.0 },
            },
            Field {
                key: "shadow_map_size",
                range: Range::Int { lo: 0, hi: 4096 },
            },
            Field {
                key: "shadow_map_extent_m",
                range: Range::Float {
                    lo: 100.0,
                    hi: 1_000_000.0,
                },
            },
            Field {
                key: "albedo",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "forward_g",
                range: Range::Float {
                    lo: -0.95,
                    hi: 0.95,
                },
            },
            Field {
                key: "backward_g",
                range: Range::Float {
                    lo: -0.95,
                    hi: 0.95,
                },
            },
            Field {
                key: "backward_scale",
                range: Range::Float { lo: 0.0, hi: 4.0 },
            },
            Field {
                key: "map_size",
                range: Range::Int { lo: 16, hi: 4096 },
            },
            Field {
                key: "steps",
                range: Range::Int { lo: 1, hi: 512 },
            },
            Field {
                key: "light_steps",
                range: Range::Int { lo: 1, hi: 64 },
            },
            Field {
                key: "max_march_m",
                range: Range::Float {
                    lo: 10.0,
                    hi: 1_000_000.0,
                },
            },
            Field {
                key: "time_slices",
                range: Range::Int { lo: 1, hi: 256 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            Preset::Low => Self {
                map_size: 256,
                steps: 24,
                light_steps: 4,
                ..d
            },
            Preset::Medium => Self {
                map_size: 512,
                steps: 32,
                light_steps: 5,
                ..d
            },
            Preset::High => d,
            Preset::Ultra => Self {
                map_size: 1024,
                steps: 64,
                light_steps: 8,
                ..d
            },
        }
    }
}
