//! GPU ray tracing against hikari-bvh's compressed 8-wide BVH: closest hit and any hit, two
//! levels (TLAS over instances, then BLAS), in a compute kernel (`shaders/bvh/traverse.wgsl`,
//! importable as `hikari::bvh` by later passes: AO, GI, shadows).
//!
//! ```ignore
//! let mut trace = BvhTrace::new(&ctx, &mut lib)?;
//! trace.upload_blases(&ctx, &blases)?;      // once, and again after refits
//! trace.upload_tlas(&ctx, &tlas)?;          // every frame
//! trace.record(&mut g, rays, hits, count, TraceMode::Closest)?;
//! ```
//!
//! The kernel is the twin of `hikari_bvh::traverse` (tests/bvh_trace.rs checks it against it
//! and against brute force). Its stack lives in private memory and holds one entry per tree
//! level below the root, TLAS and BLAS together; scenes deeper than [`STACK_SIZE`] are refused
//! when recorded.

use bytemuck::{Pod, Zeroable};
use hikari_bvh::{Blas, InstanceRecord, PackedBlases, Tlas, TriangleRecord, WideNode};
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

/// Stack entries of the kernel (`BVH_STACK_SIZE` in `shaders/bvh/traverse.wgsl`).
pub const STACK_SIZE: u32 = 24;

/// Bytes per ray and per hit in the buffers [`BvhTrace::record`] binds.
pub const RAY_BYTES: u64 = std::mem::size_of::<hikari_bvh::Ray>() as u64;
pub const HIT_BYTES: u64 = std::mem::size_of::<hikari_bvh::Hit>() as u64;

/// Uniform of `bvh/trace.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TraceParams {
    pub count: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TraceMode {
    /// Nearest hit with `t_min < t < t_max`: t, primitive, instance, barycentrics.
    Closest,
    /// Stops at the first hit with `t_min < t < t_max` (shadow and AO rays). The hit written
    /// is that one, not necessarily the nearest.
    Any,
}

impl TraceMode {
    pub fn pass_name(self) -> &'static str {
        match self {
            TraceMode::Closest => "bvh_trace.closest",
            TraceMode::Any => "bvh_trace.any",
        }
    }
}

/// The four BVH buffers of a frame, in binding order (`@binding(0..4)` of `hikari::bvh`).
#[derive(Clone, Copy, Debug)]
pub struct BvhBuffers {
    pub blas_nodes: Buf,
    pub triangles: Buf,
    pub tlas_nodes: Buf,
    pub instances: Buf,
}

/// One GPU buffer that is rewritten in place while the contents fit.
struct Upload {
    buffer: wgpu::Buffer,
    /// Bytes in use (the buffer may be larger after a shrink).
    len: u64,
}

/// Pipelines plus the GPU copy of a BVH scene (all BLAS packed, and the TLAS).
pub struct BvhTrace {
    pub closest: ComputePipeline,
    pub any: ComputePipeline,
    blas_nodes: Option<Upload>,
    triangles: Option<Upload>,
    tlas_nodes: Option<Upload>,
    instances: Option<Upload>,
    /// Deepest BLAS, in nodes on a root-to-leaf path.
    blas_depth: u32,
    tlas_depth: u32,
}

