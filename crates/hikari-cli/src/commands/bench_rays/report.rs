//! `bench rays` output: the build and trace figures as a table or as one JSON object.

use serde_json::json;

use hikari_bvh::Tlas;
use hikari_render::scene::bvh_trace::TraceConfig;

use super::measure::Measured;
use super::quality::TlasQuality;
use super::scene::BenchScene;
use super::variants::kernel_summary;

/// Everything `bench rays` measured.
#[derive(Clone, Copy)]
pub(super) struct Report<'a> {
    pub adapter: &'a str,
    /// `--scene` as given.
    pub scene_name: &'a str,
    pub scene: &'a BenchScene,
    /// Median and minimum wall-clock ms to build all BLAS.
    pub blas_ms: (f64, f64),
    pub tlas: &'a Tlas,
    /// Median and minimum wall-clock us to build the TLAS.
    pub tlas_us: (f64, f64),
    pub quality: &'a TlasQuality,
    /// Whether the trace times are GPU timestamps (else wall clock).
    pub timestamps: bool,
    pub iterations: u32,
    /// Wall-clock ms to upload the BVH (of the last variant).
    pub upload_ms: f64,
    pub gpu_bytes: u64,
    pub variants: &'a [(String, (TraceConfig, TraceConfig))],
    pub results: &'a [Measured],
}

impl Report<'_> {
    /// Prints the report: one JSON object if `json`, else lines and a table.
    pub fn print(&self, json: bool) -> anyhow::Result<()> {
        let Report {
            adapter,
            scene_name,
            scene,
            blas_ms: (blas_med, blas_min),
            tlas,
            tlas_us: (tlas_med, tlas_min),
            quality,
            timestamps,
            iterations,
            upload_ms,
            gpu_bytes,
            variants,
            results,
        } = *self;
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
        if json {
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
                "adapter": adapter,
                "scene": scene_name,
                "scene_description": scene.description,
                "timing": timing,
                "iterations": iterations,
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
            println!("adapter: {}", adapter);
            println!("scene {}: {}", scene_name, scene.description);
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
                iterations
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
            for (name, (coherent, incoherent)) in variants {
                println!(
                    "variant `{name}`: coherent rays: {}; incoherent rays: {}",
                    kernel_summary(coherent),
                    kernel_summary(incoherent)
                );
            }
            for m in results {
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
}
