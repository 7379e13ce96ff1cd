//! The parallel build paths (level-parallel top, subtree tasks, parallel collapse and
//! validation) give the same BLAS for every thread count, and that BLAS traces like brute force.

use glam::Vec3;
use hikari_bvh::reference::{closest_hit_mesh, random_dir, random_rays, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{BadTriangle, Blas, BuildOptions, BvhError, Mesh, Ray};

fn build(mesh: &Mesh, threads: usize) -> Blas {
    Blas::from_mesh(
        "m",
        mesh,
        &BuildOptions {
            threads,
            ..Default::default()
        },
    )
    .expect("builds")
}

fn assert_same_for_thread_counts(mesh: &Mesh, counts: &[usize]) -> Blas {
    let one = build(mesh, 1);
    for &t in counts {
        let other = build(mesh, t);
        assert_eq!(one.nodes, other.nodes, "nodes differ with {t} threads");
        assert_eq!(
            one.triangles, other.triangles,
            "triangles differ with {t} threads"
        );
        assert_eq!(one.stats.depth, other.stats.depth);
    }
    one
}

/// Clustered soup: dense clumps next to sparse regions give uneven SAH splits, so the top levels
/// end with nodes of very different sizes and shares that straddle node boundaries.
fn clustered_soup(seed: u64, count: usize) -> Mesh {
    let mut rng = SplitMix64::new(seed);
    let centres: Vec<Vec3> = (0..6)
        .map(|_| {
            Vec3::new(
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
            )
        })
        .collect();
    let mut positions = Vec::with_capacity(3 * count);
    let mut indices = Vec::with_capacity(count);
    for t in 0..count {
        let (c, spread) = if t % 7 == 0 {
            (Vec3::ZERO, 60.0)
        } else {
            (centres[t % centres.len()], 1.0 + (t % 3) as f32)
        };
        let p = c + Vec3::new(
            rng.range(-spread, spread),
            rng.range(-spread, spread),
            rng.range(-spread, spread),
        );
        for _ in 0..3 {
            positions.push(p + random_dir(&mut rng) * 0.3);
        }
        indices.push([3 * t as u32, 3 * t as u32 + 1, 3 * t as u32 + 2]);
    }
    Mesh::new(positions, indices)
}

#[test]
fn terrain_is_identical_for_any_thread_count() {
    // 2 x 159^2 = 50,562 triangles: large enough for the level-parallel top.
    let mesh = Mesh::terrain(160);
    let blas = assert_same_for_thread_counts(&mesh, &[2, 3, 5, 16]);
    assert_eq!(blas.stats.triangles, mesh.indices.len());
}

#[test]
fn clustered_soup_is_identical_for_any_thread_count_and_matches_brute_force() {
    let mesh = clustered_soup(3, 70_000);
    let blas = assert_same_for_thread_counts(&mesh, &[2, 4, 7]);
    let parallel = build(&mesh, 4);
    let mut rng = SplitMix64::new(9);
    // Half of the rays aim at a random triangle's corner region, so many hit something.
    let mut rays = random_rays(&mut rng, 75, 60.0);
    for _ in 0..75 {
        let t = mesh.indices[rng.below(mesh.indices.len())];
        let target = (mesh.positions[t[0] as usize] + mesh.positions[t[1] as usize]) * 0.5;
        let origin = random_dir(&mut rng) * 70.0;
        rays.push(Ray::new(origin, target - origin, 0.0, f32::INFINITY));
    }
    let mut hits = 0;
    for (i, ray) in rays.iter().enumerate() {
        let want = closest_hit_mesh(&mesh, ray);
        hits += want.is_some() as usize;
        if let Err(e) = same_hit(parallel.intersect(ray), want) {
            panic!("ray {i} {ray:?}: {e}");
        }
    }
    assert!(hits > 20, "test rays should hit something ({hits})");
    assert_eq!(blas.nodes, parallel.nodes);
}

#[test]
fn equal_centroids_take_the_median_path_in_parallel() {
    // 40,000 copies of one triangle: no SAH plane exists at any level, so the top levels split
    // every node at the median.
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let n = 40_000u32;
    let positions: Vec<Vec3> = (0..n).flat_map(|_| tri).collect();
    let indices: Vec<[u32; 3]> = (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    let mesh = Mesh::new(positions, indices);
    let blas = assert_same_for_thread_counts(&mesh, &[4]);
    assert!(blas.stats.depth < 64);
    let ray = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, 0.0, f32::INFINITY);
    let hit = blas.intersect(&ray).expect("the stack is hit");
    let want = closest_hit_mesh(&mesh, &ray).expect("brute force hits");
    assert_eq!(hit.t, want.t);
}

#[test]
fn parallel_terrain_matches_brute_force() {
    let mesh = Mesh::terrain(160);
    let blas = build(&mesh, 4);
    let mut rng = SplitMix64::new(17);
    for i in 0..200 {
        let x = rng.range(-95.0, 95.0);
        let z = rng.range(-95.0, 95.0);
        let y = hikari_bvh::mesh::terrain_height(x, z);
        let mut d = random_dir(&mut rng);
        d.y = d.y.abs();
        let ray = if i % 2 == 0 {
            Ray::new(
                Vec3::new(x, 30.0, z),
                Vec3::new(d.x, -1.5, d.z),
                0.0,
                f32::INFINITY,
            )
        } else {
            Ray::new(Vec3::new(x, y + 0.01, z), d, 0.0, 5.0)
        };
        let want = closest_hit_mesh(&mesh, &ray);
        if let Err(e) = same_hit(blas.intersect(&ray), want) {
            panic!("ray {i} {ray:?}: {e}");
        }
        assert_eq!(
            blas.occluded(&ray),
            want.is_some(),
            "any-hit disagrees on ray {i}"
        );
    }
}

/// Mesh with bad triangles spread over several validation pieces.
fn mesh_with_bad_triangles() -> (Mesh, Vec<usize>) {
    let mut mesh = Mesh::terrain(120);
    let n = mesh.indices.len();
    let bad = vec![n / 5, n / 2, n - 3];
    let v = mesh.positions.len() as u32;
    mesh.positions.push(Vec3::new(f32::NAN, 0.0, 0.0));
    for &t in &bad {
        mesh.indices[t][1] = v;
    }
    (mesh, bad)
}

#[test]
fn parallel_validation_reports_the_first_bad_triangle() {
    let (mesh, bad) = mesh_with_bad_triangles();
    for threads in [1, 3, 8] {
        let err = Blas::from_mesh(
            "bad",
            &mesh,
            &BuildOptions {
                threads,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(err, BvhError::NonFiniteVertex { triangle, .. } if triangle == bad[0]),
            "{threads} threads: {err:?}"
        );
    }
}

#[test]
fn parallel_validation_skips_and_keeps_triangle_order() {
    let (mesh, bad) = mesh_with_bad_triangles();
    let opts = |threads| BuildOptions {
        threads,
        invalid: BadTriangle::Skip,
        ..Default::default()
    };
    let one = Blas::from_mesh("bad", &mesh, &opts(1)).unwrap();
    let many = Blas::from_mesh("bad", &mesh, &opts(6)).unwrap();
    assert_eq!(one.stats.skipped_non_finite, bad.len());
    assert_eq!(many.stats.skipped_non_finite, bad.len());
    assert_eq!(many.stats.triangles, mesh.indices.len() - bad.len());
    assert_eq!(one.nodes, many.nodes);
    assert_eq!(one.triangles, many.triangles);
    // Every kept triangle appears once; the skipped ones never.
    let mut seen = vec![false; mesh.indices.len()];
    for t in &many.triangles {
        assert!(
            !seen[t.primitive as usize],
            "triangle {} twice",
            t.primitive
        );
        seen[t.primitive as usize] = true;
    }
    for (t, s) in seen.iter().enumerate() {
        assert_eq!(*s, !bad.contains(&t), "triangle {t}");
    }
}

#[test]
fn the_current_rayon_pool_gives_the_same_blas_whatever_its_size() {
    // `threads: 0` builds on the pool the caller is in (the global one, or one installed).
    let mesh = Mesh::terrain(160);
    let one = build(&mesh, 1);
    for n in [2, 3, 6] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool starts");
        let blas = pool.install(|| build(&mesh, 0));
        assert_eq!(one.nodes, blas.nodes, "nodes differ on a pool of {n}");
        assert_eq!(
            one.triangles, blas.triangles,
            "triangles differ on a pool of {n}"
        );
    }
}
