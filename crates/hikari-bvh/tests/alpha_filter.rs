//! Hits that a filter can reject (alpha cut-outs): traversal with a filter against brute force
//! over every triangle, for closest and any hit, in one BLAS and through a TLAS.

use glam::{Affine3A, Vec3};
use hikari_bvh::layout::InstanceRecord;
use hikari_bvh::reference::{
    any_hit_mesh_filtered, closest_hit_mesh_filtered, random_dir, random_rays, same_hit,
};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::tlas::world_to_object;
use hikari_bvh::traverse::to_object_space;
use hikari_bvh::{Blas, BuildOptions, BvhError, Instance, Mesh, Ray, Tlas};

/// Cut-out rule of the tests: keep the half of a triangle where the weight of `v2` is at least
/// that of `v1`.
fn keep_half(u: f32, v: f32) -> bool {
    v >= u
}

/// Four stacked unit quads (z = 0..3, each turned a little) over an opaque floor at z = 5, and
/// a soup of small triangles around them. Quads 0 and 2 and every other soup triangle are cut
/// out; returns the mesh and its marks.
fn scene() -> (Mesh, Vec<bool>) {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut marks = Vec::new();
    let quad = |positions: &mut Vec<Vec3>, z: f32, half: f32, turn: f32| {
        let base = positions.len() as u32;
        let (s, c) = turn.sin_cos();
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            positions.push(Vec3::new(half * (c * x - s * y), half * (s * x + c * y), z));
        }
        [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    };
    for (k, z) in [0.0f32, 1.0, 2.0, 3.0].into_iter().enumerate() {
        indices.extend(quad(&mut positions, z, 1.0, 0.3 * k as f32));
        marks.extend([k % 2 == 0; 2]);
    }
    indices.extend(quad(&mut positions, 5.0, 4.0, 0.0));
    marks.extend([false; 2]);
    let soup = Mesh::random_soup(21, 3000, 6.0, 0.7);
    let base = positions.len() as u32;
    positions.extend(&soup.positions);
    for (i, t) in soup.indices.iter().enumerate() {
        indices.push(t.map(|j| j + base));
        marks.push(i % 2 == 0);
    }
    (Mesh::new(positions, indices), marks)
}

/// Rays through the quads from both sides, and rays in every direction through the soup.
fn rays(rng: &mut SplitMix64) -> Vec<Ray> {
    let mut rays = random_rays(rng, 1000, 8.0);
    for i in 0..3000 {
        let target = Vec3::new(
            rng.range(-1.2, 1.2),
            rng.range(-1.2, 1.2),
            rng.range(0.0, 3.0),
        );
        let mut d = random_dir(rng);
        d.z = d.z.abs() + 0.5;
        // Half from below the stack, half from above it (back faces first).
        let d = if i % 2 == 0 { d } else { -d };
        let origin = target - d * 10.0;
        let t_max = if i % 5 == 0 { 10.5 } else { f32::INFINITY };
        rays.push(Ray::new(origin, d, 0.0, t_max));
    }
    rays
}

fn build(mesh: &Mesh, marks: &[bool], threads: usize) -> Blas {
    Blas::build_with_opacity(
        "cut-outs",
        &mesh.positions,
        &mesh.indices,
        marks,
        &BuildOptions {
            threads,
            ..Default::default()
        },
    )
    .expect("builds")
}

#[test]
fn filtered_blas_traversal_matches_brute_force() {
    let (mesh, marks) = scene();
    let blas = build(&mesh, &marks, 2);
    let mut rng = SplitMix64::new(31);
    let (mut rejected_somewhere, mut hits, mut occluded_differs) = (0, 0, 0);
    for (i, ray) in rays(&mut rng).iter().enumerate() {
        let mut calls = 0;
        let got = blas.intersect_filtered(ray, |inst, p, u, v| {
            assert_eq!(inst, 0);
            assert!(marks[p as usize], "filter called for opaque triangle {p}");
            calls += 1;
            keep_half(u, v)
        });
        let want = closest_hit_mesh_filtered(&mesh, &marks, ray, |_, u, v| keep_half(u, v));
        if let Err(e) = same_hit(got, want) {
            panic!("closest hit, ray {i} {ray:?}: {e}");
        }
        let got_any = blas.occluded_filtered(ray, |_, p, u, v| {
            assert!(marks[p as usize], "filter called for opaque triangle {p}");
            keep_half(u, v)
        });
        let want_any = any_hit_mesh_filtered(&mesh, &marks, ray, |_, u, v| keep_half(u, v));
        assert_eq!(got_any, want_any, "any hit, ray {i} {ray:?}");
        // The filter must change results for the test to mean anything.
        let unfiltered = blas.intersect(ray);
        hits += want.is_some() as usize;
        rejected_somewhere +=
            (calls > 0 && unfiltered.map(|h| h.primitive) != want.map(|h| h.primitive)) as usize;
        occluded_differs += (blas.occluded(ray) != want_any) as usize;
    }
    assert!(hits > 1500, "{hits} rays hit");
    assert!(
        rejected_somewhere > 300,
        "only {rejected_somewhere} rays saw a cut-out"
    );
    assert!(
        occluded_differs > 20,
        "only {occluded_differs} rays passed through cut-outs"
    );
}

