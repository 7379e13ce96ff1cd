//! The WGSL traversal (`shaders/bvh/traverse.wgsl`) against its CPU twin (hikari-bvh's
//! traversal of the same buffers) against brute force over every triangle, on small scenes:
//! random triangle soups, instances with rotations, scales and mirrors, and a terrain.

use crate::common;

use glam::{Affine3A, Quat, Vec3};
use hikari_bvh::reference::{
    any_hit_instances, closest_hit_instances, random_dir, random_rays, same_hit,
};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Hit, Instance, Mesh, Ray, Tlas};
use hikari_render::GpuContext;
use hikari_render::graph::GraphRuntime;
use hikari_render::scene::bvh::BvhAlpha;
use hikari_render::scene::bvh_trace::{
    BvhTrace, HIT_BYTES, RayOrder, Refill, TraceConfig, TraceMode,
};
use hikari_render::shader;
use wgpu::util::DeviceExt;

struct Scene {
    meshes: Vec<Mesh>,
    blases: Vec<Blas>,
    instances: Vec<Instance>,
    tlas: Tlas,
}

impl Scene {
    fn new(meshes: Vec<Mesh>, instances: Vec<Instance>) -> Self {
        let blases: Vec<Blas> = meshes
            .iter()
            .enumerate()
            .map(|(i, m)| {
                Blas::from_mesh(&format!("mesh{i}"), m, &BuildOptions::default()).unwrap()
            })
            .collect();
        let all: Vec<u32> = (0..instances.len() as u32).collect();
        let tlas = Tlas::build(&instances, &all, &blases).unwrap();
        Self {
            meshes,
            blases,
            instances,
            tlas,
        }
    }

    fn single(mesh: Mesh) -> Self {
        Self::new(vec![mesh], vec![Instance::new(Affine3A::IDENTITY, 0)])
    }
}

struct Gpu {
    ctx: GpuContext,
    lib: shader::ShaderLibrary,
}

impl Gpu {
    fn new() -> Self {
        let ctx = common::gpu_context();
        let lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
        Self { ctx, lib }
    }

    /// Hits of both modes for `rays`, traced in one frame by the default kernels (closest hit
    /// as coherent rays, any hit as incoherent ones).
    fn trace(&mut self, scene: &Scene, rays: &[Ray]) -> (Vec<Hit>, Vec<Hit>) {
        let trace = BvhTrace::new(&self.ctx, &mut self.lib).unwrap();
        self.trace_on(trace, scene, rays)
    }

    /// As [`Gpu::trace`] with both modes tracing the rays as a row-major image.
    fn trace_image(&mut self, scene: &Scene, rays: &[Ray], width: u32) -> (Vec<Hit>, Vec<Hit>) {
        let trace = BvhTrace::new(&self.ctx, &mut self.lib).unwrap();
        let order = RayOrder::Image { width };
        self.trace_on_with(trace, scene, rays, [order, order])
    }

    /// As [`Gpu::trace`] with one configuration for both.
    fn trace_with(
        &mut self,
        scene: &Scene,
        rays: &[Ray],
        config: TraceConfig,
    ) -> (Vec<Hit>, Vec<Hit>) {
        let trace = BvhTrace::with_config(&self.ctx, &mut self.lib, config).unwrap();
        self.trace_on(trace, scene, rays)
    }

    fn trace_on(&mut self, trace: BvhTrace, scene: &Scene, rays: &[Ray]) -> (Vec<Hit>, Vec<Hit>) {
        self.trace_on_with(
            trace,
            scene,
            rays,
            [RayOrder::Coherent, RayOrder::Incoherent],
        )
    }

