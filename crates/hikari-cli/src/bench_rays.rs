//! `hikari bench rays`: BVH build and GPU ray throughput (issue 5).
//!
//! Rays are generated on the CPU from fixed seeds and uploaded once per workload; only the
//! trace passes are timed, with GPU timestamps around each pass. Every workload is also read
//! back once: the hit count shows a broken kernel at a glance, and a sample is traced again by
//! the CPU twin (hikari-bvh) and compared.

use std::time::Instant;

use anyhow::{Context, bail, ensure};
use clap::Args;
use glam::Vec3;
use serde_json::json;

use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Hit, Instance, Mesh, Ray, Tlas};
use hikari_render::graph::{GraphRuntime, TimestampMode};
use hikari_render::passes::bvh_trace::{BvhTrace, HIT_BYTES, RAY_BYTES, TraceMode};
use hikari_render::shader::{self, ShaderLibrary};
use hikari_render::wgpu;
use hikari_render::wgpu::util::DeviceExt;
use hikari_render::{ContextOptions, GpuContext};

#[derive(Args, Debug)]
pub struct RaysArgs {
    /// `terrain` (the three workloads) or `village`.
    #[arg(long, default_value = "terrain")]
    pub scene: String,
    /// Rays per workload. The coherent image keeps its 2:1 shape and field of view and gets
    /// about this many pixels (4096 x 2048 at the default).
    #[arg(long, default_value_t = 8_388_608)]
    pub rays: u32,
    /// Timed trace passes per workload (after two untimed ones); median and min are reported.
    #[arg(long, default_value_t = 10)]
    pub iterations: u32,
    /// Rays per workload re-traced on the CPU and compared with the GPU's hits.
    #[arg(long, default_value_t = 20_000)]
    pub check: u32,
    #[arg(long)]
    pub json: bool,
}

/// Vertices per side of the issue-5 terrain (issue 3 defines it): 708 x 708 over
/// [-100, 100]^2, two triangles per cell.
const TERRAIN_SIDE: usize = 708;
const SEED: u64 = 0x5EED_0005;
const AO_T_MAX: f32 = 5.0;

struct Workload {
    name: &'static str,
    mode: TraceMode,
    rays: Vec<Ray>,
    /// E.g. the coherent image size.
    note: String,
}

struct Measured {
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

pub fn run(args: RaysArgs) -> anyhow::Result<()> {
    match args.scene.as_str() {
        "terrain" => {}
        "village" => bail!(
            "--scene village is not available until the village scene exists (issue 3); use --scene terrain"
        ),
        other => bail!("unknown --scene {other:?}; expected `terrain` or `village`"),
    }
    ensure!(args.rays > 0, "--rays must be at least 1");
    ensure!(args.iterations > 0, "--iterations must be at least 1");
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    let limit = ctx
        .limits
        .max_storage_buffer_binding_size
        .min(ctx.limits.max_buffer_size);
    let ray_bytes = args.rays as u64 * RAY_BYTES.max(HIT_BYTES);
    ensure!(
        ray_bytes <= limit,
        "--rays {}: the ray and hit buffers would need {} bytes each, but this GPU binds at most {} bytes \
         per storage buffer; use --rays {} or fewer",
        args.rays,
        ray_bytes,
        limit,
        limit / RAY_BYTES.max(HIT_BYTES)
    );
    let timestamps = ctx.has(wgpu::Features::TIMESTAMP_QUERY);

    // Build.
    let mesh = Mesh::terrain(TERRAIN_SIDE);
    let options = BuildOptions::default();
    let mut build_ms = Vec::new();
    let mut blas = None;
    for _ in 0..3 {
        let t0 = Instant::now();
        let b = Blas::from_mesh("terrain", &mesh, &options).context("building the terrain BLAS")?;
        build_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        blas = Some(b);
    }
    let blas = blas.unwrap();
    let blases = vec![blas];
    let instances = vec![Instance::new(glam::Affine3A::IDENTITY, 0)];
    let mut tlas_us = Vec::new();
    let mut tlas = Tlas::default();
    for _ in 0..200 {
        let t0 = Instant::now();
        tlas = Tlas::build(&instances, &[0], &blases)?;
        tlas_us.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    let (build_med, build_min) = median_min(&mut build_ms);
    let (tlas_med, tlas_min) = median_min(&mut tlas_us);

    let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features))?;
    let mut trace = BvhTrace::new(&ctx, &mut lib)?;
    let t0 = Instant::now();
    trace.upload_blases(&ctx, &blases)?;
    trace.upload_tlas(&ctx, &tlas)?;
    ctx.wait_idle()?;
    let upload_ms = t0.elapsed().as_secs_f64() * 1e3;

