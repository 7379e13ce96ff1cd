//! Alpha cut-outs in the GPU traversal (`bvh_accept_candidate` in `shaders/bvh/traverse.wgsl`)
//! on the built-in `cutout` scene: closest and any hit, both kernel configurations, for rays
//! through its two double-sided quads from the front and from behind, and rays from the ground
//! towards the sun. Held to two references: the CPU traversal with the CPU twin of the filter
//! (`bvh::SceneAlphaFilter`), and the analytic coverage of the quads
//! (`builtin::cutout_checker_covered`, `builtin::cutout_ramp_alpha` against the ramp's cut-off)
//! at the exact point where the ray crosses them.
//!
//! Tolerance: a ray may disagree only when it crosses a quad within a quarter of a texel (1/256
//! in UV) of a cut-out edge (a checker cell edge, or the ramp's u = 0.25), or within 1 mm of a
//! quad's or the ground's outline. Alpha is read bilinearly at mip 0: its 0.5 contour between
//! the checker's 0 and 1 texels lies on the cell edges, and its contour at the ramp's cut-off
//! within 0.06 texel of u = 0.25 (8-bit alpha); the band holds the filtering's fixed-point
//! weights and float rounding. The band covers 1/8 of the checker's area (2/256 around each of
//! 8 cell edges a unit, on both axes) and 1/128 of the ramp's, so about 4.5% of these rays fall
//! in it; more than 8% would mean a wider band than stated. All others agree exactly.

use crate::common;

use common::cutout::{self, QUADS};

use glam::Vec3;
use hikari_bvh::reference::{random_dir, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Hit, Ray, Tlas};
use hikari_render::GpuContext;
use hikari_render::graph::GraphRuntime;
use hikari_render::scene::bvh::{self, BvhAlpha, SceneAlphaFilter};
use hikari_render::scene::bvh_trace::{BvhTrace, HIT_BYTES, RayOrder, TraceMode};
use hikari_render::scene::textures::TextureArrays;
use hikari_render::shader;
use hikari_scene::Scene;
use hikari_scene::builtin::{self, CUTOUT_RAMP_CUTOFF};
use wgpu::util::DeviceExt;

/// The analytic answer for one ray: the first surface it meets in (t_min, t_max) with the
/// cut-outs, whether that answer is within the tolerance band of another, and whether the ray
/// went through a hole (crossed a quad's inside where it is not covered).
#[derive(Clone, Copy, Debug)]
struct Analytic {
    hit: Option<u32>,
    ambiguous: bool,
    through_hole: bool,
}

/// Traces the scene analytically. The BVH culls no faces, so the ground counts from below too.
fn analytic(ray: &Ray) -> Analytic {
    let t = cutout::trace(
        Vec3::from(ray.origin),
        Vec3::from(ray.dir),
        ray.t_min,
        ray.t_max,
        true,
        true,
    );
    Analytic {
        hit: t.hit.map(|(i, _)| i),
        ambiguous: t.ambiguous,
        through_hole: t.through_hole,
    }
}

/// Rays that cross the quads from the front and from behind (`t_max` infinite, or `short`:
/// ending 0.5 m past the quads' plane), and rays from the ground behind the quads towards the
/// sun.
fn rays(scene: &Scene, short: bool) -> Vec<Ray> {
    let mut rng = SplitMix64::new(if short { 11 } else { 7 });
    let mut rays = Vec::new();
    for i in 0..3000 {
        let (x, _) = QUADS[i % 2];
        let target = Vec3::new(x + rng.range(-1.1, 1.1), rng.range(0.15, 2.35), 0.0);
        let mut d = random_dir(&mut rng);
        let side = if (i / 2) % 2 == 0 { 1.0 } else { -1.0 };
        d.z = side * (d.z.abs() + 0.3);
        let d = d.normalize();
        let t_max = if short { 4.5 } else { f32::INFINITY };
        rays.push(Ray::new(target - d * 4.0, d, 0.0, t_max));
    }
    let sun = scene.sun.clone().unwrap().direction;
    for i in 0..1500 {
        let (x, _) = QUADS[i % 2];
        let target = Vec3::new(x + rng.range(-1.1, 1.1), rng.range(0.15, 2.35), 0.0);
        let mut origin = target - sun * (target.y / sun.y);
        origin.y = 0.0;
        rays.push(Ray::new(origin, sun, 1e-3, f32::INFINITY));
    }
    rays
}