    /// Closest hits traced as rays of `orders[0]`, any hits as rays of `orders[1]`.
    fn trace_on_with(
        &mut self,
        mut trace: BvhTrace,
        scene: &Scene,
        rays: &[Ray],
        orders: [RayOrder; 2],
    ) -> (Vec<Hit>, Vec<Hit>) {
        let ctx = &self.ctx;
        trace.upload_blases(ctx, &scene.blases).unwrap();
        trace.upload_tlas(ctx, &scene.tlas).unwrap();
        let marked = scene
            .blases
            .iter()
            .any(|b| b.triangles.iter().any(|t| !t.is_opaque()));
        if marked {
            // Every instance opaque: the filter accepts every candidate.
            let alpha = BvhAlpha::opaque(scene.instances.len());
            trace.upload_alpha(ctx, &alpha, None).unwrap();
        }
        let ray_buffer = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("test.rays"),
                contents: bytemuck::cast_slice(rays),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let n = rays.len() as u32;
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(ctx);
        let rays_buf = g.import_buffer("test.rays", &ray_buffer);
        let closest = g.buffer("test.closest", n as u64 * HIT_BYTES).unwrap();
        let any = g.buffer("test.any", n as u64 * HIT_BYTES).unwrap();
        trace
            .record(&mut g, rays_buf, closest, n, TraceMode::Closest, orders[0])
            .unwrap();
        trace
            .record(&mut g, rays_buf, any, n, TraceMode::Any, orders[1])
            .unwrap();
        g.readback(closest);
        g.readback(any);
        let r = g.execute().unwrap();
        let get = |name: &str| -> Vec<Hit> {
            let bytes = &r.buffers.iter().find(|(b, _)| b == name).unwrap().1;
            bytemuck::pod_collect_to_vec(&bytes[..rays.len() * HIT_BYTES as usize])
        };
        (get("test.closest"), get("test.any"))
    }
}

fn as_option(h: Hit) -> Option<Hit> {
    h.is_hit().then_some(h)
}

/// Kernel configurations every comparison runs: the two defaults, and the other code paths of
/// the kernel (wgpu's checks on; every way of picking the next ray; every triangle budget per
/// step; small and large workgroups).
fn configs(ctx: &GpuContext) -> Vec<(String, TraceConfig)> {
    let coherent = TraceConfig::coherent();
    let mut v = vec![
        coherent,
        TraceConfig::incoherent(),
        TraceConfig {
            runtime_checks: true,
            triangles_per_step: 0,
            ..coherent
        },
        TraceConfig {
            workgroup: 32,
            rays_per_thread: 4,
            triangles_per_step: 1,
            ..coherent
        },
        TraceConfig {
            workgroup: 128,
            rays_per_thread: 16,
            refill: Refill::Dynamic,
            triangles_per_step: 3,
            ..coherent
        },
    ];
    if ctx.has(wgpu::Features::SUBGROUP) {
        v.push(TraceConfig {
            rays_per_thread: 32,
            refill: Refill::Subgroup { min_free: 8 },
            triangles_per_step: 4,
            ..coherent
        });
    } else {
        eprintln!("no subgroup operations on this adapter: Refill::Subgroup not tested");
    }
    v.into_iter().map(|c| (format!("{c:?}"), c)).collect()
}

/// GPU vs CPU twin vs brute force, closest and any hit, for every kernel configuration;
/// returns the number of hits.
fn check(gpu: &mut Gpu, name: &str, scene: &Scene, rays: &[Ray]) -> usize {
    let mut hits = 0;
    for (config_name, config) in configs(&gpu.ctx) {
        let (closest, any) = gpu.trace_with(scene, rays, config);
        hits = check_hits(
            &format!("{name}, {config_name}"),
            scene,
            rays,
            &closest,
            &any,
        );
    }
    hits
}

fn check_hits(name: &str, scene: &Scene, rays: &[Ray], closest: &[Hit], any: &[Hit]) -> usize {
    let mut hits = 0;
    let mut failures = Vec::new();
    for (i, ray) in rays.iter().enumerate() {
        let cpu = scene.tlas.closest_hit(&scene.blases, ray);
        let brute = closest_hit_instances(&scene.meshes, &scene.instances, None, ray);
        if let Err(e) = same_hit(cpu, brute) {
            failures.push(format!("ray {i} {ray:?}: CPU vs brute force: {e}"));
        }
        if let Err(e) = same_hit(as_option(closest[i]), cpu) {
            failures.push(format!("ray {i} {ray:?}: GPU vs CPU: {e}"));
        }
        if !closest[i].is_hit()
            && (closest[i].t != f32::INFINITY || closest[i].instance != Hit::MISS)
        {
            failures.push(format!(
                "ray {i}: a miss must have t = inf and no instance: {:?}",
                closest[i]
            ));
        }
        let cpu_any = scene.tlas.any_hit(&scene.blases, ray);
        let brute_any = any_hit_instances(&scene.meshes, &scene.instances, None, ray);
        if cpu_any != brute_any {
            failures.push(format!(
                "ray {i} {ray:?}: CPU any-hit {cpu_any}, brute force {brute_any}"
            ));
        }
        if any[i].is_hit() != cpu_any {
            failures.push(format!(
                "ray {i} {ray:?}: GPU any-hit {:?}, CPU {cpu_any}",
                any[i]
            ));
        } else if any[i].is_hit() && !(any[i].t > ray.t_min && any[i].t < ray.t_max) {
            failures.push(format!(
                "ray {i} {ray:?}: any-hit outside (t_min, t_max): {:?}",
                any[i]
            ));
        }
        hits += closest[i].is_hit() as usize;
    }
    assert!(
        failures.is_empty(),
        "{name}: {} of {} rays disagree; first ones:\n{}",
        failures.len(),
        rays.len(),
        failures[..failures.len().min(12)].join("\n")
    );
    hits
}

