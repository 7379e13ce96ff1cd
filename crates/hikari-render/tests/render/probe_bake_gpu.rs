//! The GPU probe bake (`probe_bake_gpu`) against its CPU twin (hikari-bake's `CpuTransport`,
//! on the same rays), and against closed forms on its own.
//!
//! Both trace the same probe directions and the same hashed secondary rays through the same
//! BVH; the GPU sums in f32 in another order, computes the secondary directions with its own
//! sin/cos, and may round a hit point or normal differently, which can flip a ray grazing an
//! edge. The tolerance is therefore [`RAY_FLIPS`] rays' worth of SH weight per coefficient,
//! `RAY_FLIPS · 4π/n · max|Y_i|`, plus 1e-4 for f32 sums of up to a few thousand terms.

use crate::common;

use std::f32::consts::PI;

use glam::{Mat4, Vec3};
use hikari_bake::scene_rays::SceneRays;
use hikari_bake::surfaces::SurfaceAlbedo;
use hikari_bake::transport::ProbeTransport;
use hikari_bake::{
    CpuTransport, GridBakeOptions, ProbeRequest, SceneBakeOptions, TransportSettings,
    TransportTracer, bake_scene_resume_with, transport_settings,
};
use hikari_probes::Bake;
use hikari_render::probe_bake_gpu::GpuTransport;
use hikari_scene::{Instance, Material, Mesh, Scene, Texture, TextureRef, shapes};

/// Rays per coefficient that may differ between the twins.
const RAY_FLIPS: f32 = 3.0;

fn max_abs_y() -> [f32; 9] {
    let s = 1.0 / (2.0 * PI.sqrt());
    let l1 = 3f32.sqrt() * s;
    let l2 = 15f32.sqrt() / (4.0 * PI.sqrt());
    [s, l1, l1, l1, l2, l2, 5f32.sqrt() * s, l2, l2]
}

fn tolerance(n: u32) -> [f32; 9] {
    max_abs_y().map(|y| RAY_FLIPS * 4.0 * PI / n as f32 * y + 1e-4)
}

fn settings(n: u32, bounce_rays: u32) -> TransportSettings {
    let options = SceneBakeOptions {
        grid: GridBakeOptions {
            rays_per_probe: n,
            ..Default::default()
        },
        bounce_rays,
        ..Default::default()
    };
    transport_settings(&options)
}

fn cpu(
    scene: &Scene,
    settings: &TransportSettings,
    probes: &[ProbeRequest],
) -> Vec<ProbeTransport> {
    let rays = SceneRays::build(scene).unwrap();
    let albedo = SurfaceAlbedo::new(scene);
    CpuTransport {
        scene: &rays,
        albedo: &albedo,
        settings,
    }
    .trace(probes)
    .unwrap()
}

fn gpu(
    ctx: &hikari_render::GpuContext,
    scene: &Scene,
    settings: &TransportSettings,
    probes: &[ProbeRequest],
) -> Vec<ProbeTransport> {
    GpuTransport::new(ctx, scene, settings.clone())
        .unwrap()
        .trace(probes)
        .unwrap()
}

fn probes_in(lo: Vec3, hi: Vec3, steps: [usize; 3]) -> Vec<ProbeRequest> {
    let mut v = Vec::new();
    let f = |i: usize, n: usize| {
        if n == 1 {
            0.5
        } else {
            i as f32 / (n - 1) as f32
        }
    };
    for iy in 0..steps[1] {
        for iz in 0..steps[2] {
            for ix in 0..steps[0] {
                let t = Vec3::new(f(ix, steps[0]), f(iy, steps[1]), f(iz, steps[2]));
                v.push(ProbeRequest {
                    position: lo + (hi - lo) * t,
                    seed: 0x9e37_79b9 ^ (v.len() as u64) << 7,
                });
            }
        }
    }
    v
}