    // Workloads.
    let n = args.rays as usize;
    let incoherent = incoherent_rays(&mesh, n);
    let ao: Vec<Ray> = incoherent
        .iter()
        .map(|r| Ray {
            t_max: AO_T_MAX,
            ..*r
        })
        .collect();
    let (w, h) = coherent_size(n);
    let workloads = vec![
        Workload {
            name: "incoherent closest hit",
            mode: TraceMode::Closest,
            rays: incoherent,
            note: "surface points, cosine directions".into(),
        },
        Workload {
            name: "incoherent any hit (AO, t_max 5)",
            mode: TraceMode::Any,
            rays: ao,
            note: "same rays".into(),
        },
        Workload {
            name: "coherent closest hit",
            mode: TraceMode::Closest,
            rays: coherent_rays(w, h),
            note: format!("{w}x{h} pinhole"),
        },
    ];

    let mut rt = GraphRuntime::new();
    rt.set_timestamps(TimestampMode::Pass);
    let mut results = Vec::new();
    for wl in &workloads {
        results.push(measure(
            &ctx, &mut rt, &trace, &blases, &tlas, wl, &args, timestamps,
        )?);
    }

    let s = &blases[0].stats;
    let blas_node_bytes = std::mem::size_of_val(blases[0].nodes.as_slice());
    let blas_tri_bytes = std::mem::size_of_val(blases[0].triangles.as_slice());
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
            "timing": timing,
            "iterations": args.iterations,
            "blas": {
                "triangles": s.triangles,
                "nodes": s.nodes,
                "depth": s.depth,
                "build_ms": { "median": build_med, "min": build_min },
                "build_threads": std::thread::available_parallelism().map_or(1, |n| n.get()),
                "node_bytes": blas_node_bytes,
                "triangle_bytes": blas_tri_bytes,
            },
            "tlas": {
                "instances": tlas.stats.instances,
                "nodes": tlas.stats.nodes,
                "bytes": tlas.gpu_bytes(),
                "build_us": { "median": tlas_med, "min": tlas_min },
            },
            "gpu_bvh_bytes": trace.gpu_bytes(),
            "upload_ms": upload_ms,
            "workloads": workloads,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let mib = |b: usize| b as f64 / (1024.0 * 1024.0);
        println!("adapter: {}", ctx.describe());
        println!(
            "scene terrain: {}x{} vertices, {} triangles",
            TERRAIN_SIDE, TERRAIN_SIDE, s.triangles
        );
        println!(
            "BLAS build ({} threads): median {:.1} ms, min {:.1} ms over {} builds; {} nodes, depth {}, \
             nodes {:.2} MiB + triangles {:.2} MiB",
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            build_med,
            build_min,
            build_ms.len(),
            s.nodes,
            s.depth,
            mib(blas_node_bytes),
            mib(blas_tri_bytes)
        );
        println!(
            "TLAS build: median {:.1} us, min {:.1} us; {} instances, {} nodes, {} bytes",
            tlas_med,
            tlas_min,
            tlas.stats.instances,
            tlas.stats.nodes,
            tlas.gpu_bytes()
        );
        println!(
            "GPU BVH memory {:.2} MiB, upload {:.1} ms; timing: {timing}, {} passes after 2 untimed",
            mib(trace.gpu_bytes() as usize),
            upload_ms,
            args.iterations
        );
        println!(
            "{:<34} {:>9} {:>10} {:>9} {:>9} {:>9} {:>9} {:>13}  note",
            "workload", "rays", "hits", "med ms", "min ms", "Grays/s", "best", "CPU mismatch"
        );
        for m in &results {
            println!(
                "{:<34} {:>9} {:>10} {:>9.3} {:>9.3} {:>9.4} {:>9.4} {:>13}  {}",
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
    args: &RaysArgs,
    timestamps: bool,
) -> anyhow::Result<Measured> {
    let n = wl.rays.len() as u32;
    let ray_buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bench.rays"),
            contents: &ray_bytes(&wl.rays),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let mut frame = |readback: bool| -> anyhow::Result<(Option<f64>, Option<Vec<u8>>)> {
        let t0 = Instant::now();
        let mut g = rt.begin_frame(ctx);
        let rays = g.import_buffer("bench.rays", &ray_buffer);
        let (hits, _) = g.persistent_buffer("bench.hits", n as u64 * HIT_BYTES)?;
        trace.record(&mut g, rays, hits, n, wl.mode)?;
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
    for _ in 0..2 {
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
    let mismatches = match wl.mode {
        TraceMode::Closest => {
            let cpu = tlas.closest_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, c)| !same_hit(&hits[i], c))
                .count()
        }
        TraceMode::Any => {
            let cpu = tlas.any_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, &c)| hits[i].is_hit() != c)
                .count()
        }
    };
    Ok(Measured {
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

/// The tests' rule: same primitive with t within 1e-4 relative, or a tie (another primitive at
/// the same t within 1e-6 relative).
fn same_hit(g: &Hit, w: &Hit) -> bool {
    match (g.is_hit(), w.is_hit()) {
        (false, false) => true,
        (true, true) => {
            let scale = w.t.abs().max(1e-6);
            if g.primitive == w.primitive && g.instance == w.instance {
                (g.t - w.t).abs() <= 1e-4 * scale
            } else {
                (g.t - w.t).abs() <= 1e-6 * scale
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

/// Workloads 1 and 2: uniformly random surface points with x, z in [-90, 90], 1 cm above the
/// surface, cosine-distributed directions around +y (Malley's method).
fn incoherent_rays(mesh: &Mesh, n: usize) -> Vec<Ray> {
    let mut rng = SplitMix64::new(SEED);
    (0..n)
        .map(|_| {
            let x = rng.range(-90.0, 90.0);
            let z = rng.range(-90.0, 90.0);
            let y = mesh_height(mesh, x, z) + 0.01;
            let r2 = rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = r2.sqrt();
            let d = Vec3::new(r * phi.cos(), (1.0 - r2).max(0.0).sqrt(), r * phi.sin()).normalize();
            Ray::new(Vec3::new(x, y, z), d, 0.0, f32::INFINITY)
        })
        .collect()
}

/// A 2:1 image of about `n` pixels: 4096 x 2048 for the 8,388,608.
fn coherent_size(n: usize) -> (u32, u32) {
    let h = ((n as f64 / 2.0).sqrt().floor() as u32).max(1);
    (2 * h, h)
}

/// Workload 3: pinhole camera at (0, 40, -120) looking along normalize(0, -0.5, 1); the image
/// plane at distance 1 spans 0.8 horizontally and 0.4 vertically on each side of the axis.
fn coherent_rays(w: u32, h: u32) -> Vec<Ray> {
    let origin = Vec3::new(0.0, 40.0, -120.0);
    let forward = Vec3::new(0.0, -0.5, 1.0).normalize();
    let right = Vec3::Y.cross(forward).normalize();
    let up = forward.cross(right);
    let mut rays = Vec::with_capacity(w as usize * h as usize);
    for py in 0..h {
        let sy = (1.0 - 2.0 * (py as f32 + 0.5) / h as f32) * 0.4;
        for px in 0..w {
            let sx = (2.0 * (px as f32 + 0.5) / w as f32 - 1.0) * 0.8;
            let d = (forward + sx * right + sy * up).normalize();
            rays.push(Ray::new(origin, d, 0.0, f32::INFINITY));
        }
    }
    rays
}