#[test]
fn random_soups_match_cpu_and_brute_force() {
    let mut gpu = Gpu::new();
    for (seed, count) in [(1u64, 1usize), (2, 7), (3, 60), (4, 700), (5, 5000)] {
        let scene = Scene::single(Mesh::random_soup(seed, count, 10.0, 3.0));
        let mut rng = SplitMix64::new(seed * 31);
        let rays = random_rays(&mut rng, 700, 12.0);
        let hits = check(
            &mut gpu,
            &format!("soup {seed} ({count} triangles)"),
            &scene,
            &rays,
        );
        if count >= 700 {
            assert!(hits > 100, "test rays should hit something ({hits})");
        }
    }
}

#[test]
fn flagged_triangles_with_the_accept_all_filter_trace_like_opaque_ones() {
    // With every instance's material opaque (BvhAlpha::opaque, see `trace_on_with`),
    // bvh_accept_candidate accepts every candidate: non-opaque triangles must then give
    // bit-identical hits, and the flag must not disturb the records the kernel reads
    // (vertices, primitive). tests/render/bvh_alpha.rs tests real cut-outs.
    let mut gpu = Gpu::new();
    let mesh = Mesh::random_soup(6, 2000, 10.0, 3.0);
    let plain = Scene::single(mesh.clone());
    let marks: Vec<bool> = (0..mesh.indices.len()).map(|i| i % 3 != 0).collect();
    let mut flagged = Scene::single(mesh.clone());
    flagged.blases = vec![
        Blas::build_with_opacity(
            "flagged",
            &mesh.positions,
            &mesh.indices,
            &marks,
            &BuildOptions::default(),
        )
        .unwrap(),
    ];
    flagged.tlas = Tlas::build(&flagged.instances, &[0], &flagged.blases).unwrap();
    assert!(flagged.blases[0].triangles.iter().any(|t| !t.is_opaque()));
    let mut rng = SplitMix64::new(61);
    let rays = random_rays(&mut rng, 1000, 12.0);
    for (config_name, config) in configs(&gpu.ctx) {
        // Kernels with the cut-out test compiled in (without it, a TLAS with marked
        // triangles is refused: tests/render/bvh_alpha.rs).
        let config = TraceConfig {
            alpha: true,
            ..config
        };
        let (closest, any) = gpu.trace_with(&plain, &rays, config);
        let (f_closest, f_any) = gpu.trace_with(&flagged, &rays, config);
        assert!(closest == f_closest, "{config_name}: closest hits differ");
        assert!(any == f_any, "{config_name}: any hits differ");
        let hits = check_hits(
            &format!("flagged, {config_name}"),
            &flagged,
            &rays,
            &f_closest,
            &f_any,
        );
        assert!(hits > 100, "test rays should hit something ({hits})");
    }
}

#[test]
fn mixed_scale_soup_matches() {
    // Tiny triangles next to long slivers: wide boxes beside small ones stress quantization.
    let mut gpu = Gpu::new();
    let mut mesh = Mesh::random_soup(11, 1500, 10.0, 0.05);
    let slivers = Mesh::random_soup(12, 500, 10.0, 20.0);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(&slivers.positions);
    mesh.indices
        .extend(slivers.indices.iter().map(|t| t.map(|i| i + base)));
    let mut rng = SplitMix64::new(13);
    let rays = random_rays(&mut rng, 1000, 12.0);
    check(&mut gpu, "mixed", &Scene::single(mesh), &rays);
}