fn assert_twins(name: &str, n: u32, m: u32, cpu: &[ProbeTransport], gpu: &[ProbeTransport]) {
    assert_eq!(cpu.len(), gpu.len(), "{name}: probe count");
    let tol = tolerance(n);
    let mut worst = 0.0f32;
    for (p, (c, g)) in cpu.iter().zip(gpu).enumerate() {
        #[allow(clippy::needless_range_loop)] // i indexes four arrays
        for i in 0..9 {
            let d = (c.sky_visibility[i] - g.sky_visibility[i]).abs();
            worst = worst.max(d / tol[i]);
            assert!(
                d <= tol[i],
                "{name}, probe {p}: sky coefficient {i} is {} on the GPU, {} on the CPU (± {})",
                g.sky_visibility[i],
                c.sky_visibility[i],
                tol[i]
            );
            for k in 0..3 {
                let d = (c.bounced[i][k] - g.bounced[i][k]).abs();
                worst = worst.max(d / tol[i]);
                assert!(
                    d <= tol[i],
                    "{name}, probe {p}: bounced coefficient {i} channel {k} is {} on the GPU, \
                     {} on the CPU (± {})",
                    g.bounced[i][k],
                    c.bounced[i][k],
                    tol[i]
                );
            }
        }
        assert!(
            (c.enclosed_fraction - g.enclosed_fraction).abs() <= RAY_FLIPS / n as f32,
            "{name}, probe {p}: enclosed fraction {} vs {}",
            g.enclosed_fraction,
            c.enclosed_fraction
        );
        let rays_diff = c.rays.abs_diff(g.rays);
        assert!(
            rays_diff <= RAY_FLIPS as u64 * u64::from(m),
            "{name}, probe {p}: {} rays on the GPU, {} on the CPU",
            g.rays,
            c.rays
        );
    }
    eprintln!("{name}: worst difference {worst:.3} of the tolerance");
}

fn one_instance_each(meshes: Vec<Mesh>, materials: Vec<Material>, of: &[usize]) -> Scene {
    let instances = of
        .iter()
        .enumerate()
        .map(|(mesh, &material)| Instance {
            mesh,
            material,
            transform: Mat4::IDENTITY,
        })
        .collect();
    Scene {
        meshes,
        materials,
        instances,
        ..Default::default()
    }
}

/// A textured, vertex-coloured, partly metallic ground, a single-sided box, a double-sided
/// mirrored box and a wall: every branch of the hit shading.
fn shading_scene() -> Scene {
    let mut ground = Mesh {
        name: "ground".into(),
        ..Default::default()
    };
    let c = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    shapes::push_triangle(&mut ground, c(-50.0, -50.0), c(-50.0, 50.0), c(50.0, 50.0));
    shapes::push_triangle(&mut ground, c(-50.0, -50.0), c(50.0, 50.0), c(50.0, -50.0));
    ground.colors = Some(vec![
        glam::Vec4::new(0.5, 0.8, 1.0, 1.0),
        glam::Vec4::new(1.0, 0.6, 0.2, 1.0),
        glam::Vec4::new(0.3, 0.9, 0.4, 1.0),
        glam::Vec4::new(0.7, 0.7, 0.7, 1.0),
        glam::Vec4::new(0.2, 0.4, 0.9, 1.0),
        glam::Vec4::new(0.9, 0.9, 0.1, 1.0),
    ]);
    let mut textured = Material::diffuse("textured", Vec3::new(0.9, 0.5, 0.7));
    textured.metalness = 0.25;
    textured.base_color_texture = Some(TextureRef::new(0));
    let single = Material::diffuse("red", Vec3::new(0.8, 0.1, 0.1));
    let mut double = Material::diffuse("white", Vec3::new(0.9, 0.9, 0.9));
    double.double_sided = true;
    let mut scene = one_instance_each(
        vec![
            ground,
            shapes::cuboid(Vec3::new(-3.0, 0.0, -3.0), Vec3::new(-1.0, 2.0, -1.0)),
            shapes::cuboid(Vec3::new(1.0, 0.0, -4.0), Vec3::new(4.0, 3.0, -2.0)),
            shapes::cuboid(Vec3::new(-6.0, 0.0, 2.0), Vec3::new(6.0, 5.0, 2.3)),
        ],
        vec![textured, single, double],
        &[0, 1, 2, 1],
    );
    // The double-sided box mirrored through x = 2.5: the winding (and the front face) flips.
    scene.instances[2].transform = Mat4::from_translation(Vec3::new(5.0, 0.0, 0.0))
        * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    scene.textures = vec![Texture {
        name: "t".into(),
        width: 2,
        height: 1,
        data: vec![0, 255, 64, 255, 188, 255, 64, 255],
        ..Default::default()
    }];
    scene
}

