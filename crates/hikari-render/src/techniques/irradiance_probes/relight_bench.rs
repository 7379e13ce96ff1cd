//! The relight on its own, for `hikari bench probes`: the talk's steady-state work as separate
//! dispatches of `relight.wgsl`, each with its own GPU timestamps, on probes copied from a
//! real bake. The frame relights one list of chunks in one dispatch (`budget.rs`), and a
//! scene smaller than the talk's world (the village: 4 tiles, meshes of 20 to 1600 probes)
//! never holds the talk's 73 tiles or 5000-probe mesh; here they are laid out as many times
//! over as they need to be, so that the cost of the sizes the talk measured can be read.
//!
//! The relight reads nothing but a probe's own 9 coefficients, so what is timed is the work of
//! a frame that relit that many probes of that bake. Dispatches:
//!
//! * [`GRID_PASS`]: `grid_tiles` tiles of 768 probes (the talk: 8x8 round-robin tiles plus
//!   the 3x3 around the camera = 73), copied in turn from the bake's grid probes;
//! * [`MESH_PASS`]: one tetrahedral mesh of `mesh_probes` probes (the talk: about 5000),
//!   copied in turn from the bake's mesh probes;
//! * [`SCENE_MESH_PASS`]: the bake's largest tetrahedral mesh as it is (absent without one).

use glam::Vec3;

use super::budget::{self, CHUNK};
use super::gpu_data::ProbeGpuData;
use crate::context::GpuContext;
use crate::error::{RenderError, Result};

/// The grid dispatch's pass name.
pub const GRID_PASS: &str = "irradiance_probes.relight_grid";
/// The synthetic mesh's pass name.
pub const MESH_PASS: &str = "irradiance_probes.relight_mesh";
/// The bake's largest mesh's pass name.
pub const SCENE_MESH_PASS: &str = "irradiance_probes.relight_scene_mesh";

/// Probes of one grid tile.
const TILE_PROBES: u32 = hikari_probes::TILE_PROBE_COUNT as u32;
/// Workgroups of one dispatch at most (wgpu's default limit per dimension).
const MAX_CHUNKS: u64 = 65_535;

/// What to time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RelightBenchSpec {
    /// Grid tiles relit by the grid dispatch (the talk: 73).
    pub grid_tiles: u32,
    /// Probes of the synthetic tetrahedral mesh (the talk: about 5000).
    pub mesh_probes: u32,
}

impl Default for RelightBenchSpec {
    fn default() -> Self {
        Self {
            grid_tiles: 73,
            mesh_probes: 5000,
        }
    }
}

/// One timed dispatch.
pub struct RelightWorkload {
    /// Its pass name (`irradiance_probes.relight_*`).
    pub pass: &'static str,
    /// Probes it relights.
    pub probes: u32,
    /// Grid tiles among them (0 for a mesh).
    pub tiles: u32,
    /// Workgroups (chunks of up to 64 probes).
    pub chunk_count: u32,
    pub(super) chunks: wgpu::Buffer,
}

/// The buffers of the timed dispatches; record them with
/// [`super::IrradianceProbes::record_relight_bench`].
pub struct RelightBench {
    pub workloads: Vec<RelightWorkload>,
    /// 9 `vec4` per probe, laid out as `gpu_data.rs` describes, the workloads one after the
    /// other.
    pub(super) probe_data: wgpu::Buffer,
    /// The relit output, 9 `vec4` per probe.
    pub(super) irradiance: wgpu::Buffer,
    /// A position per probe (zeros: the bench casts no cloud shadow).
    pub(super) positions: wgpu::Buffer,
    /// The sky pass's layout: 9 raw radiance coefficients, then 9 deringed ones (the raw ones
    /// again here; the relight reads only the first 9).
    pub(super) sky_sh: wgpu::Buffer,
}

