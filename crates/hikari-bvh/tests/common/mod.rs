#![allow(dead_code)]
//! Shared helpers: random rays and the hit comparison every traversal test uses.

use glam::Vec3;
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Hit, Ray};

pub fn random_dir(rng: &mut SplitMix64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// Rays from random points in `[-extent, extent]^3` in random directions; some are axis-aligned
/// (zero direction components exercise the reciprocal clamp), some have random t ranges.
pub fn random_rays(rng: &mut SplitMix64, count: usize, extent: f32) -> Vec<Ray> {
    (0..count)
        .map(|i| {
            let o = Vec3::new(
                rng.range(-extent, extent),
                rng.range(-extent, extent),
                rng.range(-extent, extent),
            );
            let d = match i % 7 {
                0 => [Vec3::X, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_X][rng.below(4)],
                1 => random_dir(rng) * rng.range(0.1, 10.0),
                _ => random_dir(rng),
            };
            let (t_min, t_max) = if i % 5 == 0 {
                (rng.range(0.0, extent), rng.range(0.0, 3.0 * extent))
            } else {
                (0.0, f32::INFINITY)
            };
            Ray::new(o, d, t_min, t_max)
        })
        .collect()
}

/// Same primitive and instance with t within 1e-4 relative, or a tie: a different primitive
/// at the same distance (1e-6 relative). `refit_t` re-tests the BVH's choice, when given.
pub fn same_hit(got: Option<Hit>, want: Option<Hit>) -> Result<(), String> {
    match (got, want) {
        (None, None) => Ok(()),
        (Some(g), None) => Err(format!("BVH hit {g:?}, brute force missed")),
        (None, Some(w)) => Err(format!("BVH missed, brute force hit {w:?}")),
        (Some(g), Some(w)) => {
            let scale = w.t.abs().max(1e-6);
            if g.primitive == w.primitive && g.instance == w.instance {
                if (g.t - w.t).abs() <= 1e-4 * scale
                    && (g.u - w.u).abs() <= 1e-4
                    && (g.v - w.v).abs() <= 1e-4
                {
                    Ok(())
                } else {
                    Err(format!("same primitive, different hit: {g:?} vs {w:?}"))
                }
            } else if (g.t - w.t).abs() <= 1e-6 * scale {
                Ok(())
            } else {
                Err(format!("different primitive: {g:?} vs brute force {w:?}"))
            }
        }
    }
}
