//! `hikari bake`: bakes a scene's irradiance probes on the CPU and writes the bake file (by
//! default into the cache `hikari render` reads), with a summary: probes per grid tile and
//! mesh, rays, time.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use crate::args::{JsonArgs, SceneArgs};
use crate::probe_bake;
use crate::scene_source::{self, DEFAULT_SCENE};

#[derive(Args, Debug)]
pub struct BakeArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Bake file to write [default: the cache, $XDG_CACHE_HOME/hikari/probes-KEY.hikprobe].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArgs,
}

pub fn run(a: BakeArgs) -> anyhow::Result<()> {
    let name = a
        .scene
        .scene
        .clone()
        .unwrap_or_else(|| DEFAULT_SCENE.into());
    let scene = scene_source::load_scene(&name)?;
    let key = probe_bake::scene_key(&scene, &probe_bake::options());
    let (bake, stats) = probe_bake::bake_scene(&scene, key)?;
    let path = a.output.unwrap_or_else(|| probe_bake::cache_path(&key));
    probe_bake::write(&path, &bake)?;
    let tiles: Vec<_> = bake
        .tiles
        .iter()
        .map(|t| json!({"tile": t.tile, "probes": t.probes.len()}))
        .collect();
    let meshes: Vec<_> = bake
        .meshes
        .iter()
        .map(|m| json!({"id": m.id, "probes": m.probes.len(), "tetrahedra": m.tets.len()}))
        .collect();
    let grid_probes: usize = bake.tiles.iter().map(|t| t.probes.len()).sum();
    let mesh_probes: usize = bake.meshes.iter().map(|m| m.probes.len()).sum();
    if a.json.json {
        let out = json!({
            "scene": name,
            "key": key.to_string(),
            "file": path.display().to_string(),
            "grid": {"tiles": tiles, "probes": grid_probes},
            "meshes": meshes,
            "mesh_probes": mesh_probes,
            "probes": bake.probe_count(),
            "lifted": stats.lifted,
            "dropped": stats.dropped,
            "rays_per_probe": stats.rays_per_probe,
            "sky_rays": stats.sky_rays,
            "placement_rays": stats.placement_rays,
            "sky_rays_per_second": stats.sky_rays_per_second(),
            "threads": stats.threads,
            "seconds": stats.total_seconds,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("scene {name} (key {key})");
        println!(
            "grid: {} tiles, {grid_probes} probes ({} lifted, {} dropped)",
            bake.tiles.len(),
            stats.lifted,
            stats.dropped
        );
        println!(
            "tetrahedral meshes: {}, {mesh_probes} probes",
            bake.meshes.len()
        );
        println!(
            "rays: {} a probe, {} sky + {} placement, {:.1} Mrays/s on {} threads",
            stats.rays_per_probe,
            stats.sky_rays,
            stats.placement_rays,
            stats.sky_rays_per_second() / 1e6,
            stats.threads
        );
        println!("time: {:.2} s", stats.total_seconds);
        println!("wrote {}", path.display());
    }
    Ok(())
}
