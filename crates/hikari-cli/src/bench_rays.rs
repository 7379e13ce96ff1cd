//! `hikari bench rays`: BVH build and GPU ray throughput (issue 5).
//!
//! Rays are generated on the CPU from fixed seeds and uploaded once per workload; only the
//! trace passes are timed, with GPU timestamps around each pass. Every workload is also read
//! back once: the hit count shows a broken kernel at a glance, and a sample is traced again by
//! the CPU twin (hikari-bvh) and compared.
//!
//! `--scene terrain` is issue 5's benchmark: its 1M-triangle height field
//! (`hikari_bvh::Mesh::terrain`), rays from random points 1 cm above it. Any other name is a
//! scene as `hikari render` loads it (a built-in scene or a glTF file): one BLAS per mesh, one
//! instance per scene instance, incoherent rays from random points on its surfaces (area
//! weighted, 1 cm off the front face, cosine-distributed around the face normal) and coherent
//! rays through its first camera (or a camera framing its bounds).

use std::time::Instant;

use anyhow::{Context, bail, ensure};
use clap::Args;
use glam::{Affine3A, Vec3};
use serde_json::json;

use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{
    Blas, BuildOptions, Hit, Instance, Mesh, Ray, RefitScheduler, ThrottleSettings, Tlas,
};
use hikari_render::bvh_trace::{
    BvhTrace, HIT_BYTES, RAY_BYTES, RayOrder, Refill, TraceConfig, TraceMode,
};
use hikari_render::graph::{GraphRuntime, TimestampMode};
use hikari_render::shader::{self, ShaderLibrary};
use hikari_render::wgpu;
use hikari_render::wgpu::util::DeviceExt;
use hikari_render::{ContextOptions, GpuContext};

#[derive(Args, Debug)]
pub struct RaysArgs {
    /// `terrain` (issue 5's benchmark), another built-in scene (`village`, `boxes`, ...) or a
    /// .gltf/.glb file.
    #[arg(long, default_value = "terrain")]
    pub scene: String,
    /// Rays per workload. The coherent image keeps its 2:1 shape and gets about this many
    /// pixels (4096 x 2048 at the default).
    #[arg(long, default_value_t = 8_388_608)]
    pub rays: u32,
    /// Timed trace passes per workload (after two untimed ones); median and min are reported.
    #[arg(long, default_value_t = 10)]
    pub iterations: u32,
    /// Rays per workload re-traced on the CPU and compared with the GPU's hits (`--check`
    /// alone: 20000; `--check 0`: none).
    #[arg(long, default_value_t = 20_000, num_args = 0..=1, default_missing_value = "20000")]
    pub check: u32,
    #[arg(long)]
    pub json: bool,
    /// Print this many of each workload's rays whose GPU and CPU hits differ (to stderr).
    #[arg(long, default_value_t = 0, hide = true)]
    pub show_mismatches: u32,
    /// Kernel variants to measure one after the other, comma-separated. Each starts with
    /// `auto` (the configuration of each ray order), `coh` or `inc` (the coherent or the
    /// incoherent configuration for every workload), followed by `+`-joined changes: `rpt<N>`
    /// (rays per invocation), `wg<N>` (workgroup size), `stride`, `dyn` or `refill<N>` (how
    /// the next ray is picked; refill: subgroup refill once N lanes are free), `tri<N>`
    /// (triangles per step, 0 = all), `checked` (wgpu's runtime checks on).
    #[arg(long, default_value = "auto", hide = true)]
    pub variants: String,
}

/// Vertices per side of the issue-5 terrain (issue 3 defines it): 708 x 708 over
/// [-100, 100]^2, two triangles per cell.
const TERRAIN_SIDE: usize = 708;
const SEED: u64 = 0x5EED_0005;
const AO_T_MAX: f32 = 5.0;
/// Untimed trace passes run for at least this long (and at least two) before the timed ones.
const WARM_UP_S: f64 = 0.3;
/// Surface rays start this far off the surface.
const SURFACE_OFFSET: f32 = 0.01;

/// The geometry traced: BLAS list, instances, and how rays are generated for it.
struct BenchScene {
    description: String,
    blases: Vec<Blas>,
    instances: Vec<Instance>,
    /// Wall-clock milliseconds to build all BLAS, per repetition.
    blas_build_ms: Vec<f64>,
    rays: RaySource,
    /// The scene's deforming meshes played for a while with throttled refits.
    animation: Option<AnimationReport>,
}

/// Frames of a scene's vertex animation with Metro's refit throttling ([`RefitScheduler`]).
struct AnimationReport {
    deforming_meshes: usize,
    frames: usize,
    /// Per frame, CPU milliseconds to deform the chosen meshes and refit their BLAS.
    refit_ms_median: f64,
    refits_per_frame_max: usize,
    vertices_per_frame_max: usize,
    /// Most deforming meshes left outdated after a frame's batch.
    outdated_max: usize,
    /// After the last frame: rays traced through the refit BLAS and through BLAS rebuilt from
    /// the same deformed meshes, and how many hits differ.
    checked: usize,
    mismatches: usize,
}