#[test]
fn gpu_transport_matches_the_cpu_twin() {
    let ctx = common::gpu_context();
    let (n, m) = (256, 2);
    let s = settings(n, m);
    let cases: Vec<(&str, Scene, Vec<ProbeRequest>)> = vec![
        (
            "shading scene",
            shading_scene(),
            probes_in(
                Vec3::new(-5.0, 0.5, -5.0),
                Vec3::new(5.0, 4.0, 5.0),
                [4, 3, 3],
            ),
        ),
        (
            "boxes",
            hikari_scene::builtin::boxes(),
            probes_in(
                Vec3::new(-8.0, 0.5, -8.0),
                Vec3::new(8.0, 6.0, 8.0),
                [3, 2, 3],
            ),
        ),
        (
            "village crop",
            hikari_scene::builtin::village(),
            probes_in(
                Vec3::new(-30.0, 0.0, -30.0),
                Vec3::new(30.0, 0.0, 30.0),
                [4, 1, 4],
            )
            .into_iter()
            .map(|mut r| {
                let (x, z) = (r.position.x, r.position.z);
                r.position.y = hikari_scene::builtin::terrain_height(x, z) + 1.5;
                r
            })
            .collect(),
        ),
    ];
    for (name, scene, probes) in &cases {
        let c = cpu(scene, &s, probes);
        let g = gpu(&ctx, scene, &s, probes);
        assert_twins(name, n, m, &c, &g);
        // Not a vacuous comparison: some rays bounced light back.
        if *name != "village crop" {
            assert!(
                c.iter().any(|t| t.bounced[0].iter().any(|&b| b > 0.01)),
                "{name}: no bounced light at all"
            );
        }
    }
}

#[test]
fn gpu_transport_known_answers() {
    let ctx = common::gpu_context();
    let n = 512;
    // Open space: a lone triangle 1 km away stands in for "nothing" (an empty scene never
    // reaches the kernels). Visibility 1 everywhere is the SH of a constant: c_0 = 2√π.
    let mut far = Mesh {
        name: "far".into(),
        ..Default::default()
    };
    shapes::push_triangle(
        &mut far,
        Vec3::new(1000.0, 0.0, 0.0),
        Vec3::new(1000.0, 1.0, 0.0),
        Vec3::new(1000.0, 0.0, 1.0),
    );
    let open = one_instance_each(vec![far], vec![Material::diffuse("m", Vec3::ONE)], &[0]);
    let probes = probes_in(Vec3::splat(-5.0), Vec3::splat(5.0), [2, 2, 2]);
    let t = gpu(&ctx, &open, &settings(n, 2), &probes);
    // The Fibonacci set integrates the constant exactly in c_0 and to within its own
    // quadrature error in the others (a few 4π/n).
    let tol = max_abs_y().map(|y| 4.0 * 4.0 * PI / n as f32 * y);
    for p in &t {
        assert!(
            (p.sky_visibility[0] - 2.0 * PI.sqrt()).abs() < 1e-3,
            "{p:?}"
        );
        for (c, t) in p.sky_visibility.iter().zip(tol).skip(1) {
            assert!(c.abs() <= t, "{p:?}");
        }
        assert!(p.bounced.iter().flatten().all(|&b| b == 0.0));
        assert_eq!(p.enclosed_fraction, 0.0);
        assert_eq!(p.rays, u64::from(n));
    }
    // A closed double-sided white box: no sky, and every surface seen is closed off too.
    let mut white = Material::diffuse("white", Vec3::ONE);
    white.double_sided = true;
    let boxed = one_instance_each(
        vec![shapes::cuboid(Vec3::splat(-2.0), Vec3::splat(2.0))],
        vec![white],
        &[0],
    );
    // No probe ray escapes. A secondary ray leaving a hit within millimetres of the box's
    // edges can slip out between two faces' triangles (the CPU twin loses the same rays: one
    // in a few thousand here), so bounced light is 0 up to two such rays' worth.
    let m = 4;
    let probes = probes_in(Vec3::splat(-1.5), Vec3::splat(1.5), [2, 2, 2]);
    let t = gpu(&ctx, &boxed, &settings(n, m), &probes);
    assert_twins(
        "closed box",
        n,
        m,
        &cpu(&boxed, &settings(n, m), &probes),
        &t,
    );
    let leak = max_abs_y().map(|y| 2.0 * 4.0 * PI / n as f32 * y / m as f32 + 1e-6);
    for p in &t {
        assert!(p.sky_visibility.iter().all(|&c| c == 0.0), "{p:?}");
        for (c, l) in p.bounced.iter().zip(leak) {
            assert!(c.iter().all(|b| b.abs() <= l), "{p:?}");
        }
        assert_eq!(p.enclosed_fraction, 1.0);
        assert_eq!(p.rays, u64::from(n) * 5);
    }
}