#[test]
fn instanced_scene_matches() {
    let mut gpu = Gpu::new();
    let meshes = vec![
        Mesh::random_soup(3, 300, 3.0, 1.5),
        Mesh::terrain(17),
        Mesh::random_soup(4, 30, 1.0, 2.0),
    ];
    let mut rng = SplitMix64::new(21);
    let instances: Vec<Instance> = (0..48)
        .map(|i| {
            let axis = random_dir(&mut rng);
            let rot = Quat::from_axis_angle(axis, rng.range(0.0, std::f32::consts::TAU));
            let mut scale = Vec3::new(
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
            );
            if i % 5 == 0 {
                scale.x = -scale.x;
            }
            let blas = (i % 3) as u32;
            if blas == 1 {
                scale *= 0.1;
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
    let scene = Scene::new(meshes, instances);
    assert!(
        scene.tlas.stats.depth >= 2,
        "the TLAS should have more than one level"
    );
    let mut rng = SplitMix64::new(22);
    let rays = random_rays(&mut rng, 1500, 35.0);
    let hits = check(&mut gpu, "instances", &scene, &rays);
    assert!(hits > 100, "{hits} hits");
    // The instance reported is the index in the caller's list, not the TLAS leaf order.
    let (closest, _) = gpu.trace(&scene, &rays);
    let seen: std::collections::HashSet<u32> = closest
        .iter()
        .filter(|h| h.is_hit())
        .map(|h| h.instance)
        .collect();
    assert!(seen.len() > 10, "hits spread over instances: {seen:?}");
}

fn terrain_rays(rng: &mut SplitMix64, count: usize) -> Vec<Ray> {
    (0..count)
        .map(|i| {
            let x = rng.range(-90.0, 90.0);
            let z = rng.range(-90.0, 90.0);
            let y = hikari_bvh::mesh::terrain_height(x, z);
            match i % 3 {
                0 => Ray::new(
                    Vec3::new(x, 30.0, z),
                    random_dir(rng) - Vec3::Y * 1.5,
                    0.0,
                    f32::INFINITY,
                ),
                1 => {
                    let d = random_dir(rng);
                    Ray::new(
                        Vec3::new(x, y + 0.5, z),
                        Vec3::new(d.x, 0.02 * d.y, d.z),
                        0.0,
                        f32::INFINITY,
                    )
                }
                _ => {
                    let mut d = random_dir(rng);
                    d.y = d.y.abs();
                    Ray::new(Vec3::new(x, y + 0.01, z), d, 0.0, 5.0)
                }
            }
        })
        .collect()
}

#[test]
fn terrain_matches() {
    let mut gpu = Gpu::new();
    // 64 x 64 cells, 8192 triangles.
    let scene = Scene::single(Mesh::terrain(65));
    let mut rng = SplitMix64::new(5);
    let rays = terrain_rays(&mut rng, 2400);
    let hits = check(&mut gpu, "terrain", &scene, &rays);
    assert!(hits > 800, "{hits} hits");
}

#[test]
fn rays_through_shared_edges_and_vertices_never_leak() {
    // Straight down and slanted through grid vertices and cell edges of the terrain: the
    // watertight test must report a hit for every one.
    let mut gpu = Gpu::new();
    let n = 33;
    let mesh = Mesh::terrain(n);
    let v = |i: usize, j: usize| mesh.positions[j * n + i];
    let mut rays = Vec::new();
    for j in 2..n - 2 {
        for i in 2..n - 2 {
            // A vertex, the midpoints of two cell edges, and the midpoint of the cell's diagonal
            // (Mesh::terrain splits cells along (i+1, j)-(i, j+1)), all on the surface.
            let targets = [
                v(i, j),
                (v(i, j) + v(i + 1, j)) * 0.5,
                (v(i, j) + v(i, j + 1)) * 0.5,
                (v(i + 1, j) + v(i, j + 1)) * 0.5,
            ];
            for p in targets {
                for d in [
                    Vec3::NEG_Y,
                    Vec3::new(0.3, -1.0, -0.2),
                    Vec3::new(-0.05, -0.3, 0.1),
                ] {
                    rays.push(Ray::new(p - d * 40.0, d, 0.0, f32::INFINITY));
                }
            }
        }
    }
    let scene = Scene::single(mesh);
    let (closest, any) = gpu.trace(&scene, &rays);
    // Named on failure: what the CPU twin makes of a leaking ray tells a kernel bug from a
    // test-geometry mistake.
    for i in (0..rays.len()).filter(|&i| !closest[i].is_hit()).take(8) {
        eprintln!(
            "leak ray {i} {:?}: CPU {:?}, GPU any hit {:?}",
            rays[i],
            scene.tlas.closest_hit(&scene.blases, &rays[i]),
            any[i]
        );
    }
    let leaks = closest.iter().filter(|h| !h.is_hit()).count();
    let any_leaks = any.iter().filter(|h| !h.is_hit()).count();
    assert_eq!((leaks, any_leaks), (0, 0), "of {} rays", rays.len());
    check(&mut gpu, "edges", &scene, &rays);
}

#[test]
fn nan_and_degenerate_rays_miss_and_terminate() {
    let mut gpu = Gpu::new();
    let scene = Scene::single(Mesh::random_soup(8, 400, 5.0, 2.0));
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let rays = vec![
        Ray::new(Vec3::new(nan, 0.0, 0.0), Vec3::X, 0.0, inf),
        Ray::new(Vec3::ZERO, Vec3::new(nan, 1.0, 0.0), 0.0, inf),
        Ray::new(Vec3::ZERO, Vec3::splat(nan), 0.0, inf),
        Ray::new(Vec3::splat(nan), Vec3::splat(nan), nan, nan),
        Ray::new(Vec3::ZERO, Vec3::X, nan, inf),
        Ray::new(Vec3::ZERO, Vec3::X, 0.0, nan),
        Ray::new(Vec3::ZERO, Vec3::ZERO, 0.0, inf),
        Ray::new(Vec3::new(inf, 0.0, 0.0), Vec3::NEG_X, 0.0, inf),
        Ray::new(Vec3::ZERO, Vec3::new(inf, 0.0, 0.0), 0.0, inf),
        // Empty t range, reversed t range.
        Ray::new(Vec3::ZERO, Vec3::X, 3.0, 3.0),
        Ray::new(Vec3::ZERO, Vec3::X, 5.0, 1.0),
    ];
    let (closest, any) = gpu.trace(&scene, &rays);
    for (i, (c, a)) in closest.iter().zip(&any).enumerate() {
        assert!(
            !c.is_hit() && !a.is_hit(),
            "ray {i} {:?} hit: {c:?} / {a:?}",
            rays[i]
        );
        assert!(
            scene.tlas.closest_hit(&scene.blases, &rays[i]).is_none(),
            "the CPU twin agrees"
        );
    }
}

#[test]
fn empty_scene_misses() {
    let mut gpu = Gpu::new();
    let scene = Scene::new(vec![], vec![]);
    let rays = vec![Ray::new(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY); 5];
    let (closest, any) = gpu.trace(&scene, &rays);
    assert!(closest.iter().chain(&any).all(|h| !h.is_hit()));
}

#[test]
fn any_hit_respects_t_max_and_closest_reports_the_nearest() {
    // Two parallel triangles at z = 1 and z = 2 (two instances of one BLAS).
    let mut gpu = Gpu::new();
    let mesh = Mesh::new(
        vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(2.0, -1.0, 0.0),
            Vec3::new(-1.0, 2.0, 0.0),
        ],
        vec![[0, 1, 2]],
    );
    let instances = vec![
        Instance::new(Affine3A::from_translation(Vec3::Z * 2.0), 0),
        Instance::new(Affine3A::from_translation(Vec3::Z), 0),
    ];
    let scene = Scene::new(vec![mesh], instances);
    let o = Vec3::new(0.1, 0.2, 0.0);
    let rays = vec![
        Ray::new(o, Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(o, Vec3::Z, 0.0, 1.5),
        Ray::new(o, Vec3::Z, 0.0, 0.999),
        Ray::new(o, Vec3::Z, 1.5, f32::INFINITY),
        Ray::new(o, Vec3::Z * 2.0, 0.0, f32::INFINITY),
    ];
    let (closest, any) = gpu.trace(&scene, &rays);
    assert_eq!(closest[0].instance, 1);
    assert!((closest[0].t - 1.0).abs() < 1e-6);
    assert!(
        (closest[0].u - 0.1 / 3.0 - 1.0 / 3.0).abs() < 1e-5,
        "{:?}",
        closest[0]
    );
    assert!(any[1].is_hit() && any[1].instance == 1);
    assert!(!any[2].is_hit() && !closest[2].is_hit());
    assert_eq!(closest[3].instance, 0);
    assert!((closest[3].t - 2.0).abs() < 1e-6);
    // t is in units of the direction, in world and object space alike.
    assert!((closest[4].t - 0.5).abs() < 1e-6);
    check(&mut gpu, "two planes", &scene, &rays);
}

#[test]
fn malformed_bvhs_and_short_buffers_are_refused() {
    // The kernel runs without bounds checks, so everything it would index must be refused
    // before it reaches the GPU, with an error that says what is wrong.
    let gpu = Gpu::new();
    let Gpu { ctx, mut lib } = gpu;
    let scene = Scene::single(Mesh::random_soup(9, 300, 5.0, 2.0));
    let mut trace = BvhTrace::new(&ctx, &mut lib).unwrap();
    let refused = |blas: Blas, trace: &mut BvhTrace| -> String {
        trace
            .upload_blases(&ctx, std::slice::from_ref(&blas))
            .expect_err("a malformed BLAS must be refused")
            .to_string()
    };
    let good = &scene.blases[0];
    let internal_slot = (0..8)
        .find(|&s| good.nodes[0].imask() & (1 << s) != 0)
        .expect("the root of a 300-triangle BLAS has internal children");

    let mut b = good.clone();
    b.nodes[0].child_base = b.nodes.len() as u32;
    let e = refused(b, &mut trace);
    assert!(e.contains("node 0") && e.contains("child node"), "{e}");

    let mut b = good.clone();
    b.nodes[0].child_base = 0;
    let e = refused(b, &mut trace);
    assert!(e.contains("not after this node"), "{e}");

    let mut b = good.clone();
    b.nodes[0].set_meta(internal_slot, 0x20);
    let e = refused(b, &mut trace);
    assert!(e.contains("internal child with meta"), "{e}");

    // A leaf whose primitives run past the BLAS's triangles.
    let leaf = b_leaf(good);
    let mut b = good.clone();
    b.nodes[leaf.0].prim_base = b.triangles.len() as u32;
    let e = refused(b, &mut trace);
    assert!(e.contains("out of the"), "{e}");

    // A leaf count that is not unary.
    let mut b = good.clone();
    let m = b.nodes[leaf.0].meta(leaf.1);
    b.nodes[leaf.0].set_meta(leaf.1, (m & 0x1f) | 0b010_00000);
    let e = refused(b, &mut trace);
    assert!(e.contains("leaf meta"), "{e}");

    // The intact BLAS goes up; a TLAS pointing at a BLAS that is not there does not.
    trace.upload_blases(&ctx, &scene.blases).unwrap();
    let mut tlas = scene.tlas.clone();
    tlas.instances[0].blas_index = 3;
    let e = trace.upload_tlas(&ctx, &tlas).unwrap_err().to_string();
    assert!(e.contains("instance record 0"), "{e}");
    let mut tlas = scene.tlas.clone();
    tlas.instances[0].blas_node_offset = 1;
    assert!(trace.upload_tlas(&ctx, &tlas).is_err());
    trace.upload_tlas(&ctx, &scene.tlas).unwrap();

    // Buffers shorter than the ray count.
    let rays = vec![Ray::new(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY); 4];
    let ray_buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.rays"),
            contents: bytemuck::cast_slice(&rays),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let rays_buf = g.import_buffer("test.rays", &ray_buffer);
    let hits = g.buffer("test.hits", 4 * HIT_BYTES).unwrap();
    let e = trace
        .record(
            &mut g,
            rays_buf,
            hits,
            5,
            TraceMode::Closest,
            RayOrder::Coherent,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("rays buffer"), "{e}");
    let short_hits = g.buffer("test.short_hits", 3 * HIT_BYTES).unwrap();
    let e = trace
        .record(
            &mut g,
            rays_buf,
            short_hits,
            4,
            TraceMode::Any,
            RayOrder::Incoherent,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("hits buffer"), "{e}");
    trace
        .record(
            &mut g,
            rays_buf,
            hits,
            4,
            TraceMode::Closest,
            RayOrder::Coherent,
        )
        .unwrap();
    drop(g);

    // A BLAS list of another shape drops the TLAS checked against the old one.
    let other = Blas::from_mesh(
        "other",
        &Mesh::random_soup(10, 50, 5.0, 2.0),
        &BuildOptions::default(),
    )
    .unwrap();
    trace.upload_blases(&ctx, &[other]).unwrap();
    let mut g = rt.begin_frame(&ctx);
    let e = trace.import(&mut g).unwrap_err().to_string();
    assert!(e.contains("TLAS"), "{e}");
}

/// (node, slot) of some leaf slot of `blas`.
fn b_leaf(blas: &Blas) -> (usize, usize) {
    for (i, n) in blas.nodes.iter().enumerate() {
        for s in 0..8 {
            if n.imask() & (1 << s) == 0 && n.meta(s) != 0 {
                return (i, s);
            }
        }
    }
    panic!("a BLAS has leaves");
}

#[test]
fn image_order_traces_every_ray_once() {
    // Images whose sides are and are not multiples of the 8 x 8 tiles: every ray must be traced
    // and its hit written in its own place.
    let mut gpu = Gpu::new();
    let scene = Scene::single(Mesh::terrain(33));
    for (w, h) in [(16u32, 16u32), (21, 13), (7, 3), (1, 9), (30, 1)] {
        let eye = Vec3::new(3.0, 25.0, -60.0);
        let rays: Vec<Ray> = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| {
                    let sx = (x as f32 + 0.5) / w as f32 - 0.5;
                    let sy = (y as f32 + 0.5) / h as f32 - 0.5;
                    Ray::new(
                        eye,
                        Vec3::new(sx * 1.6, -0.4 - sy * 0.6, 1.0),
                        0.0,
                        f32::INFINITY,
                    )
                })
            })
            .collect();
        let (closest, any) = gpu.trace_image(&scene, &rays, w);
        let hits = check_hits(&format!("{w}x{h} image"), &scene, &rays, &closest, &any);
        assert!(hits > 0, "{w}x{h}: the camera looks at the terrain");
    }
    // A ray count that is not a whole number of rows is refused.
    let Gpu { ctx, mut lib } = gpu;
    let mut trace = BvhTrace::new(&ctx, &mut lib).unwrap();
    trace.upload_blases(&ctx, &scene.blases).unwrap();
    trace.upload_tlas(&ctx, &scene.tlas).unwrap();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let rays = g.buffer("test.rays", 10 * HIT_BYTES).unwrap();
    let hits = g.buffer("test.hits", 10 * HIT_BYTES).unwrap();
    for width in [0, 3] {
        let e = trace
            .record(
                &mut g,
                rays,
                hits,
                10,
                TraceMode::Closest,
                RayOrder::Image { width },
            )
            .unwrap_err()
            .to_string();
        assert!(e.contains("whole number of rows"), "{e}");
    }
}

