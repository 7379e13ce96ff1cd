//! Brute-force references: every triangle of every instance, no acceleration structure. Tests
//! compare the BVH traversal against these; they share only the triangle test and the
//! world-to-object transform with it.

use crate::blas::Blas;
use crate::layout::{Hit, InstanceRecord, Ray};
use crate::mesh::Mesh;
use crate::rng::SplitMix64;
use crate::tlas::{Instance, Tlas, world_to_object};
use crate::traverse::to_object_space;
use crate::triangle::{PreparedRay, intersect, is_degenerate};
use glam::{Vec3, Vec3A};

fn usable(m: &Mesh, tri: &[u32; 3]) -> Option<[[f32; 3]; 3]> {
    let v = tri.map(|i| m.positions.get(i as usize).copied());
    let [Some(a), Some(b), Some(c)] = v else {
        return None;
    };
    if !(a.is_finite() && b.is_finite() && c.is_finite())
        || is_degenerate(Vec3A::from(a), Vec3A::from(b), Vec3A::from(c))
    {
        return None;
    }
    Some([a.into(), b.into(), c.into()])
}

fn closest_in_mesh(m: &Mesh, r: &PreparedRay, t_max: &mut f32, best: &mut Hit, instance: u32) {
    for (p, tri) in m.indices.iter().enumerate() {
        let Some([a, b, c]) = usable(m, tri) else {
            continue;
        };
        if let Some((t, u, v)) = intersect(r, a, b, c, *t_max) {
            *t_max = t;
            *best = Hit {
                t,
                u,
                v,
                primitive: p as u32,
                instance,
                _pad: [0; 3],
            };
        }
    }
}

pub fn closest_hit_mesh(m: &Mesh, ray: &Ray) -> Option<Hit> {
    let r = PreparedRay::new(ray);
    let mut t = ray.t_max;
    let mut best = Hit::NONE;
    closest_in_mesh(m, &r, &mut t, &mut best, 0);
    best.is_hit().then_some(best)
}

pub fn any_hit_mesh(m: &Mesh, ray: &Ray) -> bool {
    let r = PreparedRay::new(ray);
    m.indices.iter().any(|tri| {
        usable(m, tri).is_some_and(|[a, b, c]| intersect(&r, a, b, c, ray.t_max).is_some())
    })
}

/// [`closest_hit_mesh`] where a hit on triangle `p` with `non_opaque[p]` counts only if
/// `accept(primitive, u, v)` says so: every triangle is tested, nothing is skipped by distance.
pub fn closest_hit_mesh_filtered(
    m: &Mesh,
    non_opaque: &[bool],
    ray: &Ray,
    mut accept: impl FnMut(u32, f32, f32) -> bool,
) -> Option<Hit> {
    let r = PreparedRay::new(ray);
    let mut best = Hit::NONE;
    for (p, tri) in m.indices.iter().enumerate() {
        let Some([a, b, c]) = usable(m, tri) else {
            continue;
        };
        if let Some((t, u, v)) = intersect(&r, a, b, c, ray.t_max)
            && t < best.t
            && (!non_opaque[p] || accept(p as u32, u, v))
        {
            best = Hit {
                t,
                u,
                v,
                primitive: p as u32,
                instance: 0,
                _pad: [0; 3],
            };
        }
    }
    best.is_hit().then_some(best)
}

/// [`any_hit_mesh`] with the filter of [`closest_hit_mesh_filtered`].
pub fn any_hit_mesh_filtered(
    m: &Mesh,
    non_opaque: &[bool],
    ray: &Ray,
    mut accept: impl FnMut(u32, f32, f32) -> bool,
) -> bool {
    let r = PreparedRay::new(ray);
    m.indices.iter().enumerate().any(|(p, tri)| {
        usable(m, tri).is_some_and(|[a, b, c]| {
            intersect(&r, a, b, c, ray.t_max)
                .is_some_and(|(_, u, v)| !non_opaque[p] || accept(p as u32, u, v))
        })
    })
}

fn record(inst: &Instance, index: usize) -> Option<InstanceRecord> {
    Some(InstanceRecord {
        world_to_object: world_to_object(&inst.transform)?,
        instance_index: index as u32,
        blas_index: inst.blas,
        ..Default::default()
    })
}

/// Closest hit over `selected` instances (all if `None`) of `meshes`.
pub fn closest_hit_instances(
    meshes: &[Mesh],
    instances: &[Instance],
    selected: Option<&[u32]>,
    ray: &Ray,
) -> Option<Hit> {
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let mut t_max = ray.t_max;
    let mut best = Hit::NONE;
    for &i in selected.unwrap_or(&all) {
        let inst = &instances[i as usize];
        let Some(rec) = record(inst, i as usize) else {
            continue;
        };
        let r = PreparedRay::new(&to_object_space(&rec, ray, t_max));
        closest_in_mesh(&meshes[inst.blas as usize], &r, &mut t_max, &mut best, i);
    }
    best.is_hit().then_some(best)
}

pub fn any_hit_instances(
    meshes: &[Mesh],
    instances: &[Instance],
    selected: Option<&[u32]>,
    ray: &Ray,
) -> bool {
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    selected.unwrap_or(&all).iter().any(|&i| {
        let inst = &instances[i as usize];
        record(inst, i as usize).is_some_and(|rec| {
            any_hit_mesh(
                &meshes[inst.blas as usize],
                &to_object_space(&rec, ray, ray.t_max),
            )
        })
    })
}

// Test support shared by hikari-bvh's tests and the GPU kernel's tests in hikari-render.

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

/// The hit comparison every traversal test uses (CPU, GPU, brute force): same primitive and
/// instance with t and barycentrics within 1e-4 relative (t relative to at least 1 cm), or a
/// tie: a different primitive at the same distance (1e-6 relative).
pub fn same_hit(got: Option<Hit>, want: Option<Hit>) -> Result<(), String> {
    match (got, want) {
        (None, None) => Ok(()),
        (Some(g), None) => Err(format!("hit {g:?}, expected a miss")),
        (None, Some(w)) => Err(format!("missed, expected {w:?}")),
        (Some(g), Some(w)) => {
            // t comes from coordinates of up to ~100 m, so it carries an absolute rounding error
            // of a few ulps of those (~1e-6 m; GPUs may also fuse multiply-adds differently).
            // That error dominates the relative rule for hits nearer than 1 cm, hence the floor.
            let scale = w.t.abs().max(1e-2);
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
                Err(format!("different primitive: {g:?} vs {w:?}"))
            }
        }
    }
}

/// Traces every ray through `tlas` (built over `selected` of `instances`) and against brute
/// force, closest and any hit; panics naming the first ray that disagrees. Returns the number
/// of rays that hit something.
pub fn assert_tlas_matches_brute_force(
    tlas: &Tlas,
    meshes: &[Mesh],
    blases: &[Blas],
    instances: &[Instance],
    selected: &[u32],
    rays: &[Ray],
) -> usize {
    let mut hits = 0;
    for (i, ray) in rays.iter().enumerate() {
        let want = closest_hit_instances(meshes, instances, Some(selected), ray);
        if let Err(e) = same_hit(tlas.closest_hit(blases, ray), want) {
            panic!("{} instances, ray {i} {ray:?}: {e}", selected.len());
        }
        hits += want.is_some() as usize;
        assert_eq!(
            tlas.any_hit(blases, ray),
            any_hit_instances(meshes, instances, Some(selected), ray),
            "{} instances: any hit disagrees on ray {i} {ray:?}",
            selected.len()
        );
    }
    hits
}