fn all_probes(b: &Bake) -> Vec<hikari_probes::ProbeSh> {
    b.tiles
        .iter()
        .flat_map(|t| t.probes.iter().copied())
        .chain(b.meshes.iter().flat_map(|m| m.probes.iter().copied()))
        .collect()
}

/// The whole bake (placement on the CPU, transport on the GPU, in batches) against the CPU
/// bake of the boxes: same probes, same interior flags, transport within the tolerance.
#[test]
fn gpu_bake_of_a_scene_matches_the_cpu_bake() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let options = SceneBakeOptions {
        grid: GridBakeOptions {
            rays_per_probe: 64,
            inside_test_rays: 16,
            progress_batch: 200,
            ..Default::default()
        },
        bounce_rays: 1,
        ..Default::default()
    };
    let fresh = || {
        Bake::new(
            options.scene_key,
            hikari_bake::scene_bake::bake_settings(&options),
        )
    };
    let cpu = bake_scene_resume_with(&scene, &options, fresh(), None, &|_| {}, &mut |_| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    let tracer = GpuTransport::new(&ctx, &scene, transport_settings(&options)).unwrap();
    let gpu = bake_scene_resume_with(
        &scene,
        &options,
        fresh(),
        Some(&tracer),
        &|_| {},
        &mut |_| std::ops::ControlFlow::Continue(()),
    )
    .unwrap();
    assert_eq!(cpu.tiles.len(), gpu.tiles.len());
    for (c, g) in cpu.tiles.iter().zip(&gpu.tiles) {
        assert_eq!(c.ground_heights_m, g.ground_heights_m);
    }
    let (c, g) = (all_probes(&cpu), all_probes(&gpu));
    let as_transport = |p: &hikari_probes::ProbeSh| ProbeTransport {
        sky_visibility: p.sky_visibility,
        bounced: p.bounced_sky_visibility,
        enclosed_fraction: 0.0,
        rays: 0,
    };
    let c: Vec<_> = c.iter().map(as_transport).collect();
    let g: Vec<_> = g.iter().map(as_transport).collect();
    assert!(c.len() >= 768);
    assert_twins("boxes bake", 64, 1, &c, &g);

    // A tracer built for other rays is refused, naming both.
    let other = GpuTransport::new(&ctx, &scene, settings(128, 1)).unwrap();
    let e = bake_scene_resume_with(
        &scene,
        &options,
        fresh(),
        Some(&other),
        &|_| {},
        &mut |_| std::ops::ControlFlow::Continue(()),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("gpu") && e.contains("128") && e.contains("64"),
        "{e}"
    );
}
