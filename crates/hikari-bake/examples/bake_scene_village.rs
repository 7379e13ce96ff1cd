//! The full bake of the village (grid tiles and the tetrahedral meshes of its houses, temple
//! and courtyard; sky visibility and bounced sky visibility) on all cores, then the error the
//! ray counts leave: every 150th probe traced again with 8 times the probe rays and 8 times
//! the bounce rays per hit.
//!
//! `cargo run --release -p hikari-bake --example bake_scene_village [RAYS_PER_PROBE [BOUNCE_RAYS [--bake-only]]]`
//! (`--bake-only` skips the error measurement, so that `time` measures the bake alone).

use std::io::Write;
use std::time::Instant;

use hikari_bake::scene_rays::SceneRays;
use hikari_bake::sky_visibility::SphereRays;
use hikari_bake::surfaces::SurfaceAlbedo;
use hikari_bake::transport::probe_transport;
use hikari_bake::{SceneBakeOptions, bake_scene, volumes};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut options = SceneBakeOptions::default();
    if let Some(a) = args.next() {
        options.grid.rays_per_probe = a.parse()?;
    }
    if let Some(a) = args.next() {
        options.bounce_rays = a.parse()?;
    }
    let t0 = Instant::now();
    let village = hikari_scene::village::build(hikari_scene::village::DEFAULT_SEED);
    options.volumes = volumes::village_volumes(&village.layout);
    let scene = village.scene;
    println!(
        "village: {} triangles, {} probe volumes; built in {:.2} s",
        scene.triangle_count(),
        options.volumes.len(),
        t0.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    let rays_traced = std::cell::Cell::new(0u64);
    let bake = bake_scene(&scene, &options, &|p| {
        rays_traced.set(p.rays_traced);
        let eta = p
            .eta()
            .map_or("?".into(), |e| format!("{:.1} s", e.as_secs_f64()));
        eprint!(
            "\r{}/{} probes, section {}/{}, eta {eta}      ",
            p.probes_done, p.probes_total, p.sections_done, p.sections_total
        );
        let _ = std::io::stderr().flush();
    })?;
    let seconds = start.elapsed().as_secs_f64();
    eprintln!();
    let grid_probes: usize = bake.tiles.iter().map(|t| t.probes.len()).sum();
    let mesh_probes: usize = bake.meshes.iter().map(|m| m.probes.len()).sum();
    let tets: usize = bake.meshes.iter().map(|m| m.tets.len()).sum();
    let interior_grid = bake
        .tiles
        .iter()
        .flat_map(|t| &t.interior)
        .filter(|i| **i)
        .count();
    let interior_mesh = bake
        .meshes
        .iter()
        .flat_map(|m| &m.interior)
        .filter(|i| **i)
        .count();
    println!(
        "rays/probe {}, bounce rays/hit {}, threads {}",
        options.grid.rays_per_probe,
        options.bounce_rays,
        rayon::current_num_threads()
    );
    println!(
        "grid: {} tiles, {grid_probes} probes ({interior_grid} interior); meshes: {}, {mesh_probes} probes ({interior_mesh} interior), {tets} tetrahedra",
        bake.tiles.len(),
        bake.meshes.len()
    );
    for (m, v) in bake.meshes.iter().zip(&options.volumes) {
        let lattice = v.lattice(options.volume_jitter)?.len();
        println!(
            "  {:>14}: {:4} probes of {:4} ({} dropped), {:3} interior, {:5} tets",
            v.name,
            m.probes.len(),
            lattice,
            lattice - m.probes.len(),
            m.interior.iter().filter(|i| **i).count(),
            m.tets.len()
        );
    }
    // Exterior probes that see (almost) no sky: buried under terrain or sealed in a solid
    // the inside test let pass.
    let full = 2.0 * std::f32::consts::PI.sqrt();
    let sealed: Vec<[f32; 3]> = bake
        .meshes
        .iter()
        .flat_map(|m| m.positions.iter().zip(&m.probes).zip(&m.interior))
        .filter(|((_, p), i)| !**i && p.sky_visibility[0] < 0.01 * full)
        .map(|((x, _), _)| *x)
        .collect();
    println!(
        "exterior mesh probes seeing < 1 % of the sky: {} {:?}",
        sealed.len(),
        &sealed[..sealed.len().min(5)]
    );
    let probes = (grid_probes + mesh_probes).max(1) as u64;
    println!(
        "bake: {seconds:.2} s; {} rays traced, {} a probe on average (placement included), {:.3e} rays/s",
        rays_traced.get(),
        rays_traced.get() / probes,
        rays_traced.get() as f64 / seconds
    );
    if args.next().as_deref() == Some("--bake-only") {
        return Ok(());
    }

    // Error left by the ray counts.
    let rays = SceneRays::build(&scene)?;
    let albedo = SurfaceAlbedo::new(&scene);
    let reference_rays = SphereRays::fibonacci(options.grid.rays_per_probe * 8);
    let sphere = SphereRays::fibonacci(options.grid.rays_per_probe);
    let mut stacks = hikari_bvh::TraversalStacks::default();
    let positions: Vec<[f32; 3]> = bake
        .meshes
        .iter()
        .flat_map(|m| m.positions.iter().copied())
        .collect();
    let mut max_sky = [0.0f32; 9];
    let mut sum_sky = [0.0f64; 9];
    let mut max_bounce = [0.0f32; 9];
    let mut sum_bounce = [0.0f64; 9];
    let mut mean_bounce_c0 = 0.0f64;
    let mut count = 0;
    for (k, p) in positions.iter().enumerate().step_by(150) {
        let at = glam::Vec3::from_array(*p);
        let ours = probe_transport(
            &rays,
            &albedo,
            &sphere,
            options.bounce_rays,
            at,
            k as u64,
            12.0,
            &mut stacks,
        );
        let reference = probe_transport(
            &rays,
            &albedo,
            &reference_rays,
            options.bounce_rays * 8,
            at,
            k as u64 + 1_000_000,
            12.0,
            &mut stacks,
        );
        for i in 0..9 {
            let e = (ours.sky_visibility[i] - reference.sky_visibility[i]).abs();
            max_sky[i] = max_sky[i].max(e);
            sum_sky[i] += f64::from(e);
            for c in 0..3 {
                let e = (ours.bounced[i][c] - reference.bounced[i][c]).abs();
                max_bounce[i] = max_bounce[i].max(e);
                sum_bounce[i] += f64::from(e) / 3.0;
            }
        }
        mean_bounce_c0 += f64::from(reference.bounced[0].iter().sum::<f32>() / 3.0);
        count += 1;
    }
    let n = count.max(1) as f64;
    println!(
        "error vs {} probe rays and {} bounce rays/hit, over {count} mesh probes (c0 of the full sky = 3.545):",
        options.grid.rays_per_probe * 8,
        options.bounce_rays * 8
    );
    println!("  sky visibility max |err| per coefficient: {max_sky:.4?}");
    println!(
        "  sky visibility mean |err| per coefficient: {:.4?}",
        sum_sky.map(|v| (v / n) as f32)
    );
    println!("  bounce max |err| per coefficient (any channel): {max_bounce:.4?}");
    println!(
        "  bounce mean |err| per coefficient: {:.4?}; mean bounce c0 {:.4}",
        sum_bounce.map(|v| (v / n) as f32),
        mean_bounce_c0 / n
    );
    Ok(())
}
