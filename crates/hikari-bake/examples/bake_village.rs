//! Bakes the village's grid sky visibility on all cores and reports probes, rays and time,
//! then the error `rays_per_probe` leaves: a few probes traced again with 16 times the rays.
//!
//! `cargo run --release -p hikari-bake --example bake_village [RAYS_PER_PROBE]`

use std::io::Write;

use hikari_bake::sky_visibility::sky_visibility;
use hikari_bake::{GridBakeOptions, Placement, SceneRays, SphereRays, bake_grid_sky_visibility};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rays: u32 = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => hikari_bake::DEFAULT_RAYS_PER_PROBE,
    };
    let scene = hikari_scene::builtin::village();
    let (lo, hi) = scene.bounds().ok_or("the village has no geometry")?;
    println!(
        "village: {} triangles, bounds {lo:.1} .. {hi:.1}",
        scene.triangle_count()
    );
    let options = GridBakeOptions {
        rays_per_probe: rays,
        ..Default::default()
    };
    let bake = bake_grid_sky_visibility(&scene, &options, |done, total| {
        eprint!("\r{done}/{total} probes");
        let _ = std::io::stderr().flush();
    })?;
    eprintln!();
    let s = &bake.stats;
    println!(
        "tiles {}x{}, probes {} (lifted {}, dropped {}), threads {}",
        bake.tiles_x, bake.tiles_z, s.probes, s.lifted, s.dropped, s.threads
    );
    println!(
        "rays/probe {}, sky rays {}, placement rays {}",
        s.rays_per_probe, s.sky_rays, s.placement_rays
    );
    println!(
        "seconds: bvh {:.3}, placement {:.3}, sky {:.3}, total {:.3}; sky rays/s {:.3e}",
        s.bvh_seconds,
        s.placement_seconds,
        s.sky_seconds,
        s.total_seconds,
        s.sky_rays_per_second()
    );

    // Visible sky fraction (c0 / 2√π) per layer: the 1.5 m layer should see the least sky.
    let full = 2.0 * std::f32::consts::PI.sqrt();
    for layer in 0..hikari_bake::LAYERS {
        let per_tile = bake.options.probes_per_tile as usize;
        let per_tile = per_tile * per_tile;
        let fractions: Vec<f32> = bake
            .tiles
            .iter()
            .flat_map(|t| &t.probes[layer * per_tile..(layer + 1) * per_tile])
            .filter(|p| p.placement != Placement::Dropped)
            .map(|p| p.sky_visibility[0] / full)
            .collect();
        let mean = fractions.iter().sum::<f32>() / fractions.len().max(1) as f32;
        let min = fractions.iter().copied().fold(f32::INFINITY, f32::min);
        println!(
            "layer {} m: visible sky fraction mean {mean:.3}, min {min:.3}",
            bake.options.heights[layer]
        );
    }

    // Probes that see (almost) no sky yet passed the inside test: sealed rooms, or solids
    // whose faces point inwards.
    let sealed: Vec<_> = bake
        .tiles
        .iter()
        .flat_map(|t| &t.probes)
        .filter(|p| p.placement != Placement::Dropped && p.sky_visibility[0] < 0.01 * full)
        .collect();
    println!("kept probes seeing < 1 % of the sky: {}", sealed.len());
    for p in sealed.iter().take(5) {
        println!("  at {:.2} ({:?})", p.position, p.placement);
    }

    // Error left by `rays`: every 97th kept probe, against 16x the rays.
    let tracer = SceneRays::build(&scene)?;
    let reference = SphereRays::fibonacci(rays * 16);
    let mut stacks = hikari_bvh::TraversalStacks::default();
    let kept: Vec<_> = bake
        .tiles
        .iter()
        .flat_map(|t| &t.probes)
        .filter(|p| p.placement != Placement::Dropped)
        .collect();
    let mut max_abs = [0.0f32; 9];
    let mut sum_abs = [0.0f64; 9];
    let mut count = 0;
    for p in kept.iter().step_by(97) {
        let r = sky_visibility(&tracer, &reference, p.position, &mut stacks);
        for i in 0..9 {
            let e = (p.sky_visibility[i] - r[i]).abs();
            max_abs[i] = max_abs[i].max(e);
            sum_abs[i] += f64::from(e);
        }
        count += 1;
    }
    println!(
        "error vs {} rays over {count} probes (c0 of full sky = 2 sqrt(pi) = 3.545):",
        rays * 16
    );
    println!("  max |err| per coefficient: {max_abs:.4?}");
    println!(
        "  mean |err| per coefficient: {:.4?}",
        sum_abs.map(|v| (v / count.max(1) as f64) as f32)
    );
    Ok(())
}
