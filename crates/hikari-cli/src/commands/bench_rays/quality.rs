//! TLAS quality measured on the CPU, independent of the GPU kernel.

use serde_json::json;

use hikari_bvh::{Ray, Tlas};

use super::rays::coherent_size;
use super::scene::BenchScene;

/// Rays per workload traced on the CPU for the TLAS quality figures.
const QUALITY_RAYS: usize = 4096;

/// How good the TLAS is, independent of the GPU: its SAH cost, and the work closest-hit rays
/// do in it when traced on the CPU (the twin of the kernel, so the same visits).
pub(super) struct TlasQuality {
    pub sah: hikari_bvh::SahCost,
    /// Incoherent and coherent rays: count, TLAS nodes visited and instances entered per ray.
    pub per_ray: [(&'static str, usize, f64, f64); 2],
}

impl TlasQuality {
    /// On the scene's own rays: the first [`QUALITY_RAYS`] incoherent ones, and a coherent
    /// image of about as many pixels (fixed, whatever `--rays` says).
    pub(super) fn measure(scene: &BenchScene, tlas: &Tlas) -> Self {
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

    pub(super) fn line(&self) -> String {
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

    pub(super) fn json(&self) -> serde_json::Value {
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
