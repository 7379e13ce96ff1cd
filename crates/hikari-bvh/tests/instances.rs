//! Two-level traversal (TLAS over instances sharing BLAS) against brute force over every
//! triangle of every instance.

use hikari_bvh::reference as common;

use glam::{Affine3A, Quat, Vec3};
use hikari_bvh::reference::assert_tlas_matches_brute_force;
use hikari_bvh::reference::random_rays;
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Instance, Mesh, Ray, Tlas};

fn scene(seed: u64, count: usize) -> (Vec<Mesh>, Vec<Blas>, Vec<Instance>) {
    let meshes = vec![
        Mesh::random_soup(seed, 150, 3.0, 1.5),
        Mesh::terrain(9),
        Mesh::random_soup(seed + 1, 20, 1.0, 2.0),
    ];
    let blases: Vec<Blas> = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| Blas::from_mesh(&format!("mesh{i}"), m, &BuildOptions::default()).unwrap())
        .collect();
    let mut rng = SplitMix64::new(seed);
    let instances = (0..count)
        .map(|i| {
            let axis = common::random_dir(&mut rng);
            let rot = Quat::from_axis_angle(axis, rng.range(0.0, std::f32::consts::TAU));
            let mut scale = Vec3::new(
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
            );
            if i % 5 == 0 {
                scale.x = -scale.x; // mirrored
            }
            let blas = (i % 3) as u32;
            if blas == 1 {
                scale *= 0.1; // the 200 m terrain, shrunk to 20 m
            }
            let t = Vec3::new(
                rng.range(-30.0, 30.0),
                rng.range(-30.0, 30.0),
                rng.range(-30.0, 30.0),
            );
            Instance::new(
                Affine3A::from_scale_rotation_translation(scale, rot, t),
                blas,
            )
        })
        .collect();
    (meshes, blases, instances)
}

fn check(
    meshes: &[Mesh],
    blases: &[Blas],
    instances: &[Instance],
    selected: &[u32],
    rays: &[Ray],
) -> usize {
    let tlas = Tlas::build(instances, selected, blases).unwrap();
    assert_tlas_matches_brute_force(&tlas, meshes, blases, instances, selected, rays)
}

#[test]
fn instanced_scene_matches_brute_force() {
    let (meshes, blases, instances) = scene(3, 40);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let mut rng = SplitMix64::new(9);
    let rays = random_rays(&mut rng, 500, 35.0);
    let hits = check(&meshes, &blases, &instances, &all, &rays);
    assert!(hits > 50, "{hits} hits");
}

#[test]
fn subset_of_instances_matches_brute_force_on_the_subset() {
    let (meshes, blases, instances) = scene(4, 30);
    let subset: Vec<u32> = (0..instances.len() as u32).filter(|i| i % 3 != 1).collect();
    let mut rng = SplitMix64::new(10);
    let rays = random_rays(&mut rng, 300, 35.0);
    check(&meshes, &blases, &instances, &subset, &rays);
}

#[test]
fn hits_report_the_instance_index_and_object_space_primitive() {
    let mesh = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
    let blas = vec![Blas::from_mesh("tri", &mesh, &BuildOptions::default()).unwrap()];
    let instances: Vec<Instance> = (0..5)
        .map(|i| {
            Instance::new(
                Affine3A::from_translation(Vec3::new(0.0, 0.0, i as f32 * 2.0)),
                0,
            )
        })
        .collect();
    let tlas = Tlas::build(&instances, &[4, 2, 3], &blas).unwrap();
    let ray = Ray::new(Vec3::new(0.25, 0.25, -10.0), Vec3::Z, 0.0, f32::INFINITY);
    let hit = tlas.closest_hit(&blas, &ray).unwrap();
    assert_eq!(hit.instance, 2);
    assert_eq!(hit.primitive, 0);
    assert!((hit.t - 14.0).abs() < 1e-5);
    assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.25).abs() < 1e-6);
    // Scaled direction: t stays in units of the world-space direction.
    let ray2 = Ray::new(
        Vec3::new(0.25, 0.25, -10.0),
        Vec3::Z * 2.0,
        0.0,
        f32::INFINITY,
    );
    assert!((tlas.closest_hit(&blas, &ray2).unwrap().t - 7.0).abs() < 1e-5);
}

#[test]
fn empty_scene_misses() {
    let blases: Vec<Blas> = Vec::new();
    let tlas = Tlas::build(&[], &[], &blases).unwrap();
    let ray = Ray::new(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY);
    assert!(tlas.closest_hit(&blases, &ray).is_none());
    assert!(!tlas.any_hit(&blases, &ray));
    assert_eq!(tlas.stats.instances, 0);
}

#[test]
fn packed_offsets_match_blas_sizes() {
    let (_, blases, instances) = scene(5, 9);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = Tlas::build(&instances, &all, &blases).unwrap();
    let packed = hikari_bvh::PackedBlases::new(&blases);
    for rec in &tlas.instances {
        let b = &blases[rec.blas_index as usize];
        let n = rec.blas_node_offset as usize;
        let t = rec.blas_triangle_offset as usize;
        assert_eq!(&packed.nodes[n..n + b.nodes.len()], b.nodes.as_slice());
        assert_eq!(
            &packed.triangles[t..t + b.triangles.len()],
            b.triangles.as_slice()
        );
    }
}

#[test]
fn batch_tracing_matches_single_rays() {
    let (_, blases, instances) = scene(6, 12);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = Tlas::build(&instances, &all, &blases).unwrap();
    let mut rng = SplitMix64::new(11);
    let rays = random_rays(&mut rng, 200, 35.0);
    let hits = tlas.closest_hits(&blases, &rays, 3);
    let occluded = tlas.any_hits(&blases, &rays, 2);
    for (i, ray) in rays.iter().enumerate() {
        assert_eq!(
            tlas.closest_hit(&blases, ray)
                .unwrap_or(hikari_bvh::Hit::NONE),
            hits[i]
        );
        assert_eq!(tlas.any_hit(&blases, ray), occluded[i]);
    }
}