/// Frames played at 60 Hz for the animation report.
const ANIMATION_FRAMES: usize = 120;

fn animate(
    scene: &hikari_scene::Scene,
    blases: &[Blas],
    instances: &[Instance],
) -> anyhow::Result<Option<AnimationReport>> {
    let deforming: Vec<usize> = (0..scene.meshes.len())
        .filter(|&m| scene.meshes[m].deformation.is_some())
        .collect();
    if deforming.is_empty() {
        return Ok(None);
    }
    let camera = scene
        .cameras
        .first()
        .map(|c| c.position)
        .unwrap_or(Vec3::ZERO);
    let mut blases = blases.to_vec();
    let mut scheduler = RefitScheduler::new(ThrottleSettings::default());
    let ids: Vec<usize> = deforming
        .iter()
        .map(|&m| scheduler.register(scene.meshes[m].positions.len()))
        .collect();
    let mut times = Vec::new();
    let (mut refits_max, mut vertices_max, mut outdated_max) = (0, 0, 0);
    for frame in 0..ANIMATION_FRAMES {
        let t = frame as f32 / 60.0;
        for (k, &m) in deforming.iter().enumerate() {
            // Priority from the nearest instance: size over distance, as the talk weighs it.
            let (lo, hi) = scene.meshes[m].bounds().unwrap_or_default();
            let radius = 0.5 * (hi - lo).length();
            let distance = scene
                .instances
                .iter()
                .filter(|i| i.mesh == m)
                .map(|i| {
                    i.transform
                        .transform_point3(0.5 * (lo + hi))
                        .distance(camera)
                })
                .fold(f32::INFINITY, f32::min);
            scheduler.touch(ids[k], true, radius, distance);
        }
        let batch = scheduler.select();
        let t0 = Instant::now();
        for &id in &batch.ids {
            let m = deforming[id];
            let (positions, _) = scene.meshes[m].deformed(t);
            blases[m]
                .refit(&positions)
                .with_context(|| format!("refitting mesh `{}`", scene.meshes[m].name))?;
        }
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        refits_max = refits_max.max(batch.ids.len());
        vertices_max = vertices_max.max(batch.vertices);
        outdated_max = outdated_max.max(batch.outdated);
    }
    // Every mesh refit at the last frame's time, compared with a rebuild at that time.
    let t_last = (ANIMATION_FRAMES - 1) as f32 / 60.0;
    let mut rebuilt = blases.clone();
    for &m in &deforming {
        let (positions, _) = scene.meshes[m].deformed(t_last);
        blases[m].refit(&positions)?;
        let mesh = Mesh::new(
            positions,
            scene.meshes[m]
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        );
        rebuilt[m] = Blas::from_mesh(&scene.meshes[m].name, &mesh, &BuildOptions::default())?;
    }
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let refit_tlas = Tlas::build(instances, &all, &blases)?;
    let rebuilt_tlas = Tlas::build(instances, &all, &rebuilt)?;
    // Rays aimed at the deforming instances, from the camera, so they test what moved.
    let mut rng = SplitMix64::new(SEED ^ 0xA11);
    let targets: Vec<Vec3> = scene
        .instances
        .iter()
        .filter(|i| deforming.contains(&i.mesh))
        .map(|i| {
            let (lo, hi) = scene.meshes[i.mesh].bounds().unwrap_or_default();
            i.transform.transform_point3(0.5 * (lo + hi))
        })
        .collect();
    let rays: Vec<Ray> = (0..4000)
        .map(|k| {
            let aim = targets[k % targets.len()]
                + (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 4.0;
            Ray::new(camera, (aim - camera).normalize(), 0.0, f32::INFINITY)
        })
        .collect();
    let a = refit_tlas.closest_hits(&blases, &rays, 0);
    let b = rebuilt_tlas.closest_hits(&rebuilt, &rays, 0);
    let mismatches = a
        .iter()
        .zip(&b)
        .zip(&rays)
        .filter(|((x, y), r)| !same_hit(x, y, r))
        .count();
    let (median, _) = median_min(&mut times);
    Ok(Some(AnimationReport {
        deforming_meshes: deforming.len(),
        frames: ANIMATION_FRAMES,
        refit_ms_median: median,
        refits_per_frame_max: refits_max,
        vertices_per_frame_max: vertices_max,
        outdated_max,
        checked: rays.len(),
        mismatches,
    }))
}

enum RaySource {
    /// Issue 5's terrain: points over the height field, the camera.
    Terrain(Mesh),
    /// Area-weighted points on world-space triangles; coherent rays through `camera`.
    Surfaces {
        triangles: Vec<[Vec3; 3]>,
        /// Cumulative areas, for picking a triangle by area.
        cdf: Vec<f64>,
        camera: hikari_scene::Camera,
    },
}

struct Workload {
    name: &'static str,
    mode: TraceMode,
    order: RayOrder,
    rays: Vec<Ray>,
    /// E.g. the coherent image size.
    note: String,
}

struct Measured {
    variant: String,
    /// The kernel configuration that traced it.
    kernel: TraceConfig,
    name: &'static str,
    mode: TraceMode,
    rays: usize,
    note: String,
    median_ms: f64,
    min_ms: f64,
    hits: usize,
    checked: usize,
    mismatches: usize,
}

impl Measured {
    fn grays(&self, ms: f64) -> f64 {
        self.rays as f64 / (ms * 1e-3) / 1e9
    }
}

/// A `--variants` entry: the configurations for coherent and for incoherent rays.
fn parse_variant(spec: &str) -> anyhow::Result<(TraceConfig, TraceConfig)> {
    let mut configs = (TraceConfig::coherent(), TraceConfig::incoherent());
    let mut parts = spec.split('+').peekable();
    match parts.peek().copied() {
        Some("auto") => {
            parts.next();
        }
        Some("coh") => {
            parts.next();
            configs.1 = configs.0;
        }
        Some("inc") => {
            parts.next();
            configs.0 = configs.1;
        }
        _ => bail!("variant `{spec}` must start with `auto`, `coh` or `inc`"),
    }
    for part in parts {
        let num = |prefix: &str| -> anyhow::Result<u32> {
            part[prefix.len()..]
                .parse()
                .with_context(|| format!("variant `{spec}`: `{part}` needs a number"))
        };
        let change: Box<dyn Fn(&mut TraceConfig)> = match part {
            "checked" => Box::new(|c| c.runtime_checks = true),
            "dyn" => Box::new(|c| c.refill = Refill::Dynamic),
            "stride" => Box::new(|c| c.refill = Refill::Stride),
            p if p.starts_with("refill") => {
                let min_free = num("refill")?;
                Box::new(move |c| c.refill = Refill::Subgroup { min_free })
            }
            p if p.starts_with("rpt") => {
                let n = num("rpt")?;
                Box::new(move |c| c.rays_per_thread = n)
            }
            p if p.starts_with("wg") => {
                let n = num("wg")?;
                Box::new(move |c| c.workgroup = n)
            }
            p if p.starts_with("tri") => {
                let n = num("tri")?;
                Box::new(move |c| c.triangles_per_step = n)
            }
            _ => bail!(
                "variant `{spec}`: unknown part `{part}` (checked, dyn, stride, refill<N>, \
                 rpt<N>, wg<N>, tri<N>)"
            ),
        };
        change(&mut configs.0);
        change(&mut configs.1);
    }
    Ok(configs)
}

pub fn run(args: RaysArgs) -> anyhow::Result<()> {
    ensure!(args.rays > 0, "--rays must be at least 1");
    ensure!(args.iterations > 0, "--iterations must be at least 1");
    let variants: Vec<(String, (TraceConfig, TraceConfig))> = args
        .variants
        .split(',')
        .map(|v| Ok((v.trim().to_string(), parse_variant(v.trim())?)))
        .collect::<anyhow::Result<_>>()?;
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    let limit = ctx
        .limits
        .max_storage_buffer_binding_size
        .min(ctx.limits.max_buffer_size);
    let buffer_bytes = args.rays as u64 * RAY_BYTES.max(HIT_BYTES);
    ensure!(
        buffer_bytes <= limit,
        "--rays {}: the ray and hit buffers would need {} bytes each, but this GPU binds at most {} bytes \
         per storage buffer; use --rays {} or fewer",
        args.rays,
        buffer_bytes,
        limit,
        limit / RAY_BYTES.max(HIT_BYTES)
    );
    let timestamps = ctx.has(wgpu::Features::TIMESTAMP_QUERY);

    let scene = load(&args.scene)?;
    let (blas_med, blas_min) = median_min(&mut scene.blas_build_ms.clone());
    let all: Vec<u32> = (0..scene.instances.len() as u32).collect();
    let mut tlas_us = Vec::new();
    let mut tlas = Tlas::default();
    for _ in 0..200 {
        let t0 = Instant::now();
        tlas = Tlas::build(&scene.instances, &all, &scene.blases)?;
        tlas_us.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    let (tlas_med, tlas_min) = median_min(&mut tlas_us);
    let quality = TlasQuality::measure(&scene, &tlas);

    // Workloads, uploaded once and shared by every variant.
    let n = args.rays as usize;
    let incoherent = scene.rays.incoherent(n);
    let ao: Vec<Ray> = incoherent
        .iter()
        .map(|r| Ray {
            t_max: AO_T_MAX,
            ..*r
        })
        .collect();
    let (w, h) = coherent_size(n);
    let coherent = scene.rays.coherent(w, h);
    let workloads = [
        Workload {
            name: "incoherent closest hit",
            mode: TraceMode::Closest,
            order: RayOrder::Incoherent,
            rays: incoherent,
            note: "surface points, cosine directions".into(),
        },
        Workload {
            name: "incoherent any hit (AO, t_max 5)",
            mode: TraceMode::Any,
            order: RayOrder::Incoherent,
            rays: ao,
            note: "same rays".into(),
        },
        Workload {
            name: "coherent closest hit",
            mode: TraceMode::Closest,
            order: RayOrder::Image { width: w },
            rays: coherent.clone(),
            note: format!("{w}x{h} pinhole, row-major, traced as an image (8x8 tiles)"),
        },
        Workload {
            name: "coherent closest hit, buffer order",
            mode: TraceMode::Closest,
            order: RayOrder::Coherent,
            rays: coherent,
            note: "same rays, traced in buffer order (32-pixel row strips per warp)".into(),
        },
    ];
    let ray_buffers: Vec<wgpu::Buffer> = workloads
        .iter()
        .map(|wl| {
            ctx.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("bench.rays"),
                    contents: &ray_bytes(&wl.rays),
                    usage: wgpu::BufferUsages::STORAGE,
                })
        })
        .collect();

    let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features))?;
    let mut rt = GraphRuntime::new();
    rt.set_timestamps(TimestampMode::Pass);
    let mut results = Vec::new();
    let mut upload_ms = 0.0;
    let mut gpu_bytes = 0;
    for (name, (coherent, incoherent)) in &variants {
        let mut trace = BvhTrace::with_configs(&ctx, &mut lib, *coherent, *incoherent)
            .with_context(|| format!("building kernel variant `{name}`"))?;
        let t0 = Instant::now();
        trace.upload_blases(&ctx, &scene.blases)?;
        trace.upload_tlas(&ctx, &tlas)?;
        ctx.wait_idle()?;
        upload_ms = t0.elapsed().as_secs_f64() * 1e3;
        gpu_bytes = trace.gpu_bytes();
        for (wl, buffer) in workloads.iter().zip(&ray_buffers) {
            let m = measure(
                &ctx,
                &mut rt,
                &trace,
                &scene.blases,
                &tlas,
                wl,
                buffer,
                &args,
                timestamps,
            )
            .with_context(|| format!("variant `{name}`, workload `{}`", wl.name))?;
            results.push(Measured {
                variant: name.clone(),
                kernel: trace.config(wl.order),
                ..m
            });
        }
    }

    let blas_triangles: usize = scene.blases.iter().map(|b| b.stats.triangles).sum();
    let blas_nodes: usize = scene.blases.iter().map(|b| b.stats.nodes).sum();
    let blas_depth = scene
        .blases
        .iter()
        .map(|b| b.stats.depth)
        .max()
        .unwrap_or(0);
    let blas_node_bytes: usize = scene
        .blases
        .iter()
        .map(|b| std::mem::size_of_val(b.nodes.as_slice()))
        .sum();
    let blas_tri_bytes: usize = scene
        .blases
        .iter()
        .map(|b| std::mem::size_of_val(b.triangles.as_slice()))
        .sum();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let timing = if timestamps {
        "GPU timestamps around each trace pass"
    } else {
        "wall clock (no timestamp queries)"
    };
    if args.json {
        let workloads: Vec<_> = results
            .iter()
            .map(|m| {
                json!({
                    "variant": m.variant,
                    "kernel": kernel_summary(&m.kernel),
                    "name": m.name,
                    "mode": format!("{:?}", m.mode),
                    "rays": m.rays,
                    "note": m.note,
                    "ms": { "median": m.median_ms, "min": m.min_ms },
                    "grays_per_s": { "median": m.grays(m.median_ms), "best": m.grays(m.min_ms) },
                    "hits": m.hits,
                    "checked_against_cpu": m.checked,
                    "mismatches": m.mismatches,
                })
            })
            .collect();
        let out = json!({
            "benchmark": "rays",
            "adapter": ctx.describe(),
            "scene": args.scene,
            "scene_description": scene.description,
            "timing": timing,
            "iterations": args.iterations,
            "blas": {
                "count": scene.blases.len(),
                "triangles": blas_triangles,
                "nodes": blas_nodes,
                "depth": blas_depth,
                "build_ms": { "median": blas_med, "min": blas_min },
                "build_threads": threads,
                "node_bytes": blas_node_bytes,
                "triangle_bytes": blas_tri_bytes,
            },
            "tlas": {
                "instances": tlas.stats.instances,
                "nodes": tlas.stats.nodes,
                "depth": tlas.stats.depth,
                "bytes": tlas.gpu_bytes(),
                "build_us": { "median": tlas_med, "min": tlas_min },
                "quality": quality.json(),
            },
            "animation": scene.animation.as_ref().map(|a| json!({
                "deforming_meshes": a.deforming_meshes,
                "frames": a.frames,
                "refit_ms_median": a.refit_ms_median,
                "refits_per_frame_max": a.refits_per_frame_max,
                "vertices_per_frame_max": a.vertices_per_frame_max,
                "outdated_max": a.outdated_max,
                "refit_vs_rebuild": { "checked": a.checked, "mismatches": a.mismatches },
            })),
            "gpu_bvh_bytes": gpu_bytes,
            "upload_ms": upload_ms,
            "workloads": workloads,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let mib = |b: usize| b as f64 / (1024.0 * 1024.0);
        println!("adapter: {}", ctx.describe());
        println!("scene {}: {}", args.scene, scene.description);
        println!(
            "BLAS build ({threads} threads): median {blas_med:.1} ms, min {blas_min:.1} ms over {} builds; \
             {} BLAS, {blas_triangles} triangles, {blas_nodes} nodes, depth {blas_depth}, \
             nodes {:.2} MiB + triangles {:.2} MiB",
            scene.blas_build_ms.len(),
            scene.blases.len(),
            mib(blas_node_bytes),
            mib(blas_tri_bytes)
        );
        println!(
            "TLAS build: median {tlas_med:.1} us, min {tlas_min:.1} us over 200 builds; {} instances, \
             {} nodes, depth {}, {} bytes",
            tlas.stats.instances,
            tlas.stats.nodes,
            tlas.stats.depth,
            tlas.gpu_bytes()
        );
        println!("{}", quality.line());
        if let Some(a) = &scene.animation {
            println!(
                "animation: {} deforming meshes, {} frames at 60 Hz with throttled refits (16 by \
                 priority + 4 random, vertex budget): refit {:.3} ms/frame (CPU, median), at most \
                 {} refits and {} vertices a frame, at most {} outdated after a frame; refit vs \
                 rebuild: {}/{} rays differ",
                a.deforming_meshes,
                a.frames,
                a.refit_ms_median,
                a.refits_per_frame_max,
                a.vertices_per_frame_max,
                a.outdated_max,
                a.mismatches,
                a.checked
            );
        }
        println!(
            "GPU BVH memory {:.2} MiB, upload {upload_ms:.1} ms; timing: {timing}, {} passes after 2 untimed",
            mib(gpu_bytes as usize),
            args.iterations
        );
        println!(
            "{:<22} {:<34} {:>9} {:>10} {:>9} {:>9} {:>9} {:>9} {:>13}  note",
            "variant",
            "workload",
            "rays",
            "hits",
            "med ms",
            "min ms",
            "Grays/s",
            "best",
            "CPU mismatch"
        );
        for (name, (coherent, incoherent)) in &variants {
            println!(
                "variant `{name}`: coherent rays: {}; incoherent rays: {}",
                kernel_summary(coherent),
                kernel_summary(incoherent)
            );
        }
        for m in &results {
            println!(
                "{:<22} {:<34} {:>9} {:>10} {:>9.3} {:>9.3} {:>9.4} {:>9.4} {:>13}  {}",
                m.variant,
                m.name,
                m.rays,
                m.hits,
                m.median_ms,
                m.min_ms,
                m.grays(m.median_ms),
                m.grays(m.min_ms),
                format!("{}/{}", m.mismatches, m.checked),
                m.note
            );
        }
    }
    Ok(())
}

/// A kernel configuration in a few words.
fn kernel_summary(c: &TraceConfig) -> String {
    let refill = match c.refill {
        Refill::Stride => "stride".to_string(),
        Refill::Dynamic => "dynamic".to_string(),
        Refill::Subgroup { min_free } => format!("subgroup refill at {min_free}"),
    };
    let tris = match c.triangles_per_step {
        0 => "all".to_string(),
        n => n.to_string(),
    };
    format!(
        "workgroup {}, {} rays/invocation ({refill}), {tris} triangles/step{}",
        c.workgroup,
        c.rays_per_thread,
        if c.runtime_checks { ", checked" } else { "" }
    )
}

/// Builds the BLAS list (three times, for the build time) and the ray source for `name`.
fn load(name: &str) -> anyhow::Result<BenchScene> {
    let options = BuildOptions::default();
    let mut blas_build_ms = Vec::new();
    if name == "terrain" {
        let mesh = Mesh::terrain(TERRAIN_SIDE);
        let mut blas = None;
        for _ in 0..3 {
            let t0 = Instant::now();
            let b =
                Blas::from_mesh("terrain", &mesh, &options).context("building the terrain BLAS")?;
            blas_build_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            blas = Some(b);
        }
        return Ok(BenchScene {
            description: format!(
                "issue 5 terrain, {TERRAIN_SIDE}x{TERRAIN_SIDE} vertices, {} triangles",
                mesh.indices.len()
            ),
            blases: blas.into_iter().collect(),
            instances: vec![Instance::new(Affine3A::IDENTITY, 0)],
            blas_build_ms,
            rays: RaySource::Terrain(mesh),
            animation: None,
        });
    }
    let scene = crate::render::load_scene(name)?;
    scene
        .validate()
        .with_context(|| format!("scene `{name}`"))?;
    let meshes = hikari_render::scene_bvh::meshes(&scene);
    let mut blases = Vec::new();
    for _ in 0..3 {
        let t0 = Instant::now();
        blases = meshes
            .iter()
            .zip(&scene.meshes)
            .map(|(m, sm)| {
                Blas::from_mesh(&sm.name, m, &options)
                    .with_context(|| format!("building the BLAS of mesh `{}`", sm.name))
            })
            .collect::<anyhow::Result<_>>()?;
        blas_build_ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    let instances = hikari_render::scene_bvh::instances(&scene);
    let mut triangles = Vec::new();
    let mut cdf = Vec::new();
    let mut area = 0.0f64;
    for inst in &scene.instances {
        let m = &scene.meshes[inst.mesh];
        for t in m.indices.chunks_exact(3) {
            let p = [t[0], t[1], t[2]]
                .map(|i| inst.transform.transform_point3(m.positions[i as usize]));
            let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length() as f64;
            if !(a > 0.0 && a.is_finite()) {
                continue;
            }
            area += a;
            triangles.push(p);
            cdf.push(area);
        }
    }
    ensure!(
        !triangles.is_empty(),
        "scene `{name}` has no triangle with an area to start rays from"
    );
    let animation = animate(&scene, &blases, &instances)?;
    let camera = match scene.cameras.first() {
        Some(c) => c.clone(),
        None => {
            let (lo, hi) = scene.bounds().context("the scene has no geometry")?;
            hikari_scene::Camera::framing("bench", lo, hi)
        }
    };
    Ok(BenchScene {
        description: format!(
            "{} meshes, {} instances, {} world triangles ({:.0} m^2), camera `{}`",
            scene.meshes.len(),
            scene.instances.len(),
            triangles.len(),
            area,
            camera.name
        ),
        blases,
        instances,
        blas_build_ms,
        animation,
        rays: RaySource::Surfaces {
            triangles,
            cdf,
            camera,
        },
    })
}

impl RaySource {
    /// Workloads 1 and 2.
    fn incoherent(&self, n: usize) -> Vec<Ray> {
        match self {
            RaySource::Terrain(mesh) => terrain_rays(mesh, n),
            RaySource::Surfaces { triangles, cdf, .. } => surface_rays(triangles, cdf, n),
        }
    }

    /// Workload 3: a `w` x `h` pinhole image.
    fn coherent(&self, w: u32, h: u32) -> Vec<Ray> {
        match self {
            // The camera at (0, 40, -120) looking along normalize(0, -0.5, 1); the
            // image plane at distance 1 spans 0.8 horizontally and 0.4 vertically on each side.
            RaySource::Terrain(_) => pinhole_rays(
                Vec3::new(0.0, 40.0, -120.0),
                Vec3::new(0.0, -0.5, 1.0),
                Vec3::Y,
                0.4,
                w,
                h,
            ),
            RaySource::Surfaces { camera, .. } => pinhole_rays(
                camera.position,
                camera.target - camera.position,
                camera.up,
                (0.5 * camera.vfov_deg.to_radians()).tan(),
                w,
                h,
            ),
        }
    }
}

/// Rays per workload traced on the CPU for the TLAS quality figures.
const QUALITY_RAYS: usize = 4096;

/// How good the TLAS is, independent of the GPU: its SAH cost, and the work closest-hit rays
/// do in it when traced on the CPU (the twin of the kernel, so the same visits).
struct TlasQuality {
    sah: hikari_bvh::SahCost,
    /// Incoherent and coherent rays: count, TLAS nodes visited and instances entered per ray.
    per_ray: [(&'static str, usize, f64, f64); 2],
}

impl TlasQuality {
    /// On the scene's own rays: the first [`QUALITY_RAYS`] incoherent ones, and a coherent
    /// image of about as many pixels (fixed, whatever `--rays` says).
    fn measure(scene: &BenchScene, tlas: &Tlas) -> Self {
        let (w, h) = coherent_size(QUALITY_RAYS);
        let work = |rays: &[Ray]| {
            let mut stacks = hikari_bvh::TraversalStacks::default();
            for ray in rays {
                hikari_bvh::traverse::closest_hit(
                    &tlas.nodes,
                    &tlas.instances,
                    &scene.blases,
                    ray,
                    &mut stacks,
                );
            }
            let n = rays.len().max(1) as f64;
            (
                rays.len(),
                stacks.tlas.nodes_visited as f64 / n,
                stacks.tlas.prims_tested as f64 / n,
            )
        };
        let inc = work(&scene.rays.incoherent(QUALITY_RAYS));
        let coh = work(&scene.rays.coherent(w, h));
        TlasQuality {
            sah: hikari_bvh::sah_cost(&tlas.nodes),
            per_ray: [
                ("incoherent", inc.0, inc.1, inc.2),
                ("coherent", coh.0, coh.1, coh.2),
            ],
        }
    }

    fn line(&self) -> String {
        let mut out = format!(
            "TLAS quality: SAH cost {:.3} (nodes {:.3} + instances {:.3}); closest hit on the CPU, per ray:",
            self.sah.total(),
            self.sah.nodes,
            self.sah.prims
        );
        for (name, rays, nodes, instances) in &self.per_ray {
            out += &format!(
                " {name} ({rays} rays) {nodes:.3} TLAS nodes, {instances:.3} instances entered;"
            );
        }
        out.pop();
        out
    }

    fn json(&self) -> serde_json::Value {
        let mut v = json!({
            "sah": { "nodes": self.sah.nodes, "instances": self.sah.prims, "total": self.sah.total() },
        });
        for (name, rays, nodes, instances) in &self.per_ray {
            v[*name] =
                json!({ "rays": rays, "nodes_per_ray": nodes, "instances_per_ray": instances });
        }
        v
    }
}

fn median_min(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0])
}

#[allow(clippy::too_many_arguments)]
fn measure(
    ctx: &GpuContext,
    rt: &mut GraphRuntime,
    trace: &BvhTrace,
    blases: &[Blas],
    tlas: &Tlas,
    wl: &Workload,
    ray_buffer: &wgpu::Buffer,
    args: &RaysArgs,
    timestamps: bool,
) -> anyhow::Result<Measured> {
    let n = wl.rays.len() as u32;
    let mut frame = |readback: bool| -> anyhow::Result<(Option<f64>, Option<Vec<u8>>)> {
        let t0 = Instant::now();
        let mut g = rt.begin_frame(ctx);
        let rays = g.import_buffer("bench.rays", ray_buffer);
        let (hits, _) = g.persistent_buffer("bench.hits", n as u64 * HIT_BYTES)?;
        trace.record(&mut g, rays, hits, n, wl.mode, wl.order)?;
        if readback {
            g.readback(hits);
        }
        let r = g.execute()?;
        ctx.wait_idle()?;
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        let gpu = r
            .timings
            .iter()
            .find(|t| t.name == wl.mode.pass_name())
            .and_then(|t| t.gpu_ms);
        let ms = if timestamps { gpu } else { Some(wall) };
        Ok((ms, r.buffers.into_iter().next().map(|(_, b)| b)))
    };
    // GPU clocks drop while the CPU builds kernels and checks hits: warm up for a while.
    let warm = Instant::now();
    for k in 0.. {
        if k >= 2 && warm.elapsed().as_secs_f64() > WARM_UP_S {
            break;
        }
        frame(false)?;
    }
    let mut times = Vec::new();
    for _ in 0..args.iterations {
        times.extend(frame(false)?.0);
    }
    ensure!(
        !times.is_empty(),
        "no GPU timings came back for `{}`",
        wl.mode.pass_name()
    );
    let (median_ms, min_ms) = median_min(&mut times);
    let (_, bytes) = frame(true)?;
    let bytes = bytes.context("the hit buffer was not read back")?;
    let hits = hits_from_bytes(&bytes[..n as usize * HIT_BYTES as usize]);
    let hit_count = hits.iter().filter(|h| h.is_hit()).count();

    // An even spread of rays over the whole buffer, traced again on the CPU.
    let sample = (args.check as usize).min(hits.len());
    let idx: Vec<usize> = (0..sample)
        .map(|k| k * hits.len() / sample.max(1))
        .collect();
    let sample_rays: Vec<Ray> = idx.iter().map(|&i| wl.rays[i]).collect();
    let mismatched: Vec<(usize, String)> = match wl.mode {
        TraceMode::Closest => {
            let cpu = tlas.closest_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, c)| !same_hit(&hits[i], c, &wl.rays[i]))
                .map(|(&i, c)| (i, format!("GPU {:?}, CPU {c:?}", hits[i])))
                .collect()
        }
        TraceMode::Any => {
            let cpu = tlas.any_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, &c)| hits[i].is_hit() != c)
                .map(|(&i, &c)| (i, format!("GPU {:?}, CPU occluded: {c}", hits[i])))
                .collect()
        }
    };
    for (i, e) in mismatched.iter().take(args.show_mismatches as usize) {
        eprintln!("{} ray {i} {:?}: {e}", wl.name, wl.rays[*i]);
    }
    let mismatches = mismatched.len();
    Ok(Measured {
        variant: String::new(),
        kernel: trace.config(wl.order),
        name: wl.name,
        mode: wl.mode,
        rays: wl.rays.len(),
        note: wl.note.clone(),
        median_ms,
        min_ms,
        hits: hit_count,
        checked: sample,
        mismatches,
    })
}

