//! The probe bake's transport traced on the GPU: hikari-bake's [`TransportTracer`] over
//! hikari's BVH kernels ([`BvhTrace`]), for `hikari bake` and the render's bake on first use
//! when the adapter is a real GPU.
//!
//! Per batch of probes, one frame of five passes:
//! 1. `probe_bake.probe_rays` (`probe_rays.wgsl`): `n` rays per probe along the CPU's
//!    Fibonacci directions (uploaded);
//! 2. `bvh_trace.closest`: their closest hits through the scene's BVH (the BLASes and TLAS
//!    hikari-bake's [`SceneRays`] built, so CPU placement and GPU transport see one BVH);
//! 3. `probe_bake.bounce_rays` (`bounce_rays.wgsl`): per hit, the surface's albedo from
//!    [`TransportTables`] (materials' colours, averaged textures and vertex colours, as the CPU
//!    reads them) and its `m` cosine-distributed secondary rays, rotated by the CPU's hash
//!    ([`hikari_bake::transport::bounce_shift`], computed on the CPU's cores and uploaded:
//!    WGSL has no 64-bit integers);
//! 4. `bvh_trace.any`: whether each secondary ray escapes;
//! 5. `probe_bake.accumulate` (`accumulate.wgsl`): one workgroup per probe sums the L2 SH of
//!    sky and bounced visibility with the CPU's per-ray weights, in f32, reduced in workgroup
//!    memory.
//!
//! The rays are the CPU's; what differs is rounding: f32 sums in another order, the GPU's
//! sin/cos in the secondary directions, and fused multiply-adds in hit points and normals,
//! which may flip a ray that grazes an edge. tests/render/probe_bake_gpu.rs bounds the difference.

use std::cell::RefCell;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_bake::scene_rays::SceneRays;
use hikari_bake::surfaces::SurfaceAlbedo;
use hikari_bake::transport::{
    ProbeTransport, SURFACE_OFFSET, SURFACE_OFFSET_PER_METRE, bounce_shifts,
};
use hikari_bake::transport_tables::TransportTables;
use hikari_bake::{BakeError, ProbeRequest, TransportSettings, TransportTracer};
use hikari_scene::Scene;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::GraphRuntime;
use crate::pipeline::ComputePipeline;
use crate::scene::bvh_trace::{BvhTrace, HIT_BYTES, RAY_BYTES, RayOrder, TraceConfig, TraceMode};
use crate::shader;

/// Floats the accumulate kernel writes per probe.
const OUT_STRIDE: usize = 40;
/// Invocations per workgroup of the bake's kernels.
const WORKGROUP: u32 = 64;

/// Uniform of the bake's kernels (`hikari::probe_bake::BakeParams`; field meanings there).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct BakeParams {
    pub(crate) probes: u32,
    pub(crate) rays_per_probe: u32,
    pub(crate) bounce_rays: u32,
    pub(crate) row_width: u32,
    pub(crate) enclosure_radius: f32,
    pub(crate) t_min: f32,
    pub(crate) surface_offset: f32,
    pub(crate) offset_per_metre: f32,
    pub(crate) far: f32,
    pub(crate) pad_a: u32,
    pub(crate) pad_b: u32,
    pub(crate) pad_c: u32,
}

/// Whether a bake should trace on the GPU: a real one (integrated, discrete or virtual), not a
/// CPU driver such as lavapipe, where the CPU tracer on all cores is faster.
pub fn is_real_gpu(ctx: &GpuContext) -> bool {
    ctx.info.device_type != wgpu::DeviceType::Cpu
}

/// The bake's transport on the GPU of `ctx`.
pub struct GpuTransport<'a> {
    ctx: &'a GpuContext,
    rays: SceneRays,
    settings: TransportSettings,
    trace: BvhTrace,
    probe_rays: ComputePipeline,
    bounce_rays: ComputePipeline,
    accumulate: ComputePipeline,
    directions: wgpu::Buffer,
    weights: wgpu::Buffer,
    instances: wgpu::Buffer,
    triangles: wgpu::Buffer,
    /// Stand-ins for the secondary rays and hits when there are none (no bounce rays).
    empty_rays: wgpu::Buffer,
    empty_hits: wgpu::Buffer,
    /// Probes per frame: what the storage-buffer limits and the dispatch limit allow.
    max_probes: usize,
    runtime: RefCell<GraphRuntime>,
}