#[test]
fn rejecting_everything_leaves_the_opaque_triangles_and_accepting_everything_changes_nothing() {
    let (mesh, marks) = scene();
    let flagged = build(&mesh, &marks, 1);
    let plain = Blas::from_mesh("plain", &mesh, &BuildOptions::default()).unwrap();
    // The marks change no node and only the flags word of the records.
    assert_eq!(flagged.nodes, plain.nodes);
    for (f, p) in flagged.triangles.iter().zip(&plain.triangles) {
        assert_eq!(f.flags, marks[f.primitive as usize] as u32);
        assert_eq!(p.flags, 0);
        assert_eq!(
            (f.v0, f.v1, f.v2, f.primitive),
            (p.v0, p.v1, p.v2, p.primitive)
        );
    }
    let opaque_only = Mesh::new(
        mesh.positions.clone(),
        mesh.indices
            .iter()
            .zip(&marks)
            .filter(|(_, m)| !**m)
            .map(|(t, _)| *t)
            .collect(),
    );
    let opaque_ids: Vec<u32> = (0..mesh.indices.len() as u32)
        .filter(|&p| !marks[p as usize])
        .collect();
    let mut rng = SplitMix64::new(32);
    for (i, ray) in rays(&mut rng).iter().enumerate() {
        let all = flagged.intersect_filtered(ray, |_, _, _, _| true);
        assert_eq!(all, flagged.intersect(ray), "ray {i}");
        assert_eq!(all, plain.intersect(ray), "ray {i}");
        let none = flagged.intersect_filtered(ray, |_, _, _, _| false);
        let want = hikari_bvh::reference::closest_hit_mesh(&opaque_only, ray).map(|mut h| {
            h.primitive = opaque_ids[h.primitive as usize];
            h
        });
        if let Err(e) = same_hit(none, want) {
            panic!("ray {i} {ray:?}: {e}");
        }
        assert_eq!(
            flagged.occluded_filtered(ray, |_, _, _, _| false),
            want.is_some(),
            "ray {i}"
        );
    }
}

#[test]
fn filtered_tlas_traversal_matches_brute_force_per_instance() {
    let (mesh, marks) = scene();
    let blases = vec![build(&mesh, &marks, 1)];
    let transforms = [
        Affine3A::IDENTITY,
        Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_y(0.4),
            Vec3::new(3.0, 0.5, 2.0),
        ),
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(0.7),
            glam::Quat::from_rotation_x(-0.3),
            Vec3::new(-2.0, 1.0, -1.0),
        ),
    ];
    let instances: Vec<Instance> = transforms.iter().map(|t| Instance::new(*t, 0)).collect();
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = Tlas::build(&instances, &all, &blases).unwrap();
    // Instance 0 keeps half of each cut-out triangle, instance 1 none, instance 2 all of them.
    let accept = |inst: u32, u: f32, v: f32| match inst {
        0 => keep_half(u, v),
        1 => false,
        _ => true,
    };
    let records: Vec<InstanceRecord> = transforms
        .iter()
        .map(|t| InstanceRecord {
            world_to_object: world_to_object(t).unwrap(),
            ..Default::default()
        })
        .collect();
    let mut rng = SplitMix64::new(33);
    let mut hits = 0;
    for (i, ray) in rays(&mut rng).iter().enumerate() {
        let mut want: Option<hikari_bvh::Hit> = None;
        for (k, rec) in records.iter().enumerate() {
            let obj = to_object_space(rec, ray, ray.t_max);
            let h =
                closest_hit_mesh_filtered(&mesh, &marks, &obj, |_, u, v| accept(k as u32, u, v));
            if let Some(mut h) = h
                && want.is_none_or(|w| h.t < w.t)
            {
                h.instance = k as u32;
                want = Some(h);
            }
        }
        hits += want.is_some() as usize;
        let got = tlas.closest_hit_filtered(&blases, ray, |inst, p, u, v| {
            assert!(marks[p as usize]);
            accept(inst, u, v)
        });
        if let Err(e) = same_hit(got, want) {
            panic!("closest hit, ray {i} {ray:?}: {e}");
        }
        let got_any = tlas.any_hit_filtered(&blases, ray, |inst, _, u, v| accept(inst, u, v));
        let want_any = records.iter().enumerate().any(|(k, rec)| {
            let obj = to_object_space(rec, ray, ray.t_max);
            any_hit_mesh_filtered(&mesh, &marks, &obj, |_, u, v| accept(k as u32, u, v))
        });
        assert_eq!(got_any, want_any, "any hit, ray {i} {ray:?}");
    }
    assert!(hits > 1500, "{hits} rays hit");
}

#[test]
fn a_mark_per_triangle_is_required() {
    let (mesh, marks) = scene();
    let err = Blas::build_with_opacity(
        "short",
        &mesh.positions,
        &mesh.indices,
        &marks[1..],
        &BuildOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, BvhError::OpacityCount { ref mesh, flags, triangles }
            if mesh == "short" && flags == marks.len() - 1 && triangles == marks.len()),
        "{err:?}"
    );
}
