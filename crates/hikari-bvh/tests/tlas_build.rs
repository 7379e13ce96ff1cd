//! The TLAS builder on awkward instance sets: closest and any hit equal to brute force over
//! every triangle of every instance, the tree well formed (every instance once, children after
//! parents, the stats what the tree holds), the same tree for the same input, and bounded depth
//! where SAH alone would build a chain.

use glam::{Affine3A, Quat, Vec3};
use hikari_bvh::layout::SlotKind;
use hikari_bvh::reference::assert_tlas_matches_brute_force;
use hikari_bvh::reference::{random_dir, random_rays};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::tlas::TlasBuilder;
use hikari_bvh::{Blas, BuildOptions, Instance, Mesh, Ray, Tlas};

fn meshes() -> (Vec<Mesh>, Vec<Blas>) {
    let meshes = vec![
        Mesh::random_soup(1, 10, 1.0, 0.6),
        Mesh::terrain(3),
        Mesh::random_soup(2, 4, 0.5, 1.0),
    ];
    let blases = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| Blas::from_mesh(&format!("m{i}"), m, &BuildOptions::default()).unwrap())
        .collect();
    (meshes, blases)
}

fn placed(rng: &mut SplitMix64, blas: u32, centre: Vec3, scale: f32) -> Instance {
    let rot = Quat::from_axis_angle(random_dir(rng), rng.range(0.0, std::f32::consts::TAU));
    let mut s = Vec3::new(
        rng.range(0.5, 2.0),
        rng.range(0.5, 2.0),
        rng.range(0.5, 2.0),
    ) * scale;
    if rng.below(4) == 0 {
        s.z = -s.z; // mirrored
    }
    Instance::new(
        Affine3A::from_scale_rotation_translation(s, rot, centre),
        blas,
    )
}

/// Rays through the scene's box: random ones, and ones aimed at random instances.
fn rays(rng: &mut SplitMix64, instances: &[Instance], extent: f32) -> Vec<Ray> {
    let mut rays = random_rays(rng, 60, extent);
    for _ in 0..140 {
        let target = Vec3::from(instances[rng.below(instances.len())].transform.translation);
        let origin = random_dir(rng) * extent * 1.5;
        let jitter = random_dir(rng) * rng.range(0.0, 0.3);
        rays.push(Ray::new(
            origin,
            target + jitter - origin,
            0.0,
            f32::INFINITY,
        ));
    }
    rays
}

/// Checks the tree's shape and returns its depth: every child index after its parent, every
/// instance record referenced by exactly one leaf slot, and a leaf's instances within the
/// records.
fn check_shape(tlas: &Tlas) -> u32 {
    let mut referenced = vec![0u32; tlas.instances.len()];
    let mut depth = 0;
    let mut stack = vec![(0u32, 1u32)];
    while let Some((n, d)) = stack.pop() {
        depth = depth.max(d);
        let node = &tlas.nodes[n as usize];
        for slot in 0..8 {
            match node.slot_kind(slot) {
                SlotKind::Internal(c) => {
                    assert!(c > n && (c as usize) < tlas.nodes.len(), "node {n} -> {c}");
                    stack.push((c, d + 1));
                }
                SlotKind::Leaf { first, count } => {
                    assert_eq!(count, 1, "one instance per leaf slot");
                    referenced[first as usize] += 1;
                }
                SlotKind::Empty => {}
            }
        }
    }
    assert!(referenced.iter().all(|&r| r == 1), "{referenced:?}");
    assert_eq!(tlas.stats.nodes, tlas.nodes.len());
    assert_eq!(tlas.stats.instances, tlas.instances.len());
    assert_eq!(tlas.stats.depth, depth);
    depth
}

/// Builds over all of `instances`, checks shape and hits, returns the TLAS.
fn build_and_check(name: &str, instances: &[Instance], extent: f32, min_hits: usize) -> Tlas {
    let (meshes, blases) = meshes();
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = Tlas::build(instances, &all, &blases).unwrap();
    check_shape(&tlas);
    let mut rng = SplitMix64::new(99);
    let rays = rays(&mut rng, instances, extent);
    let hits = assert_tlas_matches_brute_force(&tlas, &meshes, &blases, instances, &all, &rays);
    assert!(hits >= min_hits, "{name}: only {hits} hits");
    tlas
}

#[test]
fn many_scattered_instances_match_brute_force() {
    let mut rng = SplitMix64::new(1);
    let instances: Vec<Instance> = (0..2000)
        .map(|i| {
            let c = Vec3::new(
                rng.range(-40.0, 40.0),
                rng.range(-4.0, 4.0),
                rng.range(-40.0, 40.0),
            );
            placed(
                &mut rng,
                (i % 3) as u32,
                c,
                if i % 3 == 1 { 0.03 } else { 1.0 },
            )
        })
        .collect();
    let tlas = build_and_check("scattered", &instances, 45.0, 100);
    assert!(tlas.stats.depth >= 3);
}

#[test]
fn instances_with_equal_centres_match_brute_force_and_stay_shallow() {
    // 600 instances in 3 spots, rotated and scaled differently: equal centroids, so equal
    // Morton codes, and many equal boxes among them.
    let mut rng = SplitMix64::new(2);
    let spots = [
        Vec3::ZERO,
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 7.0),
    ];
    let instances: Vec<Instance> = (0..600)
        .map(|i| {
            if i % 2 == 0 {
                Instance::new(Affine3A::from_translation(spots[i % 3]), 0)
            } else {
                placed(&mut rng, 2, spots[i % 3], 1.0)
            }
        })
        .collect();
    let tlas = build_and_check("equal centres", &instances, 10.0, 50);
    // Even splits keep it about log8(600) deep; peeling one at a time would not.
    assert!(tlas.stats.depth <= 6, "depth {}", tlas.stats.depth);
}