fn tracer_error(message: String) -> BakeError {
    BakeError::Tracer {
        tracer: "gpu".into(),
        message,
    }
}

impl<'a> GpuTransport<'a> {
    /// Builds the scene's BVH (on the CPU, as the CPU bake does), uploads it with the albedo
    /// tables and the probe rays, and compiles the kernels.
    pub fn new(ctx: &'a GpuContext, scene: &Scene, settings: TransportSettings) -> Result<Self> {
        let bake_error = |e: BakeError| RenderError::Pass {
            pass: "probe_bake".into(),
            message: e.to_string(),
        };
        let rays = SceneRays::build(scene).map_err(bake_error)?;
        let albedo = SurfaceAlbedo::new(scene);
        let tables = TransportTables::new(&rays, &albedo);
        let mut lib = shader::library(shader::capabilities_for(ctx.features))?;
        let mut trace = BvhTrace::with_config(ctx, &mut lib, TraceConfig::incoherent())?;
        if !rays.tlas().instances.is_empty() {
            trace.upload_blases(ctx, rays.blases())?;
            trace.upload_tlas(ctx, rays.tlas())?;
        }
        let path = |name: &str| format!("probe_bake_gpu/{name}.wgsl");
        let probe_rays = ComputePipeline::new(ctx, &mut lib, &path("probe_rays"), "main", &[])?;
        let bounce_rays = ComputePipeline::new(ctx, &mut lib, &path("bounce_rays"), "main", &[])?;
        let accumulate = ComputePipeline::new(ctx, &mut lib, &path("accumulate"), "main", &[])?;
        let sphere = &settings.sphere;
        let directions: Vec<[f32; 4]> = sphere
            .directions
            .iter()
            .map(|d| [d.x, d.y, d.z, 0.0])
            .collect();
        let weights: Vec<[f32; 4]> = sphere
            .weights
            .iter()
            .flat_map(|w| {
                let w = w.map(|c| c as f32);
                [
                    [w[0], w[1], w[2], w[3]],
                    [w[4], w[5], w[6], w[7]],
                    [w[8], 0.0, 0.0, 0.0],
                ]
            })
            .collect();
        let n = sphere.len().max(1) as u64;
        let m = u64::from(settings.bounce_rays);
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        // Per probe, the largest buffer of the frame: its secondary rays or hits.
        let per_probe = (n * RAY_BYTES).max(n * m * RAY_BYTES.max(HIT_BYTES));
        let max_probes = (limit / per_probe)
            .min(u64::from(ctx.limits.max_compute_workgroups_per_dimension))
            .min(4096) as usize;
        if max_probes == 0 {
            return Err(RenderError::Limit {
                what: "bytes of one probe's rays in the GPU bake".into(),
                requested: per_probe,
                limit,
            });
        }
        Ok(Self {
            ctx,
            directions: ctx
                .storage_buffer("probe_bake.directions", bytemuck::cast_slice(&directions))?,
            weights: ctx.storage_buffer("probe_bake.weights", bytemuck::cast_slice(&weights))?,
            instances: ctx.storage_buffer(
                "probe_bake.instances",
                bytemuck::cast_slice(&tables.instances),
            )?,
            triangles: ctx.storage_buffer(
                "probe_bake.triangles",
                bytemuck::cast_slice(&tables.triangles),
            )?,
            empty_rays: ctx.storage_buffer("probe_bake.no_bounce_rays", &[])?,
            empty_hits: ctx.storage_buffer("probe_bake.no_bounce_hits", &[])?,
            rays,
            settings,
            trace,
            probe_rays,
            bounce_rays,
            accumulate,
            max_probes,
            runtime: RefCell::new(GraphRuntime::new()),
        })
    }

