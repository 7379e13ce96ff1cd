//! hikari's compute rasteriser, shared by the G-buffer (visibility: depth and triangle id a
//! pixel, in 64-bit atomics) and the sun's shadow maps (depth only, up to four views a
//! dispatch). It exists because rasterising in compute is several times faster than the
//! fixed-function path on the GPUs we measure on (BENCHMARKS.md: the H200 fills ~7 Gpixel/s).
//!
//! Pass 1 (`{technique}.rasterize`) runs a thread a triangle: small triangles are rasterised by
//! their thread; larger ones are set up once into a triangle record (edge equations, depth
//! plane, id, rectangle; a quad left by near clipping gives two) and split into 32x32 tiles
//! queued for pass 2 (`{technique}.rasterize_tiles`), where a workgroup covers a tile;
//! triangles spanning more than 256 tiles are listed whole, with their tile rectangle, for
//! pass 3 (`{technique}.rasterize_large`), which deals all their tiles to its workgroups in
//! turn; a workgroup reads the records only of the triangles it draws tiles of.
//! CPU twin: rays through the pixel centres with `hikari_bvh` (tests/raster.rs).

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph};
use crate::pipeline::ComputePipeline;
use crate::scene_gpu::SceneInFrame;
use crate::shader::ShaderLibrary;
use naga_oil::compose::ShaderDefValue;

pub const TILE_SIZE: u32 = 32;
/// Workgroups of the tile pass; each loops over the queue.
const TILE_WORKGROUPS: u32 = 4096;
pub const MAX_VIEWS: usize = 4;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct RasterParams {
    pub view_proj: [[[f32; 4]; 4]; MAX_VIEWS],
    pub viewport: [f32; 4],
    pub config: [u32; 4],
    /// Per view: which slice of the target (of `width * height` texels) it draws into.
    pub slices: [u32; 4],
    /// x: capacity of the triangle records.
    pub limits: [u32; 4],
}

/// Whether a target keeps the triangle id beside the depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterTarget {
    /// 8 bytes a pixel: depth bits << 32 | visibility id.
    Visibility,
    /// 4 bytes a texel: depth bits.
    Depth,
}

impl RasterTarget {
    pub fn bytes_per_texel(self) -> u64 {
        match self {
            RasterTarget::Visibility => 8,
            RasterTarget::Depth => 4,
        }
    }
}

/// One rasterisation: into which views, at which size.
pub struct RasterJob<'a> {
    /// Technique name; the passes are `{technique}.clear`, `.rasterize`, `.rasterize_tiles`.
    pub technique: &'a str,
    pub view_proj: &'a [Mat4],
    /// Per view, the slice of the target it draws into (and clears first).
    pub slices: &'a [u32],
    pub size: [u32; 2],
    pub cull_back_faces: bool,
}

/// Large triangles the queue holds after its tile entries (`LARGE_CAPACITY` in the shader).
const LARGE_CAPACITY: u64 = 65536;
/// `TriRecord` in the shader: a triangle's edge equations, depth plane, id, view and rectangle.
const TRIANGLE_RECORD_BYTES: u64 = 64;

pub struct Rasterizer {
    /// triangles, tiles, large
    visibility: [ComputePipeline; 3],
    depth: [ComputePipeline; 3],
}