#[test]
fn huge_and_tiny_instances_match_brute_force() {
    // A ground a kilometre wide under hundreds of centimetre-sized props, and props inside
    // props: boxes that contain many others.
    let mut rng = SplitMix64::new(3);
    let mut instances = vec![Instance::new(
        Affine3A::from_scale_rotation_translation(
            Vec3::new(5.0, 0.2, 5.0),
            Quat::IDENTITY,
            Vec3::new(0.0, -2.0, 0.0),
        ),
        1,
    )];
    for i in 0..400 {
        let c = Vec3::new(
            rng.range(-30.0, 30.0),
            rng.range(-1.0, 1.0),
            rng.range(-30.0, 30.0),
        );
        let scale = [0.01, 0.1, 1.0, 20.0][i % 4];
        instances.push(placed(&mut rng, (i % 3) as u32 & !1, c, scale));
    }
    build_and_check("huge and tiny", &instances, 40.0, 50);
}

#[test]
fn one_and_two_instances_match_brute_force() {
    let mut rng = SplitMix64::new(4);
    let one = vec![placed(&mut rng, 0, Vec3::ZERO, 1.0)];
    let tlas = build_and_check("one", &one, 3.0, 10);
    assert_eq!((tlas.stats.nodes, tlas.stats.depth), (1, 1));
    let two = vec![
        placed(&mut rng, 0, Vec3::ZERO, 1.0),
        placed(&mut rng, 2, Vec3::new(0.5, 0.0, 0.0), 1.0),
    ];
    let tlas = build_and_check("two", &two, 3.0, 10);
    assert_eq!((tlas.stats.nodes, tlas.stats.depth), (1, 1));
}

#[test]
fn nested_boxes_of_geometric_sizes_stay_within_the_depth_bound() {
    // Concentric instances, each larger than the previous by a tenth: SAH may take the largest
    // one out at every split, a chain as deep as the instances are many, until the builder
    // switches to middle splits. (Sizes stay below 1e5: with coordinates near 1e9 the
    // traversal's clamped reciprocal of a zero direction component, 1e30, overflows.)
    let instances: Vec<Instance> = (0..120)
        .map(|i| Instance::new(Affine3A::from_scale(Vec3::splat(1.1f32.powi(i))), 0))
        .collect();
    let tlas = build_and_check("nested", &instances, 3.0, 20);
    // 40 chain levels become at most 40 wide levels, plus the balanced rest.
    assert!(tlas.stats.depth <= 44, "depth {}", tlas.stats.depth);
}

#[test]
fn invalid_and_missing_instances_are_skipped_and_counted() {
    let (meshes, blases) = meshes();
    let mut rng = SplitMix64::new(5);
    let mut instances: Vec<Instance> = (0..300)
        .map(|i| {
            let c = Vec3::new(
                rng.range(-20.0, 20.0),
                rng.range(-2.0, 2.0),
                rng.range(-20.0, 20.0),
            );
            placed(&mut rng, (i % 3) as u32, c, 1.0)
        })
        .collect();
    let singular = Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0));
    let nan = Affine3A::from_translation(Vec3::new(f32::NAN, 0.0, 0.0));
    let infinite = Affine3A::from_scale(Vec3::splat(f32::INFINITY));
    for (k, t) in [singular, nan, infinite].into_iter().enumerate() {
        for i in (k..300).step_by(17) {
            instances[i].transform = t;
        }
    }
    let bad = instances
        .iter()
        .filter(|i| i.transform.matrix3.determinant() == 0.0 || !i.transform.is_finite())
        .count();
    // Indices past the end of the list are skipped too.
    let mut selected: Vec<u32> = (0..300).collect();
    selected.extend([300, 1000]);
    let tlas = Tlas::build(&instances, &selected, &blases).unwrap();
    assert_eq!(tlas.stats.skipped_invalid, bad + 2);
    assert_eq!(tlas.stats.instances, 300 - bad);
    check_shape(&tlas);
    let valid: Vec<u32> = (0..300).collect();
    let rays = rays(&mut rng, &instances, 25.0);
    assert!(
        assert_tlas_matches_brute_force(&tlas, &meshes, &blases, &instances, &valid, &rays) > 50
    );
}

#[test]
fn the_same_input_gives_the_same_tree() {
    let (_, blases) = meshes();
    let mut rng = SplitMix64::new(6);
    let instances: Vec<Instance> = (0..1500)
        .map(|i| {
            // A grid (many ties) and scattered instances.
            let c = if i % 2 == 0 {
                Vec3::new((i % 40) as f32, 0.0, (i / 40) as f32)
            } else {
                Vec3::new(
                    rng.range(0.0, 40.0),
                    rng.range(-1.0, 1.0),
                    rng.range(0.0, 40.0),
                )
            };
            placed(&mut rng, (i % 3) as u32, c, 0.4)
        })
        .collect();
    let selected: Vec<u32> = (0..1500).rev().filter(|i| i % 5 != 2).collect();
    let a = TlasBuilder::default()
        .build(&instances, &selected, &blases)
        .unwrap();
    let b = TlasBuilder::default()
        .build(&instances, &selected, &blases)
        .unwrap();
    let c = Tlas::build(&instances, &selected, &blases).unwrap();
    for other in [&b, &c] {
        assert_eq!(a.nodes, other.nodes);
        assert_eq!(a.instances, other.instances);
        assert_eq!(a.stats, other.stats);
        assert_eq!(a.bounds, other.bounds);
    }
}