/// `count` probes copied in turn from `source` (probe indices into `data`) onto `out`.
fn copy_probes(out: &mut Vec<[f32; 4]>, data: &ProbeGpuData, source: &[u32], count: u32) {
    for k in 0..count as usize {
        let p = source[k % source.len()] as usize;
        out.extend_from_slice(&data.probe_data[9 * p..9 * p + 9]);
    }
}

impl RelightBench {
    /// The workloads of `spec` on the probes of `data`, relit from a sky of raw radiance SH
    /// `sky_radiance` (nits, hikari-math's order). An empty bake, or a spec of no probes or of
    /// more workgroups than one dispatch may have, is an error naming it.
    pub fn new(
        ctx: &GpuContext,
        data: &ProbeGpuData,
        spec: &RelightBenchSpec,
        sky_radiance: &[Vec3; 9],
    ) -> Result<Self> {
        let bad = |m: String| RenderError::Pass {
            pass: "irradiance_probes.relight (bench)".into(),
            message: m,
        };
        let total = data.probe_count() as u32;
        if total == 0 {
            return Err(bad("the bake holds no probes".into()));
        }
        for (what, probes) in [
            ("grid tiles", spec.grid_tiles as u64 * TILE_PROBES as u64),
            ("mesh probes", spec.mesh_probes as u64),
        ] {
            if probes == 0 || probes.div_ceil(CHUNK as u64) > MAX_CHUNKS {
                return Err(bad(format!(
                    "{what}: {probes} probes; 1 to {} a dispatch",
                    MAX_CHUNKS * CHUNK as u64
                )));
            }
        }
        // Grid probes come first in `data`, then the meshes'; a bake without one of them lends
        // the other's probes.
        let grid_end = data.tiles.len() as u32 * TILE_PROBES;
        let all: Vec<u32> = (0..total).collect();
        let grid_source = if grid_end > 0 {
            &all[..grid_end as usize]
        } else {
            &all[..]
        };
        let mesh_source = if grid_end < total {
            &all[grid_end as usize..]
        } else {
            &all[..]
        };
        let largest = data.meshes.iter().max_by_key(|m| m.probes);

        let mut probe_data = Vec::new();
        let mut plan = vec![
            (GRID_PASS, spec.grid_tiles * TILE_PROBES, spec.grid_tiles),
            (MESH_PASS, spec.mesh_probes, 0),
        ];
        copy_probes(&mut probe_data, data, grid_source, plan[0].1);
        copy_probes(&mut probe_data, data, mesh_source, plan[1].1);
        if let Some(m) = largest.filter(|m| m.probes > 0) {
            let own: Vec<u32> = (m.first_probe..m.first_probe + m.probes).collect();
            copy_probes(&mut probe_data, data, &own, m.probes);
            plan.push((SCENE_MESH_PASS, m.probes, 0));
        }

        let mut first = 0u32;
        let mut workloads = Vec::new();
        for (pass, probes, tiles) in plan {
            let mut chunks = Vec::new();
            budget::push_chunks(&mut chunks, first, probes);
            first += probes;
            workloads.push(RelightWorkload {
                pass,
                probes,
                tiles,
                chunk_count: chunks.len() as u32,
                chunks: ctx.storage_buffer(pass, bytemuck::cast_slice(&chunks))?,
            });
        }
        let mut sky = [[0.0f32; 4]; 18];
        for (k, c) in sky_radiance.iter().enumerate() {
            sky[k] = c.extend(0.0).to_array();
            sky[k + 9] = sky[k];
        }
        Ok(Self {
            workloads,
            positions: ctx.storage_buffer(
                "irradiance_probes.bench_positions",
                &vec![0u8; probe_data.len() / 9 * 16],
            )?,
            irradiance: ctx.storage_buffer(
                "irradiance_probes.bench_irradiance",
                &vec![0u8; probe_data.len() * 16],
            )?,
            probe_data: ctx.storage_buffer(
                "irradiance_probes.bench_probes",
                bytemuck::cast_slice(&probe_data),
            )?,
            sky_sh: ctx
                .storage_buffer("irradiance_probes.bench_sky_sh", bytemuck::cast_slice(&sky))?,
        })
    }
}