impl BvhTrace {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            closest: ComputePipeline::new(ctx, lib, "bvh/trace.wgsl", "closest_hit", &[])?,
            any: ComputePipeline::new(ctx, lib, "bvh/trace.wgsl", "any_hit", &[])?,
            blas_nodes: None,
            triangles: None,
            tlas_nodes: None,
            instances: None,
            blas_depth: 0,
            tlas_depth: 0,
        })
    }

    /// Uploads every BLAS, concatenated as [`PackedBlases`] lays them out (the offsets a TLAS
    /// built over the same list stores in its instance records). Call again after refits.
    pub fn upload_blases(&mut self, ctx: &GpuContext, blases: &[Blas]) -> Result<()> {
        let packed = PackedBlases::new(blases);
        let depth = blases.iter().map(|b| b.stats.depth).max().unwrap_or(0);
        self.upload_packed(ctx, &packed, depth)
    }

    /// [`BvhTrace::upload_blases`] for an already packed list; `max_depth` is the largest
    /// `BlasStats::depth` among them.
    pub fn upload_packed(
        &mut self,
        ctx: &GpuContext,
        packed: &PackedBlases,
        max_depth: u32,
    ) -> Result<()> {
        // Zero-sized bindings are not allowed; a zeroed node has no children, so a BVH made
        // of it is empty and never reads the dummy triangle.
        let nodes: &[WideNode] = if packed.nodes.is_empty() {
            &[WideNode::zeroed()]
        } else {
            &packed.nodes
        };
        let tris: &[TriangleRecord] = if packed.triangles.is_empty() {
            &[TriangleRecord::zeroed()]
        } else {
            &packed.triangles
        };
        let nodes_bytes: &[u8] = bytemuck::cast_slice(nodes);
        let tris_bytes: &[u8] = bytemuck::cast_slice(tris);
        check_size(ctx, "bvh.blas_nodes", nodes_bytes.len() as u64)?;
        check_size(ctx, "bvh.triangles", tris_bytes.len() as u64)?;
        upload(ctx, &mut self.blas_nodes, "bvh.blas_nodes", nodes_bytes);
        upload(ctx, &mut self.triangles, "bvh.triangles", tris_bytes);
        self.blas_depth = max_depth;
        Ok(())
    }

    /// Uploads the TLAS (every frame: it is rebuilt from the instances that survive culling).
    /// Its instance records must point into the BLAS list given to [`BvhTrace::upload_blases`].
    pub fn upload_tlas(&mut self, ctx: &GpuContext, tlas: &Tlas) -> Result<()> {
        let nodes: &[WideNode] = if tlas.nodes.is_empty() {
            &[WideNode::zeroed()]
        } else {
            &tlas.nodes
        };
        let insts: &[InstanceRecord] = if tlas.instances.is_empty() {
            &[InstanceRecord::zeroed()]
        } else {
            &tlas.instances
        };
        let nodes_bytes: &[u8] = bytemuck::cast_slice(nodes);
        let inst_bytes: &[u8] = bytemuck::cast_slice(insts);
        check_size(ctx, "bvh.tlas_nodes", nodes_bytes.len() as u64)?;
        check_size(ctx, "bvh.instances", inst_bytes.len() as u64)?;
        upload(ctx, &mut self.tlas_nodes, "bvh.tlas_nodes", nodes_bytes);
        upload(ctx, &mut self.instances, "bvh.instances", inst_bytes);
        self.tlas_depth = if tlas.nodes.is_empty() {
            0
        } else {
            tlas.stats.depth
        };
        Ok(())
    }

    /// Bytes of the BVH on the GPU (in use, not counting slack from shrinking).
    pub fn gpu_bytes(&self) -> u64 {
        [
            &self.blas_nodes,
            &self.triangles,
            &self.tlas_nodes,
            &self.instances,
        ]
        .iter()
        .map(|u| u.as_ref().map_or(0, |u| u.len))
        .sum()
    }

    /// Stack entries the current scene needs: one per level below each root.
    pub fn stack_needed(&self) -> u32 {
        self.blas_depth.saturating_sub(1) + self.tlas_depth.saturating_sub(1)
    }

    /// Imports the BVH buffers into a frame, for passes that trace (bind them first, in the
    /// order of [`BvhBuffers`]).
    pub fn import(&self, g: &mut FrameGraph<'_>) -> Result<BvhBuffers> {
        let missing =
            |what: &str| RenderError::Graph(format!("bvh_trace: {what} not uploaded yet"));
        let (Some(bn), Some(tr)) = (&self.blas_nodes, &self.triangles) else {
            return Err(missing("BLAS (upload_blases)"));
        };
        let (Some(tn), Some(inst)) = (&self.tlas_nodes, &self.instances) else {
            return Err(missing("TLAS (upload_tlas)"));
        };
        let need = self.stack_needed();
        if need > STACK_SIZE {
            return Err(RenderError::Limit {
                what: "traversal stack entries the BVH depth needs".into(),
                requested: need as u64,
                limit: STACK_SIZE as u64,
            });
        }
        Ok(BvhBuffers {
            blas_nodes: g.import_buffer("bvh.blas_nodes", &bn.buffer),
            triangles: g.import_buffer("bvh.triangles", &tr.buffer),
            tlas_nodes: g.import_buffer("bvh.tlas_nodes", &tn.buffer),
            instances: g.import_buffer("bvh.instances", &inst.buffer),
        })
    }

    /// Workgroups for `count` rays: 2D once one dimension's limit is passed, with as few spare
    /// workgroups as the split allows.
    pub fn groups(&self, ctx: &GpuContext, count: u32) -> [u32; 3] {
        let size = self.closest.workgroup_size[0].max(1);
        let total = count.div_ceil(size).max(1);
        let max = ctx.limits.max_compute_workgroups_per_dimension.max(1);
        let y = total.div_ceil(max);
        [total.div_ceil(y), y, 1]
    }

    /// Adds the pass `bvh_trace.closest` or `bvh_trace.any`: reads `count` [`hikari_bvh::Ray`]s
    /// from `rays`, writes as many [`hikari_bvh::Hit`]s to `hits` (misses have
    /// `primitive == instance == u32::MAX` and `t = inf`).
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        rays: Buf,
        hits: Buf,
        count: u32,
        mode: TraceMode,
    ) -> Result<()> {
        let bvh = self.import(g)?;
        let pipeline = match mode {
            TraceMode::Closest => &self.closest,
            TraceMode::Any => &self.any,
        };
        let params = TraceParams {
            count,
            ..Default::default()
        };
        let groups = if count == 0 {
            [0, 1, 1]
        } else {
            self.groups(g.ctx(), count)
        };
        g.pass(mode.pass_name())
            .read(bvh.blas_nodes)
            .read(bvh.triangles)
            .read(bvh.tlas_nodes)
            .read(bvh.instances)
            .read(rays)
            .write(hits)
            .constants(&params)
            .dispatch(pipeline, groups)
    }
}

fn check_size(ctx: &GpuContext, name: &str, bytes: u64) -> Result<()> {
    let limit = ctx
        .limits
        .max_storage_buffer_binding_size
        .min(ctx.limits.max_buffer_size);
    if bytes > limit {
        return Err(RenderError::Limit {
            what: format!("size in bytes of `{name}`"),
            requested: bytes,
            limit,
        });
    }
    Ok(())
}

fn upload(ctx: &GpuContext, slot: &mut Option<Upload>, name: &str, bytes: &[u8]) {
    let len = bytes.len() as u64;
    if let Some(u) = slot
        && u.buffer.size() >= len
        && u.buffer.size() <= len.saturating_mul(2)
    {
        ctx.queue.write_buffer(&u.buffer, 0, bytes);
        u.len = len;
        return;
    }
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(name),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
    *slot = Some(Upload { buffer, len });
}