/// The scene's BVH as the renderer builds it.
struct Bvh {
    blases: Vec<Blas>,
    tlas: Tlas,
}

fn bvh(scene: &Scene) -> Bvh {
    let blases = bvh::blases(scene, &BuildOptions::default()).unwrap();
    let instances = bvh::instances(scene);
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = Tlas::build(&instances, &all, &blases).unwrap();
    Bvh { blases, tlas }
}

/// GPU hits per (mode, order): closest and any hit, each as coherent and incoherent rays.
struct GpuHits {
    closest: [Vec<Hit>; 2],
    any: [Vec<Hit>; 2],
}

const ORDERS: [RayOrder; 2] = [RayOrder::Coherent, RayOrder::Incoherent];

/// Traces `rays` on the GPU against the scene's BVH with `alpha` (None: nothing uploaded).
fn gpu_trace(
    ctx: &GpuContext,
    scene: &Scene,
    bvh: &Bvh,
    alpha: Option<&BvhAlpha>,
    rays: &[Ray],
) -> hikari_render::Result<GpuHits> {
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    gpu_trace_with(ctx, BvhTrace::new(ctx, &mut lib)?, scene, bvh, alpha, rays)
}

fn gpu_trace_with(
    ctx: &GpuContext,
    mut trace: BvhTrace,
    scene: &Scene,
    bvh: &Bvh,
    alpha: Option<&BvhAlpha>,
    rays: &[Ray],
) -> hikari_render::Result<GpuHits> {
    trace.upload_blases(ctx, &bvh.blases)?;
    trace.upload_tlas(ctx, &bvh.tlas)?;
    let (textures, _) = TextureArrays::upload(ctx, scene)?;
    if let Some(alpha) = alpha {
        trace.upload_alpha(ctx, alpha, Some(&textures.color))?;
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
    let mut names = Vec::new();
    for mode in [TraceMode::Closest, TraceMode::Any] {
        for (k, order) in ORDERS.into_iter().enumerate() {
            let name = format!("test.{mode:?}.{k}");
            let hits = g.buffer(&name, n as u64 * HIT_BYTES)?;
            trace.record(&mut g, rays_buf, hits, n, mode, order)?;
            g.readback(hits);
            names.push(name);
        }
    }
    let r = g.execute()?;
    let get = |name: &str| -> Vec<Hit> {
        let bytes = &r.buffers.iter().find(|(b, _)| b == name).unwrap().1;
        bytemuck::pod_collect_to_vec(&bytes[..rays.len() * HIT_BYTES as usize])
    };
    Ok(GpuHits {
        closest: [get(&names[0]), get(&names[1])],
        any: [get(&names[2]), get(&names[3])],
    })
}

fn as_option(h: Hit) -> Option<Hit> {
    h.is_hit().then_some(h)
}

/// How one set of answers compares with a reference's.
#[derive(Debug, Default)]
struct Tally {
    agree: usize,
    /// Disagreements outside the tolerance band.
    differ: usize,
    /// Rays within the band, either way...
    ambiguous: usize,
    /// ...and those of them that disagree.
    band_differ: usize,
    /// Agreeing rays that went through a hole, and that hit each of ground, checker, ramp.
    through_holes: usize,
    seen: [usize; 3],
    first_difference: Option<String>,
}

impl Tally {
    fn add(&mut self, a: &Analytic, agrees: bool, what: impl FnOnce() -> String) {
        if a.ambiguous {
            self.ambiguous += 1;
            self.band_differ += !agrees as usize;
        } else if agrees {
            self.agree += 1;
            self.through_holes += a.through_hole as usize;
            if let Some(i) = a.hit {
                self.seen[i as usize] += 1;
            }
        } else {
            self.differ += 1;
            if self.first_difference.is_none() {
                self.first_difference = Some(what());
            }
        }
    }

    fn assert_matches(&self, what: &str) {
        let total = self.agree + self.differ + self.ambiguous;
        assert_eq!(self.differ, 0, "{what}: {self:?}");
        assert!(
            self.ambiguous * 100 <= total * 8,
            "{what}: too many rays in the band: {self:?}"
        );
    }
}

/// Compares GPU hits with the CPU twin (the filtered traversal with `filter`, or none: every
/// hit stands) and with the analytic coverage. Returns (vs CPU, vs analytic), closest and any
/// hit of both orders together.
fn compare(
    bvh: &Bvh,
    rays: &[Ray],
    gpu: &GpuHits,
    filter: Option<&SceneAlphaFilter>,
) -> (Tally, Tally) {
    let (mut vs_cpu, mut vs_analytic) = (Tally::default(), Tally::default());
    let accept = |i: u32, p: u32, u: f32, v: f32| filter.is_none_or(|f| f.accept(i, p, u, v));
    for (r, ray) in rays.iter().enumerate() {
        let a = analytic(ray);
        let cpu_closest = bvh.tlas.closest_hit_filtered(&bvh.blases, ray, accept);
        let cpu_any = bvh.tlas.any_hit_filtered(&bvh.blases, ray, accept);
        for k in 0..2 {
            let got = as_option(gpu.closest[k][r]);
            let same = same_hit(got, cpu_closest);
            vs_cpu.add(&a, same.is_ok(), || {
                format!("ray {r} {ray:?}, closest, order {k}: {same:?}")
            });
            vs_analytic.add(&a, got.map(|h| h.instance) == a.hit, || {
                format!("ray {r} {ray:?}, closest, order {k}: {got:?}, analytic {a:?}")
            });
            let occluded = gpu.any[k][r].is_hit();
            vs_cpu.add(&a, occluded == cpu_any, || {
                format!("ray {r} {ray:?}, any, order {k}: {occluded}, CPU {cpu_any}")
            });
            vs_analytic.add(&a, occluded == a.hit.is_some(), || {
                format!("ray {r} {ray:?}, any, order {k}: {occluded}, analytic {a:?}")
            });
        }
    }
    (vs_cpu, vs_analytic)
}

#[test]
fn cut_out_meshes_are_marked_non_opaque() {
    let scene = builtin::cutout();
    assert_eq!(bvh::cutout_meshes(&scene), [false, true, true]);
    let bvh = bvh(&scene);
    for (m, blas) in bvh.blases.iter().enumerate() {
        let opaque = blas.triangles.iter().all(|t| t.is_opaque());
        let non_opaque = blas.triangles.iter().all(|t| !t.is_opaque());
        assert!(if m == 0 { opaque } else { non_opaque }, "mesh {m}");
    }
    let alpha = BvhAlpha::for_scene(&scene);
    assert_eq!(alpha.instances.len(), 3);
    assert_eq!(alpha.instances[0].cutoff, 0.0);
    assert_eq!(alpha.instances[1].cutoff, 0.5);
    assert_eq!(alpha.instances[2].cutoff, CUTOUT_RAMP_CUTOFF);
    // The two quads' triangles, each once.
    assert_eq!(alpha.triangles.len(), 4);
}

#[test]
fn the_cpu_filter_matches_the_analytic_coverage() {
    // The twin held to the truth, with no GPU involved.
    let scene = builtin::cutout();
    let bvh = bvh(&scene);
    let filter = SceneAlphaFilter::new(&scene);
    let mut tally = Tally::default();
    for short in [false, true] {
        for ray in rays(&scene, short) {
            let a = analytic(&ray);
            let hit = bvh
                .tlas
                .closest_hit_filtered(&bvh.blases, &ray, |i, p, u, v| filter.accept(i, p, u, v));
            tally.add(&a, hit.map(|h| h.instance) == a.hit, || {
                format!("{ray:?}: {hit:?}, {a:?}")
            });
        }
    }
    tally.assert_matches("CPU filter vs analytic");
    assert!(tally.through_holes > 500, "{tally:?}");
}

#[test]
fn gpu_cut_outs_match_the_cpu_filter_and_the_analytic_coverage() {
    let ctx = common::gpu_context();
    let scene = builtin::cutout();
    let bvh = bvh(&scene);
    let alpha = BvhAlpha::for_scene(&scene);
    let filter = SceneAlphaFilter::new(&scene);
    for short in [false, true] {
        let rays = rays(&scene, short);
        let gpu = gpu_trace(&ctx, &scene, &bvh, Some(&alpha), &rays).unwrap();
        let (vs_cpu, vs_analytic) = compare(&bvh, &rays, &gpu, Some(&filter));
        eprintln!("short {short}: vs CPU {vs_cpu:?}\nvs analytic {vs_analytic:?}");
        vs_cpu.assert_matches("GPU vs CPU filter");
        // The twin reads the same texels with the same weights: inside the band too, only rays
        // within the filtering's fixed-point precision of the contour (1/512 texel with 8
        // sub-texel bits, 1/128 of the band) may go the other way.
        assert!(vs_cpu.band_differ * 20 <= vs_cpu.ambiguous, "{vs_cpu:?}");
        vs_analytic.assert_matches("GPU vs analytic");
        // The rays took every way: through holes, onto the ground, the checker and the ramp.
        assert!(vs_analytic.through_holes > 1000, "{vs_analytic:?}");
        assert!(vs_analytic.seen.iter().all(|&n| n > 500), "{vs_analytic:?}");
    }
}

#[test]
fn without_the_filter_the_comparisons_fail() {
    let ctx = common::gpu_context();
    let scene = builtin::cutout();
    let bvh = bvh(&scene);
    let rays = rays(&scene, false);
    // The CPU traversal without the filter against the GPU with it...
    let alpha = BvhAlpha::for_scene(&scene);
    let gpu = gpu_trace(&ctx, &scene, &bvh, Some(&alpha), &rays).unwrap();
    let (vs_cpu, _) = compare(&bvh, &rays, &gpu, None);
    assert!(vs_cpu.differ > 1000, "{vs_cpu:?}");
    // ...and the GPU with every instance opaque against the analytic coverage.
    let opaque = BvhAlpha::opaque(scene.instances.len());
    let gpu = gpu_trace(&ctx, &scene, &bvh, Some(&opaque), &rays).unwrap();
    let filter = SceneAlphaFilter::new(&scene);
    let (vs_cpu, vs_analytic) = compare(&bvh, &rays, &gpu, Some(&filter));
    assert!(vs_cpu.differ > 1000, "{vs_cpu:?}");
    assert!(vs_analytic.differ > 1000, "{vs_analytic:?}");
}

#[test]
fn a_bvh_with_cut_outs_needs_their_alpha_data() {
    let ctx = common::gpu_context();
    let scene = builtin::cutout();
    let bvh = bvh(&scene);
    let rays = rays(&scene, false);
    let e = gpu_trace(&ctx, &scene, &bvh, None, &rays)
        .err()
        .expect("marked triangles without alpha data")
        .to_string();
    assert!(e.contains("upload_alpha"), "{e}");
    // Too few instance records are refused too.
    let mut short = BvhAlpha::for_scene(&scene);
    short.instances.truncate(2);
    let e = gpu_trace(&ctx, &scene, &bvh, Some(&short), &rays)
        .err()
        .expect("alpha data for 2 of 3 instances")
        .to_string();
    assert!(e.contains("covers 2 instances"), "{e}");
}

/// Kernels built without the cut-out test (the ray benchmark's) refuse a TLAS with cut-outs
/// rather than trace them as opaque.
#[test]
fn kernels_without_the_cut_out_test_refuse_cut_outs() {
    let ctx = common::gpu_context();
    let scene = builtin::cutout();
    let bvh = bvh(&scene);
    let rays = rays(&scene, false);
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let trace = BvhTrace::with_configs(
        &ctx,
        &mut lib,
        hikari_render::scene::bvh_trace::TraceConfig::coherent(),
        hikari_render::scene::bvh_trace::TraceConfig::incoherent(),
    )
    .unwrap();
    let alpha = BvhAlpha::for_scene(&scene);
    let e = gpu_trace_with(&ctx, trace, &scene, &bvh, Some(&alpha), &rays)
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("TraceConfig::alpha"), "{e}");
}
