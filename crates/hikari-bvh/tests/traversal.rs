//! BLAS traversal over the GPU layout against brute force over every triangle.

use hikari_bvh::reference as common;

use glam::Vec3;
use hikari_bvh::reference::{any_hit_mesh, closest_hit_mesh};
use hikari_bvh::reference::{random_rays, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Mesh, Ray};

fn check_mesh(name: &str, mesh: &Mesh, rays: &[Ray], options: &BuildOptions) -> usize {
    let blas = Blas::from_mesh(name, mesh, options).expect("builds");
    let mut hits = 0;
    for (i, ray) in rays.iter().enumerate() {
        let want = closest_hit_mesh(mesh, ray);
        let got = blas.intersect(ray);
        if let Err(e) = same_hit(got, want) {
            panic!("{name}: ray {i} {ray:?}: {e}");
        }
        hits += want.is_some() as usize;
        assert_eq!(
            blas.occluded(ray),
            any_hit_mesh(mesh, ray),
            "{name}: any-hit disagrees on ray {i} {ray:?}"
        );
    }
    hits
}

#[test]
fn random_soups_match_brute_force() {
    for (seed, count) in [(1u64, 1usize), (2, 2), (3, 7), (4, 40), (5, 300), (6, 1500)] {
        let mesh = Mesh::random_soup(seed, count, 10.0, 3.0);
        let mut rng = SplitMix64::new(seed * 77);
        let rays = random_rays(&mut rng, 600, 12.0);
        let hits = check_mesh(
            &format!("soup{seed}"),
            &mesh,
            &rays,
            &BuildOptions::default(),
        );
        if count >= 300 {
            assert!(hits > 50, "test rays should hit something ({hits})");
        }
    }
}

#[test]
fn thin_and_mixed_scale_soup_matches_brute_force() {
    // Long slivers plus tiny triangles: wide boxes next to small ones stress quantization.
    let mut mesh = Mesh::random_soup(11, 400, 10.0, 0.05);
    let slivers = Mesh::random_soup(12, 200, 10.0, 20.0);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(&slivers.positions);
    mesh.indices
        .extend(slivers.indices.iter().map(|t| t.map(|i| i + base)));
    let mut rng = SplitMix64::new(13);
    let rays = random_rays(&mut rng, 800, 12.0);
    check_mesh("mixed", &mesh, &rays, &BuildOptions::default());
}

#[test]
fn single_thread_and_multi_thread_builds_are_identical() {
    let mesh = Mesh::random_soup(21, 40_000, 50.0, 1.0);
    let one = Blas::from_mesh(
        "a",
        &mesh,
        &BuildOptions {
            threads: 1,
            ..Default::default()
        },
    )
    .unwrap();
    let four = Blas::from_mesh(
        "a",
        &mesh,
        &BuildOptions {
            threads: 4,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(one.nodes, four.nodes);
    assert_eq!(one.triangles, four.triangles);
}

#[test]
fn terrain_matches_brute_force() {
    let mesh = Mesh::terrain(33);
    let mut rng = SplitMix64::new(5);
    let mut rays = Vec::new();
    for i in 0..1500 {
        let x = rng.range(-90.0, 90.0);
        let z = rng.range(-90.0, 90.0);
        let y = hikari_bvh::mesh::terrain_height(x, z);
        let ray = match i % 3 {
            // Down onto the surface from above.
            0 => Ray::new(
                Vec3::new(x, 30.0, z),
                common::random_dir(&mut rng) - Vec3::Y * 1.5,
                0.0,
                f32::INFINITY,
            ),
            // Grazing rays just above the surface.
            1 => {
                let d = common::random_dir(&mut rng);
                Ray::new(
                    Vec3::new(x, y + 0.5, z),
                    Vec3::new(d.x, 0.02 * d.y, d.z),
                    0.0,
                    f32::INFINITY,
                )
            }
            // AO-style: from 1 cm above, upward hemisphere, short.
            _ => {
                let mut d = common::random_dir(&mut rng);
                d.y = d.y.abs();
                Ray::new(Vec3::new(x, y + 0.01, z), d, 0.0, 5.0)
            }
        };
        rays.push(ray);
    }
    let hits = check_mesh("terrain", &mesh, &rays, &BuildOptions::default());
    assert!(hits > 500);
}

#[test]
fn identical_triangles_terminate_and_match() {
    // Every centroid equal: SAH finds no plane and the median fallback must still terminate.
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let positions: Vec<Vec3> = (0..300).flat_map(|_| tri).collect();
    let indices: Vec<[u32; 3]> = (0..300u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    let mesh = Mesh::new(positions, indices);
    let rays = [
        Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.8, 0.8, -1.0), Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, 0.5),
    ];
    let blas = Blas::from_mesh("stack", &mesh, &BuildOptions::default()).unwrap();
    assert!(blas.stats.depth < 64);
    for r in &rays {
        let got = blas.intersect(r);
        let want = closest_hit_mesh(&mesh, r);
        assert_eq!(got.is_some(), want.is_some());
        if let (Some(g), Some(w)) = (got, want) {
            assert_eq!(g.t, w.t);
        }
    }
}

#[test]
fn layout_invariants_hold() {
    let mesh = Mesh::random_soup(31, 3000, 20.0, 2.0);
    let blas = Blas::from_mesh("inv", &mesh, &BuildOptions::default()).unwrap();
    // Exact bounds of every subtree, children first.
    let mut exact = vec![hikari_bvh::Aabb::EMPTY; blas.nodes.len()];
    for n in (0..blas.nodes.len()).rev() {
        for s in 0..8 {
            match blas.nodes[n].slot_kind(s) {
                hikari_bvh::layout::SlotKind::Internal(c) => {
                    let b = exact[c as usize];
                    exact[n].grow(&b);
                }
                hikari_bvh::layout::SlotKind::Leaf { first, count } => {
                    for t in &blas.triangles[first as usize..(first + count) as usize] {
                        for v in [t.v0, t.v1, t.v2] {
                            exact[n].grow_point(v.into());
                        }
                    }
                }
                hikari_bvh::layout::SlotKind::Empty => {}
            }
        }
    }
    let mut seen = vec![false; blas.triangles.len()];
    let mut reached = vec![false; blas.nodes.len()];
    reached[0] = true;
    for (n, node) in blas.nodes.iter().enumerate() {
        let mut leaf_total = 0;
        for s in 0..8 {
            match node.slot_kind(s) {
                hikari_bvh::layout::SlotKind::Empty => {}
                hikari_bvh::layout::SlotKind::Internal(c) => {
                    assert!(c as usize > n, "children follow parents");
                    reached[c as usize] = true;
                    // The decoded box contains every triangle below it.
                    assert!(node.child_box(s).contains(&exact[c as usize]));
                }
                hikari_bvh::layout::SlotKind::Leaf { first, count } => {
                    assert!((1..=3).contains(&count));
                    leaf_total += count;
                    let b = node.child_box(s);
                    for t in &blas.triangles[first as usize..(first + count) as usize] {
                        for v in [t.v0, t.v1, t.v2] {
                            let v = glam::Vec3A::from(v);
                            assert!(b.min.cmple(v).all() && b.max.cmpge(v).all());
                        }
                    }
                    for i in first..first + count {
                        assert!(!seen[i as usize], "triangle referenced twice");
                        seen[i as usize] = true;
                    }
                }
            }
        }
        assert!(leaf_total <= 24);
    }
    assert!(seen.iter().all(|&s| s), "every triangle is in a leaf");
    assert!(reached.iter().all(|&r| r), "every node is reachable");
}