/// The GPU layout of hikari-bvh's `Ray` (32 bytes, little-endian).
fn ray_bytes(rays: &[Ray]) -> Vec<u8> {
    let mut out = Vec::with_capacity(rays.len() * RAY_BYTES as usize);
    for r in rays {
        for v in r
            .origin
            .iter()
            .chain([&r.t_min])
            .chain(&r.dir)
            .chain([&r.t_max])
        {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// hikari-bvh's `Hit` records (32 bytes, little-endian).
fn hits_from_bytes(bytes: &[u8]) -> Vec<Hit> {
    bytes
        .chunks_exact(HIT_BYTES as usize)
        .map(|c| {
            let w =
                |k: usize| u32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
            Hit {
                t: f32::from_bits(w(0)),
                u: f32::from_bits(w(1)),
                v: f32::from_bits(w(2)),
                primitive: w(3),
                instance: w(4),
                _pad: [0; 3],
            }
        })
        .collect()
}

/// Whether the GPU's closest hit matches the CPU twin's: the same primitive of the same
/// instance at the same t, or a tie (another one at the same t, e.g. coincident faces of two
/// instances). "The same t" is 1e-4 relative (1e-6 for a tie) plus 1e-6 of the ray origin's
/// largest coordinate: the GPU fuses multiply-adds where the CPU rounds twice, and in the
/// instance transform that alone moves t by a few ulps of the coordinates (4e-5 m at 200 m
/// from the origin, seen in the village). Barycentrics are not compared: far away, such a
/// rounding of the hit point is a visible fraction of a small triangle (tests/bvh_trace.rs
/// compares them on small scenes).
fn same_hit(g: &Hit, w: &Hit, ray: &Ray) -> bool {
    let coords = ray.origin.iter().fold(1.0f32, |m, c| m.max(c.abs()));
    let slack = 1e-6 * coords;
    match (g.is_hit(), w.is_hit()) {
        (false, false) => true,
        (true, true) => {
            let dt = (g.t - w.t).abs();
            if g.primitive == w.primitive && g.instance == w.instance {
                dt <= 1e-4 * w.t.abs() + slack
            } else {
                dt <= 1e-6 * w.t.abs() + slack
            }
        }
        _ => false,
    }
}

/// Height of the triangulated terrain (not the analytic formula, which the flat triangles
/// depart from by about a centimetre between vertices) at `x`, `z`.
fn mesh_height(mesh: &Mesh, x: f32, z: f32) -> f32 {
    let n = TERRAIN_SIDE;
    let cell = 200.0 / (n - 1) as f32;
    let fx = (x + 100.0) / cell;
    let fz = (z + 100.0) / cell;
    let i = (fx.floor() as usize).min(n - 2);
    let j = (fz.floor() as usize).min(n - 2);
    let (u, v) = (fx - i as f32, fz - j as f32);
    let y = |i: usize, j: usize| mesh.positions[j * n + i].y;
    // Mesh::terrain splits each cell into (a, c, b) and (b, c, d) with a = (i, j), b = (i+1, j),
    // c = (i, j+1), d = (i+1, j+1).
    if u + v <= 1.0 {
        y(i, j) + u * (y(i + 1, j) - y(i, j)) + v * (y(i, j + 1) - y(i, j))
    } else {
        y(i + 1, j + 1)
            + (1.0 - u) * (y(i, j + 1) - y(i + 1, j + 1))
            + (1.0 - v) * (y(i + 1, j) - y(i + 1, j + 1))
    }
}

/// A cosine-distributed direction around `n` (Malley's method) from two uniform numbers.
fn cosine_dir(n: Vec3, r1: f32, r2: f32) -> Vec3 {
    let r = r1.sqrt();
    let phi = std::f32::consts::TAU * r2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - r1).max(0.0).sqrt()).normalize()
}

/// Terrain workloads 1 and 2: uniformly random surface points with x, z in [-90, 90], 1 cm
/// above the surface, cosine-distributed directions around +y (Malley's method).
fn terrain_rays(mesh: &Mesh, n: usize) -> Vec<Ray> {
    let mut rng = SplitMix64::new(SEED);
    (0..n)
        .map(|_| {
            let x = rng.range(-90.0, 90.0);
            let z = rng.range(-90.0, 90.0);
            let y = mesh_height(mesh, x, z) + SURFACE_OFFSET;
            let r2 = rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = r2.sqrt();
            let d = Vec3::new(r * phi.cos(), (1.0 - r2).max(0.0).sqrt(), r * phi.sin()).normalize();
            Ray::new(Vec3::new(x, y, z), d, 0.0, f32::INFINITY)
        })
        .collect()
}

/// Scene workloads 1 and 2: points on world-space triangles picked by area, 1 cm off the front
/// face (counter-clockwise), cosine-distributed around its normal.
fn surface_rays(triangles: &[[Vec3; 3]], cdf: &[f64], n: usize) -> Vec<Ray> {
    let mut rng = SplitMix64::new(SEED);
    let total = *cdf.last().unwrap_or(&0.0);
    (0..n)
        .map(|_| {
            let pick = rng.next_f32() as f64 * total;
            let k = cdf.partition_point(|&c| c <= pick).min(triangles.len() - 1);
            let [a, b, c] = triangles[k];
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = a + u * (b - a) + v * (c - a);
            let nrm = (b - a).cross(c - a).normalize();
            let d = cosine_dir(nrm, rng.next_f32(), rng.next_f32());
            Ray::new(p + nrm * SURFACE_OFFSET, d, 0.0, f32::INFINITY)
        })
        .collect()
}

/// A 2:1 image of about `n` pixels: 4096 x 2048 for the 8,388,608.
fn coherent_size(n: usize) -> (u32, u32) {
    let h = ((n as f64 / 2.0).sqrt().floor() as u32).max(1);
    (2 * h, h)
}

/// Row-major rays of a `w` x `h` pinhole camera at `origin` looking along `forward`; the image
/// plane at distance 1 spans `half_height` above and below the axis and `half_height * w / h`
/// to each side.
fn pinhole_rays(
    origin: Vec3,
    forward: Vec3,
    up: Vec3,
    half_height: f32,
    w: u32,
    h: u32,
) -> Vec<Ray> {
    let forward = forward.normalize();
    let right = up.cross(forward).normalize();
    let up = forward.cross(right);
    let half_width = half_height * w as f32 / h as f32;
    let mut rays = Vec::with_capacity(w as usize * h as usize);
    for py in 0..h {
        let sy = (1.0 - 2.0 * (py as f32 + 0.5) / h as f32) * half_height;
        for px in 0..w {
            let sx = (2.0 * (px as f32 + 0.5) / w as f32 - 1.0) * half_width;
            let d = (forward + sx * right + sy * up).normalize();
            rays.push(Ray::new(origin, d, 0.0, f32::INFINITY));
        }
    }
    rays
}
