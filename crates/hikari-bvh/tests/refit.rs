//! Refit keeps the hits of a full rebuild on the deformed mesh.

use glam::Vec3;
use hikari_bvh::reference::closest_hit_mesh;
use hikari_bvh::reference::{random_rays, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, BvhError, Mesh};

fn deform(mesh: &Mesh, phase: f32, amp: f32) -> Mesh {
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            *p + Vec3::new(
                (p.y * 0.7 + phase).sin(),
                (p.z * 0.5 + 2.0 * phase).cos(),
                (p.x * 0.3 - phase).sin(),
            ) * amp
        })
        .collect();
    Mesh::new(positions, mesh.indices.clone())
}

fn compare_refit_and_rebuild(mesh: &Mesh, deformed: &Mesh, seed: u64, extent: f32) {
    let mut refit = Blas::from_mesh("m", mesh, &BuildOptions::default()).unwrap();
    refit.refit(&deformed.positions).unwrap();
    let rebuilt = Blas::from_mesh("m", deformed, &BuildOptions::default()).unwrap();
    let mut rng = SplitMix64::new(seed);
    let rays = random_rays(&mut rng, 600, extent);
    for (i, ray) in rays.iter().enumerate() {
        let a = refit.intersect(ray);
        let b = rebuilt.intersect(ray);
        if let Err(e) = same_hit(a, b) {
            panic!("ray {i}: refit vs rebuild: {e}");
        }
        if let Err(e) = same_hit(a, closest_hit_mesh(deformed, ray)) {
            panic!("ray {i}: refit vs brute force: {e}");
        }
        assert_eq!(refit.occluded(ray), rebuilt.occluded(ray), "ray {i}");
    }
}

#[test]
fn refit_soup_matches_rebuild() {
    let mesh = Mesh::random_soup(41, 800, 8.0, 2.0);
    compare_refit_and_rebuild(&mesh, &deform(&mesh, 0.3, 2.5), 42, 11.0);
}

#[test]
fn refit_terrain_matches_rebuild() {
    let mut mesh = Mesh::terrain(25);
    for p in &mut mesh.positions {
        *p *= 0.1;
    }
    compare_refit_and_rebuild(&mesh, &deform(&mesh, 1.1, 1.0), 43, 12.0);
}

#[test]
fn refit_back_to_the_build_pose_restores_the_hits() {
    let mesh = Mesh::random_soup(44, 300, 5.0, 1.5);
    let original = Blas::from_mesh("m", &mesh, &BuildOptions::default()).unwrap();
    let mut b = original.clone();
    b.refit(&deform(&mesh, 0.5, 3.0).positions).unwrap();
    b.refit(&mesh.positions).unwrap();
    assert_eq!(b.triangles, original.triangles);
    let mut rng = SplitMix64::new(45);
    for ray in random_rays(&mut rng, 300, 7.0) {
        same_hit(b.intersect(&ray), original.intersect(&ray)).unwrap();
    }
}

#[test]
fn refit_rejects_bad_input_and_leaves_the_blas_intact() {
    let mesh = Mesh::random_soup(46, 50, 5.0, 1.5);
    let mut b = Blas::from_mesh("cloth", &mesh, &BuildOptions::default()).unwrap();
    let before = b.clone();
    let err = b.refit(&mesh.positions[..10]).unwrap_err();
    assert!(matches!(
        err,
        BvhError::RefitVertexCount {
            expected: 150,
            got: 10,
            ..
        }
    ));
    let mut bad = mesh.positions.clone();
    bad[7] = Vec3::new(f32::NAN, 0.0, 0.0);
    let err = b.refit(&bad).unwrap_err();
    assert!(
        matches!(
            err,
            BvhError::NonFiniteVertex {
                vertex: 7,
                triangle: 2,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cloth"));
    assert_eq!(b.nodes, before.nodes);
    assert_eq!(b.triangles, before.triangles);
}
