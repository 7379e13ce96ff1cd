//! Per-frame TLAS rebuilds: a builder reused across frames whose instance sets grow, shrink and
//! move (so its kept buffers hold stale data from a larger build) must trace exactly like brute
//! force over every triangle of the selected instances, on a scene large enough (hundreds of
//! instances, several TLAS levels, village-like rows with equal boxes) to take every path of the
//! small-input build.

use glam::{Affine3A, Quat, Vec3};
use hikari_bvh::reference::assert_tlas_matches_brute_force;
use hikari_bvh::reference::random_rays;
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::tlas::TlasBuilder;
use hikari_bvh::{Blas, BuildOptions, Instance, Mesh, Ray, Tlas};

/// Small meshes (brute force is over every triangle of every instance) placed as in a village:
/// half on a grid with equal rotations (many equal boxes and centroids, so SAH ties), half
/// scattered with arbitrary rotation, scale and mirroring.
fn village(count: usize) -> (Vec<Mesh>, Vec<Blas>, Vec<Instance>) {
    let meshes = vec![
        Mesh::random_soup(1, 12, 1.0, 0.6),
        Mesh::terrain(3),
        Mesh::random_soup(2, 6, 0.5, 1.0),
    ];
    let blases: Vec<Blas> = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| Blas::from_mesh(&format!("m{i}"), m, &BuildOptions::default()).unwrap())
        .collect();
    let mut rng = SplitMix64::new(17);
    let instances = (0..count)
        .map(|i| {
            let blas = (i % meshes.len()) as u32;
            let shrink = if blas == 1 { 0.02 } else { 1.0 };
            let transform = if i % 2 == 0 {
                let cell = (i / 2) as f32;
                let t = Vec3::new((cell % 16.0) * 3.0 - 24.0, 0.0, (cell / 16.0).floor() * 3.0);
                Affine3A::from_scale_rotation_translation(Vec3::splat(shrink), Quat::IDENTITY, t)
            } else {
                let axis = hikari_bvh::reference::random_dir(&mut rng);
                let rot = Quat::from_axis_angle(axis, rng.range(0.0, std::f32::consts::TAU));
                let mut scale = Vec3::new(
                    rng.range(0.5, 2.0),
                    rng.range(0.5, 2.0),
                    rng.range(0.5, 2.0),
                ) * shrink;
                if i % 5 == 1 {
                    scale.y = -scale.y;
                }
                let t = Vec3::new(
                    rng.range(-30.0, 30.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 40.0),
                );
                Affine3A::from_scale_rotation_translation(scale, rot, t)
            };
            Instance::new(transform, blas)
        })
        .collect();
    (meshes, blases, instances)
}

#[test]
fn reused_builder_matches_brute_force_frame_after_frame() {
    let (meshes, blases, mut instances) = village(600);
    let mut rng = SplitMix64::new(5);
    // Random rays, and rays aimed near random instances so that most of them hit something.
    let mut rays = random_rays(&mut rng, 60, 30.0);
    for ray in random_rays(&mut rng, 100, 30.0) {
        let target = Vec3::from(instances[rng.below(instances.len())].transform.translation);
        let jitter = hikari_bvh::reference::random_dir(&mut rng) * rng.range(0.0, 0.5);
        let origin = Vec3::from(ray.origin);
        rays.push(Ray::new(
            origin,
            target + jitter - origin,
            0.0,
            f32::INFINITY,
        ));
    }
    let mut builder = TlasBuilder::default();
    // Frames: everything, a culled half, a handful, a single instance, everything again after
    // some instances moved.
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let half: Vec<u32> = all.iter().copied().filter(|i| i % 7 < 4).collect();
    let few: Vec<u32> = vec![599, 3, 250, 17, 18, 401, 2, 90, 91, 92, 300];
    let frames: [&[u32]; 4] = [&all, &half, &few, &[42]];
    let mut total_hits = 0;
    for selected in frames {
        let tlas = builder.build(&instances, selected, &blases).unwrap();
        assert_eq!(tlas.stats.instances, selected.len());
        total_hits +=
            assert_tlas_matches_brute_force(&tlas, &meshes, &blases, &instances, selected, &rays);
    }
    for inst in instances.iter_mut().step_by(3) {
        inst.transform.translation += glam::Vec3A::new(0.5, 1.0, -0.25);
    }
    let tlas = builder.build(&instances, &all, &blases).unwrap();
    assert!(tlas.stats.depth >= 3, "depth {}", tlas.stats.depth);
    total_hits += assert_tlas_matches_brute_force(&tlas, &meshes, &blases, &instances, &all, &rays);
    // Rays that miss everything would pass trivially.
    assert!(total_hits > 100, "{total_hits} hits");
}

