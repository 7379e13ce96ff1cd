//! Brute-force references: every triangle of every instance, no acceleration structure. Tests
//! compare the BVH traversal against these; they share only the triangle test and the
//! world-to-object transform with it.

use crate::layout::{Hit, InstanceRecord, Ray};
use crate::mesh::Mesh;
use crate::tlas::{Instance, world_to_object};
use crate::traverse::to_object_space;
use crate::triangle::{PreparedRay, intersect, is_degenerate};
use glam::Vec3A;

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
