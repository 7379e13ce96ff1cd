//! Settings of the ray-traced GI and AO signal (`[ray_traced_gi]`).

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RayTracedGiSettings {
    /// Runs the technique at all (one diffuse ray a pixel, lit, encoded, accumulated).
    pub enabled: bool,
    /// Screen-space pre-trace against the depth buffer before the BVH.
    pub pretrace: bool,
    /// Screen-space step of the pre-trace, in pixels.
    pub pretrace_step_px: f32,
    /// Steps of the pre-trace at most.
    pub pretrace_max_steps: u32,
    /// How far behind the depth buffer a ray may be and still hit it, as a fraction of the
    /// surface's view depth (the depth buffer hides as much behind a surface at 30 m as a
    /// fixed 0.3 m; a fixed thickness is most of a small room seen from close by).
    pub pretrace_thickness: f32,
    /// Length of ray the pre-trace marches, in metres.
    pub pretrace_max_distance_m: f32,
    /// Trace what the pre-trace left through the BVH (off: those rays count as misses).
    pub bvh_trace: bool,
    /// Longest GI ray (the near field), in metres.
    pub max_distance_m: f32,
    /// Hits nearer than this occlude for AO, in metres.
    pub ao_max_distance_m: f32,
    /// Lights at hits: the sun or moon.
    pub sun: bool,
    /// The sun's shadow at hits from its shadow maps inside a cascade; off, or outside
    /// every cascade: a shadow ray through the BVH.
    pub shadow_maps: bool,
    /// Hits seen last frame take last frame's lit image there (Metro's "first bounce from all
    /// lights"); the others are lit as below.
    pub reuse_lit: bool,
    /// Lights at hits: the sky's ambient light (misses always take the sky).
    pub sky: bool,
    /// Lights at hits: point and spot lights (unshadowed).
    pub punctual: bool,
    /// Temporal accumulation (off: every frame is fresh, history length 1).
    pub accumulate: bool,
    /// Frames of history at most (the accumulation speed's floor is 1 / this).
    pub max_history: u32,
    /// History is rejected where its view depth differs from the reprojected point's by more
    /// than this fraction.
    pub depth_tolerance: f32,
    /// Firefly clamp of the temporal accumulation: a new sample's luminance (SH c0) is held
    /// to this many times the history's local scale (its 3x3 maximum) plus the metered floor
    /// (`reference::FireflyClamp`), the whole sample scaled with it; 0 turns it off. Unitless.
    pub firefly_clamp: f32,
    /// Russian roulette on the shadow ray of a hit's point, spot or area light: where that
    /// light's estimate (lux) is below this fraction of the frame's metered illuminance, the ray
    /// is traced with probability estimate / (fraction · metered) and the light divided by it,
    /// else the light is 0 (unbiased). Far, dim lamps at night cost few rays. 0: always traced.
    pub hit_shadow_roulette: f32,
    /// Cap on each GI sample's radiance, relative to the display: its luminance is held to
    /// this many times the radiance (nits) that the previous frame's exposure maps to display
    /// white, 1.2 · 2^EV100 (the CPU meter's EV100 on a first frame), the colour scaled with
    /// it. Stops one ray's hit beside a lamp (E = I / d²) from becoming a speckle that the
    /// firefly clamp and the denoiser spread. 0 turns it off. Unitless.
    pub hit_radiance_cap: f32,
    /// The deferred lighting takes its ambient light from the GI within this distance of the
    /// camera (metres) and from the probes or the sky beyond.
    pub near_field_m: f32,
    /// The fraction of the near field over which the GI blends into the far field.
    pub near_field_blend: f32,
}

impl Default for RayTracedGiSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            pretrace: true,
            pretrace_step_px: 4.0,
            pretrace_max_steps: 16,
            pretrace_thickness: 0.01,
            pretrace_max_distance_m: 10.0,
            bvh_trace: true,
            max_distance_m: 250.0,
            ao_max_distance_m: 50.0,
            sun: true,
            shadow_maps: true,
            reuse_lit: true,
            sky: true,
            punctual: true,
            accumulate: true,
            max_history: 32,
            depth_tolerance: 0.05,
            firefly_clamp: 8.0,
            hit_shadow_roulette: 1.0,
            hit_radiance_cap: 4.0,
            near_field_m: 250.0,
            near_field_blend: 0.2,
        }
    }
}

impl TechniqueSettings for RayTracedGiSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "pretrace_step_px",
                range: Range::Float { lo: 0.5, hi: 64.0 },
            },
            Field {
                key: "pretrace_max_steps",
                range: Range::Int { lo: 1, hi: 256 },
            },
            Field {
                key: "pretrace_thickness",
                range: Range::Float { lo: 0.0, hi: 1.0 },
            },
            Field {
                key: "pretrace_max_distance_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "max_distance_m",
                range: Range::Float {
                    lo: 0.5,
                    hi: 60_000.0,
                },
            },
            Field {
                key: "ao_max_distance_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 60_000.0,
                },
            },
            Field {
                key: "near_field_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 100_000.0,
                },
            },
            Field {
                key: "near_field_blend",
                range: Range::Float { lo: 0.001, hi: 1.0 },
            },
            Field {
                key: "max_history",
                range: Range::Int { lo: 1, hi: 1024 },
            },
            Field {
                key: "depth_tolerance",
                range: Range::Float { lo: 0.0, hi: 10.0 },
            },
            Field {
                key: "firefly_clamp",
                range: Range::Float {
                    lo: 0.0,
                    hi: 10_000.0,
                },
            },
            Field {
                key: "hit_shadow_roulette",
                range: Range::Float { lo: 0.0, hi: 100.0 },
            },
            Field {
                key: "hit_radiance_cap",
                range: Range::Float { lo: 0.0, hi: 1.0e6 },
            },
        ];
        F
    }

    fn preset(p: Preset) -> Self {
        match p {
            Preset::Low => Self {
                pretrace_max_steps: 8,
                max_distance_m: 100.0,
                ..Self::default()
            },
            Preset::Medium | Preset::High => Self::default(),
            Preset::Ultra => Self {
                pretrace_step_px: 2.0,
                pretrace_max_steps: 32,
                ..Self::default()
            },
        }
    }
}