#[test]
fn builder_and_one_shot_build_give_the_same_tlas() {
    let (_, blases, instances) = village(400);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let mut builder = TlasBuilder::default();
    // A larger build first, so the builder's buffers hold stale data.
    let first = builder.build(&instances, &all, &blases).unwrap();
    let subset: Vec<u32> = all.iter().copied().filter(|i| i % 3 != 0).collect();
    for selected in [&subset, &all] {
        let reused = builder.build(&instances, selected, &blases).unwrap();
        let fresh = TlasBuilder::default()
            .build(&instances, selected, &blases)
            .unwrap();
        let wrapper = Tlas::build(&instances, selected, &blases).unwrap();
        for other in [&fresh, &wrapper] {
            assert_eq!(reused.nodes, other.nodes);
            assert_eq!(reused.instances, other.instances);
            assert_eq!(reused.stats, other.stats);
        }
    }
    assert_eq!(first.stats.instances, all.len());
}

/// Builds with `builder` and with a fresh one, and checks the two TLAS are identical.
fn same_as_cold(
    builder: &mut TlasBuilder,
    instances: &[Instance],
    selected: &[u32],
    blases: &[Blas],
    frame: &str,
) -> Tlas {
    let warm = builder.build(instances, selected, blases).unwrap();
    let cold = TlasBuilder::default()
        .build(instances, selected, blases)
        .unwrap();
    assert!(warm.nodes == cold.nodes, "{frame}: nodes differ");
    assert!(
        warm.instances == cold.instances,
        "{frame}: instance records differ"
    );
    assert_eq!(warm.stats, cold.stats, "{frame}");
    assert_eq!(warm.bounds, cold.bounds, "{frame}");
    warm
}

#[test]
fn kept_instance_data_gives_the_tlas_of_a_cold_build() {
    let (meshes, mut blases, mut instances) = village(500);
    let mut rng = SplitMix64::new(8);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let mut builder = TlasBuilder::default();
    same_as_cold(&mut builder, &instances, &all, &blases, "first frame");

    // Some instances move, by a little (one ulp) or a lot; one gets a mirrored transform.
    for inst in instances.iter_mut().step_by(7) {
        inst.transform.translation.x = f32::from_bits(inst.transform.translation.x.to_bits() + 1);
    }
    for inst in instances.iter_mut().skip(3).step_by(11) {
        inst.transform.translation += glam::Vec3A::new(rng.range(-5.0, 5.0), 0.0, 2.0);
    }
    instances[10].transform.matrix3.x_axis = -instances[10].transform.matrix3.x_axis;
    same_as_cold(&mut builder, &instances, &all, &blases, "moved");

    // Some become invalid, others switch BLAS.
    let singular = Affine3A::from_scale(Vec3::new(0.0, 1.0, 1.0));
    let saved = (instances[20].transform, instances[21].transform);
    instances[20].transform = singular;
    instances[21].transform.translation.y = f32::NAN;
    instances[30].blas = (instances[30].blas + 1) % blases.len() as u32;
    let t = same_as_cold(&mut builder, &instances, &all, &blases, "invalid");
    assert_eq!(t.stats.skipped_invalid, 2);
    // And come back.
    (instances[20].transform, instances[21].transform) = saved;
    same_as_cold(&mut builder, &instances, &all, &blases, "valid again");

    // A BLAS is refit (its box grows) while instances of it are culled for a few frames: when
    // they come back, their world boxes must be the refit BLAS's.
    let culled: Vec<u32> = all
        .iter()
        .copied()
        .filter(|&i| instances[i as usize].blas != 0)
        .collect();
    same_as_cold(&mut builder, &instances, &culled, &blases, "culled");
    let grown: Vec<Vec3> = meshes[0].positions.iter().map(|p| *p * 1.5).collect();
    blases[0].refit(&grown).unwrap();
    same_as_cold(
        &mut builder,
        &instances,
        &culled,
        &blases,
        "refit, still culled",
    );
    same_as_cold(
        &mut builder,
        &instances,
        &culled,
        &blases,
        "refit, still culled again",
    );
    let t = same_as_cold(
        &mut builder,
        &instances,
        &all,
        &blases,
        "back after the refit",
    );

    // The rebuilt TLAS traces the refit geometry.
    let moved: Vec<Mesh> = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            if i == 0 {
                Mesh::new(grown.clone(), m.indices.clone())
            } else {
                m.clone()
            }
        })
        .collect();
    let rays = random_rays(&mut rng, 150, 30.0);
    assert_tlas_matches_brute_force(&t, &moved, &blases, &instances, &all, &rays);

    // A different, shorter BLAS list (box of BLAS 1 changed, BLAS 2 gone), then the old one.
    let fewer: Vec<Blas> = vec![blases[0].clone(), blases[2].clone()];
    let some: Vec<u32> = all
        .iter()
        .copied()
        .filter(|&i| instances[i as usize].blas < 2)
        .collect();
    same_as_cold(&mut builder, &instances, &some, &fewer, "other BLAS list");
    same_as_cold(
        &mut builder,
        &instances,
        &all,
        &blases,
        "first BLAS list again",
    );

    // More instances than the builder keeps data for: derived afresh each build.
    let mut many = instances.clone();
    while many.len() <= 70_000 {
        many.extend_from_slice(&instances);
    }
    let spread: Vec<u32> = (0..many.len() as u32).step_by(97).collect();
    same_as_cold(&mut builder, &many, &spread, &blases, "long instance list");
    same_as_cold(&mut builder, &instances, &all, &blases, "short list again");
}
