//! Where grid probes go: the ground under each grid column, and whether a probe sits inside
//! geometry (then it is lifted, or dropped when lifting does not free it).

use glam::Vec3;
use hikari_bvh::TraversalStacks;

use crate::scene_rays::SceneRays;
use crate::sky_visibility::SphereRays;

/// Surfaces the downward ray may pass through before giving up (stacked roofs, floors, leaves).
const MAX_GROUND_LAYERS: usize = 256;

/// How far past a hit the next downward ray starts (metres): clears the triangle just hit
/// without skipping a surface a centimetre below it.
const GROUND_STEP: f32 = 1e-3;

/// Ground height (metres, +Y up) under `(x, z)`: the lowest upward-facing surface a ray cast
/// straight down from `top` meets. The lowest rather than the first, so that roofs and tree
/// canopies do not lift the grid off the terrain (the talk's grid follows the terrain; buildings
/// get tetrahedral meshes). Without an upward-facing surface, the lowest surface of any kind;
/// without any surface, `fallback`.
pub fn ground_height(
    scene: &SceneRays,
    x: f32,
    z: f32,
    top: f32,
    fallback: f32,
    stacks: &mut TraversalStacks,
) -> (f32, u64) {
    let origin = Vec3::new(x, top, z);
    let mut t_min = 0.0;
    let mut lowest_up = None;
    let mut lowest_any = None;
    let mut rays = 0;
    for _ in 0..MAX_GROUND_LAYERS {
        rays += 1;
        let Some(hit) = scene.closest(origin, Vec3::NEG_Y, t_min, stacks) else {
            break;
        };
        let y = top - hit.t;
        lowest_any = Some(y);
        if !hit.back_face {
            lowest_up = Some(y);
        }
        t_min = hit.t + GROUND_STEP;
    }
    (lowest_up.or(lowest_any).unwrap_or(fallback), rays)
}

/// Whether `p` is inside geometry: more than `back_face_fraction` of the `rays` directions
/// first meet a surface from behind. Closed solids are wound outward, so from inside one every
/// ray sees a back face; from outside, only single-sided cards seen from behind do, a minority
/// for any sensible threshold (0.5 by default).
pub fn inside_geometry(
    scene: &SceneRays,
    rays: &SphereRays,
    p: Vec3,
    back_face_fraction: f32,
    stacks: &mut TraversalStacks,
) -> bool {
    let back = rays
        .directions
        .iter()
        .filter(|d| {
            scene
                .closest(p, **d, crate::sky_visibility::RAY_T_MIN, stacks)
                .is_some_and(|h| h.back_face)
        })
        .count();
    back as f32 > back_face_fraction * rays.len() as f32
}
