//! `hikari bake`: bakes a scene's irradiance probes (grid tiles and the scene's tetrahedral
//! meshes, sky and bounced sky visibility, interior flags; the rays on the GPU when there is a
//! real one, else on all CPU cores, `--tracer`) and writes the bake file
//! (by default into the cache `hikari render` reads), with a progress bar and the time left; an
//! interrupted bake (Ctrl-C) resumes from `<file>.partial`. The summary lists probes per grid
//! tile and mesh, rays and time.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use crate::args::{JsonArgs, SceneArgs};
use crate::probe_bake::{self, TracerChoice};
use crate::progress::{self, ProgressArgs};
use crate::scene_source::{DEFAULT_SCENE, SceneSource};
use hikari_bake::TransportTracer;
use hikari_render::{ContextOptions, GpuContext};

#[derive(Args, Debug)]
pub struct BakeArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Bake file to write [default: the cache, $XDG_CACHE_HOME/hikari/probes-KEY.hikprobe].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// What traces the rays: the GPU when the adapter is a real one (auto), or either forced.
    /// The results agree within rounding, so the cache does not depend on it.
    #[arg(long, value_enum, default_value_t = TracerChoice::Auto)]
    pub tracer: TracerChoice,
    #[command(flatten)]
    pub json: JsonArgs,
    #[command(flatten)]
    pub progress: ProgressArgs,
}

pub fn run(a: BakeArgs) -> anyhow::Result<()> {
    progress::set_quiet(a.progress.quiet);
    let name = a
        .scene
        .scene
        .clone()
        .unwrap_or_else(|| DEFAULT_SCENE.into());
    let source = SceneSource::parse(&name)?;
    let scene = source.load()?;
    let options = probe_bake::options(&scene, &source)?;
    let key = options.scene_key;
    let path = a.output.unwrap_or_else(|| probe_bake::cache_path(&key));
    // The GPU tracer's set-up (BVH build, upload, kernels) counts in the bake's time.
    let start = std::time::Instant::now();
    let ctx = match a.tracer {
        TracerChoice::Cpu => None,
        TracerChoice::Gpu => Some(GpuContext::new(&ContextOptions::from_env())?),
        TracerChoice::Auto => match GpuContext::new(&ContextOptions::from_env()) {
            Ok(c) => Some(c),
            Err(e) => {
                log::info!("probes: no GPU adapter ({e}); baking on the CPU");
                None
            }
        },
    };
    let gpu = probe_bake::gpu_tracer(a.tracer, ctx.as_ref(), &scene, &options)?;
    let adapter = gpu.as_ref().map(|g| g.adapter());
    let setup_seconds = start.elapsed().as_secs_f64();
    let run = probe_bake::bake_into(
        &scene,
        &options,
        &path,
        gpu.as_ref().map(|t| t as &dyn TransportTracer),
    )?;
    let bake = &run.bake;
    let count = |flags: &[bool]| flags.iter().filter(|&&f| f).count();
    let tiles: Vec<_> = bake
        .tiles
        .iter()
        .map(|t| json!({"tile": t.tile, "probes": t.probes.len(), "interior": count(&t.interior)}))
        .collect();
    let meshes: Vec<_> = bake
        .meshes
        .iter()
        .map(|m| {
            let name = options.volumes.get(m.id as usize).map(|v| v.name.clone());
            json!({
                "id": m.id,
                "name": name,
                "probes": m.probes.len(),
                "interior": count(&m.interior),
                "tetrahedra": m.tets.len(),
            })
        })
        .collect();
    let grid_probes: usize = bake.tiles.iter().map(|t| t.probes.len()).sum();
    let mesh_probes: usize = bake.meshes.iter().map(|m| m.probes.len()).sum();
    let g = &options.grid;
    if a.json.json {
        let out = json!({
            "scene": name,
            "key": key.to_string(),
            "file": path.display().to_string(),
            "grid": {"tiles": tiles, "probes": grid_probes},
            "meshes": meshes,
            "mesh_probes": mesh_probes,
            "probes": bake.probe_count(),
            "rays_per_probe": g.rays_per_probe,
            "bounce_rays_per_hit": options.bounce_rays,
            "rays": run.rays,
            "rays_per_second": run.rays as f64 / run.seconds.max(1e-9),
            "tracer": run.tracer,
            "adapter": adapter,
            "resumed_sections": run.resumed_sections,
            "threads": rayon_threads(),
            "seconds": setup_seconds + run.seconds,
            "tracer_setup_seconds": setup_seconds,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("scene {name} (key {key})");
        println!("grid: {} tiles, {grid_probes} probes", bake.tiles.len());
        println!(
            "tetrahedral meshes: {}, {mesh_probes} probes",
            bake.meshes.len()
        );
        println!(
            "rays: {} a probe, {} bounce rays a hit, {} traced in this run ({:.1} Mrays/s)",
            g.rays_per_probe,
            options.bounce_rays,
            run.rays,
            run.rays as f64 / run.seconds.max(1e-9) / 1e6
        );
        if run.resumed_sections > 0 {
            println!(
                "resumed {} tiles and meshes from the checkpoint",
                run.resumed_sections
            );
        }
        println!(
            "tracer: {}{}",
            run.tracer,
            adapter.map_or(String::new(), |a| format!(" ({a})"))
        );
        println!(
            "time: {:.2} s ({setup_seconds:.2} s preparing the tracer)",
            setup_seconds + run.seconds
        );
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Threads the baker's pool runs on (`RAYON_NUM_THREADS`, else the cores).
fn rayon_threads() -> usize {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
