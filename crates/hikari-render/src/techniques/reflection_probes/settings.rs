//! Settings of the relit reflection probes: the cube maps' size, how many are relit a frame,
//! the prefilter's samples, and a switch for each of the talk's terms.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReflectionProbesSettings {
    /// Reflection probes need the atmosphere (`sky.enabled`): they are relit by its sun and
    /// sky.
    pub enabled: bool,
    /// Texels along each side of a cube face (the talk: 256).
    pub resolution: u32,
    /// Roughness levels of the prefiltered cube maps: level k holds perceptual roughness
    /// k / (levels - 1); level 0 is the mirror.
    pub levels: u32,
    /// Probes relit each frame, round robin (the talk: 1). Every probe is relit on the first
    /// frame, after a camera cut, and when the sun has moved more than `relight_all_deg`.
    pub per_frame: u32,
    /// Degrees the sun (or moon) may move before every probe is relit at once.
    pub relight_all_deg: f32,
    /// A probe is resident (captured, relit and used) while the camera is within this many
    /// metres of its box; 0: every probe always.
    pub stream_distance_m: f32,
    /// GGX samples a texel of the prefilter takes (filtered importance sampling).
    pub samples: u32,
    /// The talk's cube-map shadow tracing (off: the sun lights every captured texel).
    pub shadow_tracing: bool,
    /// Texel radius of the shadow trace's PCF footprint (the talk: 4 x 4 texels, radius 2).
    pub shadow_pcf_radius: u32,
    /// The talk's horizon occlusion of the normal-mapped normal's reflection cone.
    pub horizon_occlusion: bool,
    /// The talk's roughness parallax compensation.
    pub roughness_parallax: bool,
    /// Scale each probe by the ratio of the surface's diffuse light to the light at the probe's
    /// capture point (the talk's luminance normalisation), at most `max_normalization`.
    pub normalization: bool,
    pub max_normalization: f32,
    /// Keep the prefiltered maps compressed to BC6H (encoded on the GPU as each probe is
    /// relit, docs/bc6h.md), as the talk does, where the adapter samples BC formats and every
    /// level is at least 4 texels wide; else they stay RGBA16F.
    pub compress: bool,
}

impl Default for ReflectionProbesSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            resolution: 128,
            levels: 6,
            per_frame: 1,
            relight_all_deg: 2.0,
            stream_distance_m: 60.0,
            samples: 32,
            shadow_tracing: true,
            shadow_pcf_radius: 2,
            horizon_occlusion: true,
            roughness_parallax: true,
            normalization: true,
            max_normalization: 2.0,
            compress: true,
        }
    }
}

impl TechniqueSettings for ReflectionProbesSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "resolution",
                range: Range::Int { lo: 8, hi: 1024 },
            },
            Field {
                key: "levels",
                range: Range::Int { lo: 1, hi: 8 },
            },
            Field {
                key: "per_frame",
                range: Range::Int { lo: 1, hi: 256 },
            },
            Field {
                key: "relight_all_deg",
                range: Range::Float { lo: 0.0, hi: 180.0 },
            },
            Field {
                key: "stream_distance_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 1_000_000.0,
                },
            },
            Field {
                key: "samples",
                range: Range::Int { lo: 1, hi: 1024 },
            },
            Field {
                key: "shadow_pcf_radius",
                range: Range::Int { lo: 0, hi: 8 },
            },
            Field {
                key: "max_normalization",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        let d = Self::default();
        match p {
            Preset::Low => Self {
                resolution: 64,
                samples: 16,
                ..d
            },
            Preset::Medium => Self {
                resolution: 128,
                samples: 24,
                ..d
            },
            Preset::High => d,
            Preset::Ultra => Self {
                resolution: 256,
                samples: 64,
                ..d
            },
        }
    }
}