#[test]
fn village_matches() {
    let mut gpu = Gpu::new();
    let village = hikari_scene::builtin::village();
    let scene = Scene::new(
        hikari_render::scene::bvh::meshes(&village),
        hikari_render::scene::bvh::instances(&village),
    );
    // From every named camera (inside houses and the temple too) in random directions, so
    // the rays meet thin walls, furniture, leaves and terrain; brute force keeps the count low.
    let mut rng = SplitMix64::new(55);
    let rays: Vec<Ray> = (0..120)
        .map(|k| {
            let cam = &village.cameras[k % village.cameras.len()];
            Ray::new(cam.position, random_dir(&mut rng), 0.0, f32::INFINITY)
        })
        .collect();
    // Brute force over 561k triangles is slow in a test: once, with the two kernels that
    // `hikari bench rays` uses (the other configurations are covered on smaller scenes).
    let (closest, any) = gpu.trace_with(&scene, &rays, TraceConfig::incoherent());
    let hits = check_hits("village, incoherent", &scene, &rays, &closest, &any);
    assert!(hits > 50, "{hits} hits");
    let (coherent_closest, coherent_any) = gpu.trace_with(&scene, &rays, TraceConfig::coherent());
    for (i, ray) in rays.iter().enumerate() {
        assert!(
            same_hit(as_option(coherent_closest[i]), as_option(closest[i])).is_ok()
                && coherent_any[i].is_hit() == any[i].is_hit(),
            "ray {i} {ray:?}: coherent and incoherent kernels disagree"
        );
    }
}