    /// The adapter it traces on, in words.
    pub fn adapter(&self) -> String {
        self.ctx.describe()
    }

    /// Workgroups covering `count` invocations in 64-wide groups, 2D past the dimension limit,
    /// and the invocations per row.
    fn groups(&self, count: u64) -> ([u32; 3], u32) {
        let total = count.div_ceil(u64::from(WORKGROUP)).max(1);
        let max = u64::from(self.ctx.limits.max_compute_workgroups_per_dimension.max(1));
        let y = total.div_ceil(max);
        let x = total.div_ceil(y);
        ([x as u32, y as u32, 1], x as u32 * WORKGROUP)
    }

    /// A scene without geometry: every ray escapes (the BVH kernels need a BVH).
    fn open_space(&self, probes: usize) -> Vec<ProbeTransport> {
        let mut sky = [0.0f64; 9];
        for w in &self.settings.sphere.weights {
            for (s, w) in sky.iter_mut().zip(w) {
                *s += w;
            }
        }
        let t = ProbeTransport {
            sky_visibility: sky.map(|c| c as f32),
            bounced: [[0.0; 3]; 9],
            enclosed_fraction: 0.0,
            rays: self.settings.sphere.len() as u64,
        };
        vec![t; probes]
    }

    fn trace_chunk(&self, probes: &[ProbeRequest]) -> Result<Vec<ProbeTransport>> {
        if self.rays.tlas().instances.is_empty() {
            return Ok(self.open_space(probes.len()));
        }
        let ctx = self.ctx;
        let n = self.settings.sphere.len() as u64;
        let m = u64::from(self.settings.bounce_rays);
        let p = probes.len() as u64;
        let count = p * n;
        let ray_count = u32::try_from(count).map_err(|_| RenderError::Limit {
            what: "probe rays in one GPU bake frame".into(),
            requested: count,
            limit: u64::from(u32::MAX),
        })?;
        let positions: Vec<[f32; 4]> = probes
            .iter()
            .map(|r| [r.position.x, r.position.y, r.position.z, 0.0])
            .collect();
        let shifts = if m > 0 {
            bounce_shifts(probes, n as usize)
        } else {
            Vec::new()
        };
        let positions =
            ctx.storage_buffer("probe_bake.positions", bytemuck::cast_slice(&positions))?;
        let shifts = ctx.storage_buffer("probe_bake.shifts", bytemuck::cast_slice(&shifts))?;
        let (groups, row_width) = self.groups(count);
        let params = BakeParams {
            probes: p as u32,
            rays_per_probe: n as u32,
            bounce_rays: m as u32,
            row_width,
            enclosure_radius: self.settings.enclosure_radius,
            t_min: hikari_bake::sky_visibility::RAY_T_MIN,
            surface_offset: SURFACE_OFFSET,
            offset_per_metre: SURFACE_OFFSET_PER_METRE,
            far: f32::INFINITY,
            ..Default::default()
        };
        let mut rt = self.runtime.borrow_mut();
        let mut g = rt.begin_frame(ctx);
        let positions = g.import_buffer("probe_bake.positions", &positions);
        let shifts = g.import_buffer("probe_bake.shifts", &shifts);
        let directions = g.import_buffer("probe_bake.directions", &self.directions);
        let weights = g.import_buffer("probe_bake.weights", &self.weights);
        let instances = g.import_buffer("probe_bake.instances", &self.instances);
        let triangles = g.import_buffer("probe_bake.triangles", &self.triangles);
        let rays = g.buffer("probe_bake.rays", count * RAY_BYTES)?;
        let hits = g.buffer("probe_bake.hits", count * HIT_BYTES)?;
        let surfaces = g.buffer("probe_bake.surfaces", count * 16)?;
        let sums = g.buffer("probe_bake.sums", p * OUT_STRIDE as u64 * 4)?;
        g.pass("probe_bake.probe_rays")
            .read(positions)
            .read(directions)
            .write(rays)
            .constants(&params)
            .dispatch(&self.probe_rays, groups)?;
        self.trace.record(
            &mut g,
            rays,
            hits,
            ray_count,
            TraceMode::Closest,
            RayOrder::Incoherent,
        )?;
        let (bounce, bounce_hits) = if m > 0 {
            (
                g.buffer("probe_bake.bounce_rays", count * m * RAY_BYTES)?,
                g.buffer("probe_bake.bounce_hits", count * m * HIT_BYTES)?,
            )
        } else {
            (
                g.import_buffer("probe_bake.no_bounce_rays", &self.empty_rays),
                g.import_buffer("probe_bake.no_bounce_hits", &self.empty_hits),
            )
        };
        g.pass("probe_bake.bounce_rays")
            .read(hits)
            .read(directions)
            .read(shifts)
            .read(instances)
            .read(triangles)
            .write(bounce)
            .write(surfaces)
            .constants(&params)
            .dispatch(&self.bounce_rays, groups)?;
        if m > 0 {
            let bounce_count = u32::try_from(count * m).map_err(|_| RenderError::Limit {
                what: "secondary rays in one GPU bake frame".into(),
                requested: count * m,
                limit: u64::from(u32::MAX),
            })?;
            self.trace.record(
                &mut g,
                bounce,
                bounce_hits,
                bounce_count,
                TraceMode::Any,
                RayOrder::Incoherent,
            )?;
        }
        g.pass("probe_bake.accumulate")
            .read(hits)
            .read(surfaces)
            .read(bounce_hits)
            .read(weights)
            .write(sums)
            .constants(&params)
            .dispatch(&self.accumulate, [p as u32, 1, 1])?;
        g.readback(sums);
        let result = g.execute()?;
        let bytes = result
            .buffers
            .iter()
            .find(|(name, _)| name == "probe_bake.sums")
            .map(|(_, b)| b.as_slice())
            .ok_or_else(|| RenderError::Graph("probe_bake: the sums were not read back".into()))?;
        let sums: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes[..p as usize * OUT_STRIDE * 4]);
        Ok(sums
            .chunks_exact(OUT_STRIDE)
            .map(|s| {
                let mut bounced = [[0.0f32; 3]; 9];
                for (c, b) in bounced.iter_mut().enumerate() {
                    *b = [s[9 + c * 3], s[10 + c * 3], s[11 + c * 3]];
                }
                ProbeTransport {
                    sky_visibility: std::array::from_fn(|c| s[c]),
                    bounced,
                    enclosed_fraction: s[36] / n as f32,
                    rays: n + s[37] as u64 * m,
                }
            })
            .collect())
    }
}

