//! Settings of the frame's ray-tracing scene (`[scene_rt]`): the scene time, the TLAS culling
//! rule and the refit budget (docs/ray-traced-gi.md, "The BVH follows the frame").

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneRtSettings {
    /// Scene time in seconds at which deforming meshes (swaying trees, the water wheel) are
    /// drawn and traced. Absent (the default): every mesh in its rest pose, nothing refitted.
    pub time_s: Option<f32>,
    /// Cull the TLAS's instances around the camera each frame (off: every visible instance).
    pub cull: bool,
    /// Metres the view frustum is widened by on every side before culling: a ray that starts
    /// on screen and travels at most this far only meets kept instances.
    pub cull_margin_m: f32,
    /// Every instance whose box lies within this many metres of the camera is kept as well,
    /// wherever it is (rays of off-screen surfaces near the camera, shadows from behind).
    pub keep_radius_m: f32,
    /// BLAS refits a frame taken by priority (Metro Exodus: 16).
    pub refits_per_frame: u32,
    /// BLAS refits a frame taken at random among the other stale ones (Metro Exodus: 4).
    pub random_refits_per_frame: u32,
    /// Vertices refitted a frame at most (the first pick is refitted whatever its size).
    pub refit_vertex_budget: u32,
}

impl Default for SceneRtSettings {
    fn default() -> Self {
        Self {
            time_s: None,
            cull: true,
            cull_margin_m: 64.0,
            keep_radius_m: 64.0,
            refits_per_frame: 16,
            random_refits_per_frame: 4,
            refit_vertex_budget: 1 << 20,
        }
    }
}

impl TechniqueSettings for SceneRtSettings {
    fn fields() -> &'static [Field] {
        const F: &[Field] = &[
            Field {
                key: "time_s",
                range: Range::Float {
                    lo: -1.0e6,
                    hi: 1.0e6,
                },
            },
            Field {
                key: "cull_margin_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 60_000.0,
                },
            },
            Field {
                key: "keep_radius_m",
                range: Range::Float {
                    lo: 0.0,
                    hi: 60_000.0,
                },
            },
            Field {
                key: "refits_per_frame",
                range: Range::Int { lo: 0, hi: 4096 },
            },
            Field {
                key: "random_refits_per_frame",
                range: Range::Int { lo: 0, hi: 4096 },
            },
            Field {
                key: "refit_vertex_budget",
                range: Range::Int { lo: 0, hi: 1 << 30 },
            },
        ];
        F
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}