impl Rasterizer {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let missing = crate::context::REQUIRED_FEATURES - ctx.features;
        if !missing.is_empty() {
            return Err(RenderError::Graph(format!(
                "the compute rasteriser needs GPU features this adapter lacks: {missing:?} \
                 (64-bit integer atomics; Vulkan's shaderBufferInt64Atomics)"
            )));
        }
        let depth_only = [("DEPTH_ONLY", ShaderDefValue::Bool(true))];
        Ok(Self {
            visibility: [
                ComputePipeline::new(ctx, lib, "raster/triangles.wgsl", "main", &[])?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "main", &[])?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "large", &[])?,
            ],
            depth: [
                ComputePipeline::new(ctx, lib, "raster/triangles.wgsl", "main", &depth_only)?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "main", &depth_only)?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "large", &depth_only)?,
            ],
        })
    }

    /// Clears the views' slices of `target` and rasterises every scene triangle into them.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        scene: &SceneInFrame,
        job: &RasterJob<'_>,
        kind: RasterTarget,
        target: Buf,
    ) -> Result<()> {
        let views = job.view_proj.len();
        assert!((1..=MAX_VIEWS).contains(&views), "1 to {MAX_VIEWS} views");
        let [w, h] = job.size;
        let tiles = (w.div_ceil(TILE_SIZE) * h.div_ceil(TILE_SIZE)) as u64 * views as u64;
        // Room for every tile covered eight times over by large triangles; beyond that, large
        // triangles lose tiles (the overflow shows as holes, and `queue_count` tells).
        let capacity = (tiles * 8).clamp(1 << 16, 1 << 22) as u32;
        let t = job.technique;
        // A large triangle takes two entries: its id and view, then its tile rectangle.
        let queue = g.buffer(
            &format!("{t}.tile_queue"),
            (capacity as u64 + 2 * LARGE_CAPACITY) * 8,
        )?;
        let count = g.buffer(&format!("{t}.tile_count"), 16)?;
        // Every record has at least one tile entry or one large entry (a large quad two).
        let binding_limit = g.ctx().limits.max_storage_buffer_binding_size;
        let record_capacity = (capacity as u64 + 2 * LARGE_CAPACITY)
            .min(binding_limit / TRIANGLE_RECORD_BYTES) as u32;
        let records = g.buffer(
            &format!("{t}.triangle_records"),
            record_capacity as u64 * TRIANGLE_RECORD_BYTES,
        )?;
        assert_eq!(job.slices.len(), views, "one slice a view");
        let slice_bytes = w as u64 * h as u64 * kind.bytes_per_texel();
        let slices: Vec<u32> = job.slices.to_vec();
        g.pass(&format!("{t}.clear"))
            .uses(target, true)
            .uses(count, true)
            .encode(move |enc, res| {
                for &s in &slices {
                    enc.clear_buffer(
                        res.buffer(target),
                        s as u64 * slice_bytes,
                        Some(slice_bytes),
                    );
                }
                enc.clear_buffer(res.buffer(count), 0, None);
            })?;
        let mut view_proj = [[[0.0; 4]; 4]; MAX_VIEWS];
        for (dst, m) in view_proj.iter_mut().zip(job.view_proj) {
            *dst = m.to_cols_array_2d();
        }
        let mut slice_of_view = [0u32; MAX_VIEWS];
        slice_of_view[..views].copy_from_slice(job.slices);
        let params = RasterParams {
            view_proj,
            viewport: [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32],
            config: [
                job.cull_back_faces as u32,
                capacity,
                views as u32,
                scene.chunk_count,
            ],
            slices: slice_of_view,
            limits: [record_capacity, 0, 0, 0],
        };
        let SceneInFrame {
            positions,
            indices,
            instances,
            chunks,
            ..
        } = *scene;
        let pipelines = match kind {
            RasterTarget::Visibility => &self.visibility,
            RasterTarget::Depth => &self.depth,
        };
        let max = g.ctx().limits.max_compute_workgroups_per_dimension;
        let n = scene.chunk_count.max(1);
        let groups = [n.min(max), n.div_ceil(max), views as u32];
        // The three passes bind the same resources; they differ in entry point and dispatch.
        // Large before tiles: the near walls and floors that take the large path then hide
        // what lies behind them from the tile pass's atomics (its plain load rejects them).
        let [triangles, tiles, large] = pipelines;
        let stages = [
            ("rasterize", groups, triangles),
            ("rasterize_large", [TILE_WORKGROUPS, 1, 1], large),
            ("rasterize_tiles", [TILE_WORKGROUPS, 1, 1], tiles),
        ];
        for (stage, dispatch, pipeline) in stages {
            let pass = g
                .pass(&format!("{t}.{stage}"))
                .constants(&params)
                .write(target)
                .write(queue)
                .write(count)
                .write(records);
            // Only the triangle pass reads the scene; the others read its records.
            let pass = if stage == "rasterize" {
                pass.read(positions)
                    .read(indices)
                    .read(instances)
                    .read(chunks)
            } else {
                pass
            };
            pass.dispatch(pipeline, dispatch)?;
        }
        Ok(())
    }
}
