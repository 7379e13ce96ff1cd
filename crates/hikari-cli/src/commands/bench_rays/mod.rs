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

mod animation;
mod measure;
mod quality;
mod rays;
mod report;
mod scene;
mod variants;

use std::time::Instant;

use anyhow::{Context, ensure};
use clap::Args;

use hikari_bvh::Tlas;
use hikari_render::graph::{GraphRuntime, TimestampMode};
use hikari_render::scene::bvh_trace::{BvhTrace, HIT_BYTES, RAY_BYTES, TraceConfig};
use hikari_render::shader;
use hikari_render::wgpu;
use hikari_render::wgpu::util::DeviceExt;
use hikari_render::{ContextOptions, GpuContext};

use crate::args::JsonArgs;

use measure::{Measured, measure, median_min, ray_bytes, workloads};
use quality::TlasQuality;
use report::Report;
use variants::parse_variant;

#[derive(Args, Debug)]
pub struct RaysArgs {
    // Not `args::SceneArgs`: here `terrain` means issue 5's height field, not the built-in
    // scene of that name, and the default differs.
    /// `terrain` (the benchmark's own: a 1M-triangle height field, not the built-in scene of
    /// that name), another built-in scene (village, boxes, cornell, cutout) or a .gltf/.glb
    /// file.
    #[arg(long, value_name = "NAME|PATH", default_value = "terrain")]
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
    #[command(flatten)]
    pub output: JsonArgs,
    /// Print this many of each workload's rays whose GPU and CPU hits differ (to stderr).
    #[arg(long, default_value_t = 0, hide = true)]
    pub show_mismatches: u32,
    /// Kernel variants to measure one after the other, comma-separated. Each starts with
    /// `auto` (the configuration of each ray order), `coh` or `inc` (the coherent or the
    /// incoherent configuration for every workload), followed by `+`-joined changes: `rpt<N>`
    /// (rays per invocation), `wg<N>` (workgroup size), `stride`, `dyn` or `refill<N>` (how
    /// the next ray is picked; refill: subgroup refill once N lanes are free), `tri<N>`
    /// (triangles per step, 0 = all), `checked` (wgpu's runtime checks on), `alpha` (the cut-out test
    /// compiled in).
    #[arg(long, default_value = "auto", hide = true)]
    pub variants: String,
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

    let scene = scene::load(&args.scene)?;
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
    let workloads = workloads(&scene.rays, args.rays as usize);
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

    let mut lib = shader::library(shader::capabilities_for(ctx.features))?;
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

    let adapter = ctx.describe();
    Report {
        adapter: &adapter,
        scene_name: &args.scene,
        scene: &scene,
        blas_ms: (blas_med, blas_min),
        tlas: &tlas,
        tlas_us: (tlas_med, tlas_min),
        quality: &quality,
        timestamps,
        iterations: args.iterations,
        upload_ms,
        gpu_bytes,
        variants: &variants,
        results: &results,
    }
    .print(args.output.json)
}
