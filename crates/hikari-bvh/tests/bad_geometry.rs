//! Bad input is rejected with an error naming the mesh and triangle, or skipped and counted;
//! never a panic or a hang.

use glam::{Affine3A, Vec3};
use hikari_bvh::{BadTriangle, Blas, BuildOptions, BvhError, Instance, Mesh, Ray, Tlas};

fn quad() -> Mesh {
    Mesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

#[test]
fn nan_vertex_is_rejected_with_mesh_and_triangle() {
    let mut m = quad();
    m.positions.push(Vec3::new(0.0, f32::NAN, 0.0));
    m.indices.push([0, 1, 4]);
    let err = Blas::from_mesh("rock_03", &m, &BuildOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            BvhError::NonFiniteVertex {
                triangle: 2,
                vertex: 4,
                ..
            }
        ),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("rock_03") && msg.contains("triangle 2"),
        "{msg}"
    );
}

#[test]
fn infinite_vertex_can_be_skipped_and_counted() {
    let mut m = quad();
    m.positions.push(Vec3::new(f32::INFINITY, 0.0, 0.0));
    m.indices.push([0, 4, 1]);
    let opts = BuildOptions {
        invalid: BadTriangle::Skip,
        ..Default::default()
    };
    let b = Blas::from_mesh("m", &m, &opts).unwrap();
    assert_eq!(b.stats.skipped_non_finite, 1);
    assert_eq!(b.stats.triangles, 2);
    let hit = b.intersect(&Ray::new(
        Vec3::new(0.5, 0.5, 1.0),
        Vec3::NEG_Z,
        0.0,
        f32::INFINITY,
    ));
    assert!(hit.is_some());
}

#[test]
fn degenerate_triangles_are_skipped_by_default_or_rejected() {
    let mut m = quad();
    m.indices.push([1, 1, 2]); // repeated vertex
    m.positions.push(Vec3::new(2.0, 0.0, 0.0));
    m.indices.push([0, 1, 4]); // collinear
    let b = Blas::from_mesh("m", &m, &BuildOptions::default()).unwrap();
    assert_eq!(b.stats.skipped_degenerate, 2);
    assert_eq!(b.stats.triangles, 2);
    let opts = BuildOptions {
        degenerate: BadTriangle::Reject,
        ..Default::default()
    };
    let err = Blas::from_mesh("fence", &m, &opts).unwrap_err();
    assert_eq!(
        err,
        BvhError::DegenerateTriangle {
            mesh: "fence".into(),
            triangle: 2
        }
    );
}

#[test]
fn out_of_range_index_is_rejected() {
    let mut m = quad();
    m.indices.push([0, 1, 99]);
    let err = Blas::from_mesh("m", &m, &BuildOptions::default()).unwrap_err();
    assert!(matches!(
        err,
        BvhError::IndexOutOfRange {
            triangle: 2,
            index: 99,
            vertex_count: 4,
            ..
        }
    ));
}

#[test]
fn empty_and_all_bad_meshes_are_errors() {
    let err = Blas::from_mesh("void", &Mesh::default(), &BuildOptions::default()).unwrap_err();
    assert_eq!(
        err,
        BvhError::EmptyMesh {
            mesh: "void".into()
        }
    );
    let m = Mesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 2], [2, 1, 0]]);
    let err = Blas::from_mesh("dust", &m, &BuildOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            BvhError::NoValidTriangles {
                total: 2,
                degenerate: 2,
                ..
            }
        ),
        "{err:?}"
    );
}

#[test]
fn nan_and_zero_rays_terminate_without_hits() {
    let b = Blas::from_mesh("q", &quad(), &BuildOptions::default()).unwrap();
    let weird = [
        Ray::new(Vec3::splat(f32::NAN), Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(Vec3::ZERO, Vec3::splat(f32::NAN), 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::ZERO, 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z, f32::NAN, f32::NAN),
        Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z, 5.0, 1.0),
    ];
    for r in &weird {
        assert!(b.intersect(r).is_none(), "{r:?}");
        assert!(!b.occluded(r), "{r:?}");
    }
}

#[test]
fn bad_instances_are_reported_or_skipped() {
    let blases = vec![Blas::from_mesh("q", &quad(), &BuildOptions::default()).unwrap()];
    let ok = Instance::new(Affine3A::IDENTITY, 0);
    let singular = Instance::new(Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0)), 0);
    let nan = Instance::new(Affine3A::from_translation(Vec3::splat(f32::NAN)), 0);
    let tlas = Tlas::build(&[ok, singular, nan], &[0, 1, 2], &blases).unwrap();
    assert_eq!(tlas.stats.instances, 1);
    assert_eq!(tlas.stats.skipped_invalid, 2);
    let missing = Instance::new(Affine3A::IDENTITY, 7);
    let err = Tlas::build(&[ok, missing], &[0, 1], &blases).unwrap_err();
    assert_eq!(
        err,
        BvhError::BadBlasIndex {
            instance: 1,
            blas: 7,
            blas_count: 1
        }
    );
}

#[test]
fn extreme_coordinates_build_and_trace() {
    use hikari_bvh::reference::closest_hit_mesh;
    // Tiny and huge meshes, each with a far copy stretching the root box: quantization steps
    // far from 1 in both directions.
    for scale in [1e-15f32, 1e-6, 1e6, 1e15] {
        let mut m = quad();
        for p in &mut m.positions {
            *p *= scale;
        }
        // A second, far away copy stretches the root box.
        let far = Vec3::splat(scale * 1000.0);
        let base = m.positions.len() as u32;
        let copy: Vec<Vec3> = m.positions.iter().map(|p| *p + far).collect();
        m.positions.extend(copy);
        m.indices
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        let b = Blas::from_mesh("extreme", &m, &BuildOptions::default()).unwrap();
        for target in [
            Vec3::new(0.5, 0.5, 0.0) * scale,
            Vec3::new(0.5, 0.5, 0.0) * scale + far,
        ] {
            let ray = Ray::new(
                target + Vec3::Z * scale,
                Vec3::NEG_Z * scale,
                0.0,
                f32::INFINITY,
            );
            let got = b.intersect(&ray);
            let want = closest_hit_mesh(&m, &ray);
            assert_eq!(
                got.map(|h| h.primitive),
                want.map(|h| h.primitive),
                "scale {scale}"
            );
            assert!(got.is_some(), "scale {scale}");
        }
    }
}