impl TransportTracer for GpuTransport<'_> {
    fn name(&self) -> &str {
        "gpu"
    }

    fn settings(&self) -> &TransportSettings {
        &self.settings
    }

    fn scene_rays(&self) -> Option<&SceneRays> {
        Some(&self.rays)
    }

    /// A whole grid tile (768 probes) a frame: fewer, fuller frames.
    fn batch_size(&self) -> usize {
        1024
    }

    fn trace(
        &self,
        probes: &[ProbeRequest],
    ) -> std::result::Result<Vec<ProbeTransport>, BakeError> {
        let mut out = Vec::with_capacity(probes.len());
        for chunk in probes.chunks(self.max_probes) {
            let t = self
                .trace_chunk(chunk)
                .map_err(|e| tracer_error(format!("{} ({})", e, self.ctx.describe())))?;
            out.extend(t);
        }
        // NaN or infinity from a driver never reaches the bake file.
        if let Some(i) = out.iter().position(|t| {
            !(t.sky_visibility.iter().all(|c| c.is_finite())
                && t.bounced.iter().flatten().all(|c| c.is_finite()))
        }) {
            let at = probes.get(i).map_or(Vec3::ZERO, |r| r.position);
            return Err(tracer_error(format!(
                "non-finite transport for the probe at {at} on {}",
                self.ctx.describe()
            )));
        }
        Ok(out)
    }
}
