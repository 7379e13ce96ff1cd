//! Sky visibility of one point as mono L2 SH: `c_i = ∫ V(ω) Y_i(ω) dω`, where `V` is 1 for a
//! direction whose ray leaves the scene (it sees the sky, or below the horizon the sky model's
//! ground) and 0 for one that hits geometry. Estimated with a fixed Fibonacci sphere of `n`
//! directions, each standing for `4π / n` steradians, so the weights are `4π / n · Y_i(ω_k)`.
//! SH order and basis: `hikari_math::sh` (l=0; l=1 m=-1,0,1; l=2 m=-2..2, real orthonormal).

use glam::Vec3;
use hikari_bvh::TraversalStacks;
use hikari_math::sampling::sphere::fibonacci_sphere;
use hikari_math::sh::basis::eval_l2_f64;

use crate::scene_rays::SceneRays;

/// Rays start this far from the probe (metres), so a probe that touches a surface does not
/// count the surface it sits on twice; far below the 12.5 m probe spacing.
pub const RAY_T_MIN: f32 = 1e-3;

/// The ray directions of one bake and their projection weights.
#[derive(Clone, Debug)]
pub struct SphereRays {
    pub directions: Vec<Vec3>,
    /// Per direction: `4π / n · Y_i(ω)`, the solid angle it stands for times the basis.
    pub weights: Vec<[f64; 9]>,
}

impl SphereRays {
    /// `n` Fibonacci-sphere directions (n ≥ 1).
    pub fn fibonacci(n: u32) -> Self {
        let n = n.max(1);
        let solid_angle = 4.0 * std::f64::consts::PI / f64::from(n);
        let directions: Vec<Vec3> = (0..n).map(|i| fibonacci_sphere(i, n).normalize()).collect();
        let weights = directions
            .iter()
            .map(|d| eval_l2_f64(d.as_dvec3()).map(|y| y * solid_angle))
            .collect();
        Self {
            directions,
            weights,
        }
    }

    pub fn len(&self) -> usize {
        self.directions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }
}

/// Sky visibility SH at `position`: one any-hit ray per direction of `rays`.
pub fn sky_visibility(
    scene: &SceneRays,
    rays: &SphereRays,
    position: Vec3,
    stacks: &mut TraversalStacks,
) -> [f32; 9] {
    let mut acc = [0.0f64; 9];
    for (d, w) in rays.directions.iter().zip(&rays.weights) {
        if !scene.occluded(position, *d, RAY_T_MIN, stacks) {
            for (a, w) in acc.iter_mut().zip(w) {
                *a += w;
            }
        }
    }
    acc.map(|c| c as f32)
}
