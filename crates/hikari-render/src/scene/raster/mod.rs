//! hikari's compute rasteriser, shared by the G-buffer (visibility: depth and triangle id a
//! pixel, in 64-bit atomics) and the sun's shadow maps (depth only, up to eight views a
//! dispatch, each drawing a window of its slice: a whole cascade or a strip of a scrolled one). It exists because rasterising in compute is several times faster than the
//! fixed-function path on the GPUs we measure on (BENCHMARKS.md: the H200 fills ~7 Gpixel/s).
//!
//! Pass 1 (`{technique}.rasterize`) runs a thread a triangle: small triangles are rasterised by
//! their thread; larger ones are set up once into a triangle record (edge equations, depth
//! plane, id, rectangle; a quad left by near clipping gives two) and split into 32x32 tiles
//! queued for pass 2 (`{technique}.rasterize_tiles`), where a workgroup covers a tile;
//! triangles spanning more than 256 tiles are listed whole, with their tile rectangle, for
//! pass 3 (`{technique}.rasterize_large`), which deals all their tiles to its workgroups in
//! turn; a workgroup reads the records only of the triangles it draws tiles of.
//!
//! Alpha-tested triangles (glTF MASK cut-outs) never enter those three passes: their chunks
//! come last in the scene's chunk table ([`crate::scene::upload::SceneGpu::first_alpha_chunk`]),
//! the three passes stop before them, and two more passes draw them only when the scene has
//! some: `{technique}.rasterize_alpha` (pass 1 with the alpha test on each fragment; no large
//! list, every larger triangle is queued tile by tile after the opaque entries) and
//! `{technique}.rasterize_alpha_tiles` (pass 2 on those entries, with the alpha test). Both are
//! the same WGSL built with `ALPHA_TEST`, so opaque geometry runs exactly the code it ran before.
//! CPU twin: rays through the pixel centres with `hikari_bvh` (tests/render/raster.rs).

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, FrameResult, SamplerKind};
use crate::pipeline::ComputePipeline;
use crate::scene::upload::SceneInFrame;
use crate::shader::ShaderLibrary;
use naga_oil::compose::ShaderDefValue;

pub const TILE_SIZE: u32 = 32;
/// Workgroups of the tile and large passes when no earlier frame has told how many tile
/// entries and large triangles a technique queues. Each workgroup loops over its share.
const TILE_WORKGROUPS: u32 = 4096;
/// Otherwise the tile pass gets a workgroup for every this many entries of the previous frame,
/// within the bounds below: many short workgroups let the GPU's scheduler balance entries of
/// uneven cost (H200, 4K G-buffer: 32768 workgroups of about 4 entries 0.115-0.134 ms, 4096 of
/// 32 entries 0.129-0.152), and a shadow strip's few entries need few.
const ENTRIES_PER_TILE_WORKGROUP: u32 = 4;
const MIN_TILE_WORKGROUPS: u32 = 256;
const MAX_TILE_WORKGROUPS: u32 = 32768;
/// Workgroups of the large pass after a frame without large triangles: an idle dispatch of
/// 4096 cost 2.4 us more, and should a large triangle come, 256 still draw it in about 1.6
/// times the time of 4096 (the house interior's 48).
const IDLE_LARGE_WORKGROUPS: u32 = 256;
/// Views a dispatch draws at most: four shadow cascades, each scrolled in two strips.
pub const MAX_VIEWS: usize = 8;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct RasterParams {
    pub view_proj: [[[f32; 4]; 4]; MAX_VIEWS],
    pub viewport: [f32; 4],
    pub config: [u32; 4],
    /// Per view: slice of the target, origin, first pixel and end (exclusive) of the window,
    /// points packed as x | y << 16 (see [`RasterView`]).
    pub views: [[u32; 4]; MAX_VIEWS],
    /// x: capacity of the triangle records; y: the first chunk drawn (alpha-tested passes).
    pub limits: [u32; 4],
}

/// One view of a raster job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterView {
    pub view_proj: Mat4,
    /// The slice of the target (of `width * height` texels) it draws into.
    pub slice: u32,
    /// The pixels it draws (and clears first): x0, y0, x1, y1, the ends exclusive.
    pub window: [u32; 4],
    /// Where pixel (0, 0) is stored: pixel (x, y) lands at ((x + ox) mod width, (y + oy) mod
    /// height) of its slice, so that a shadow map can scroll with the camera and draw only
    /// what it uncovers. Depth targets of power-of-two sizes only.
    pub origin: [u32; 2],
}

impl RasterView {
    /// All of a `size` target, stored as drawn.
    pub fn full(view_proj: Mat4, slice: u32, [w, h]: [u32; 2]) -> Self {
        Self {
            view_proj,
            slice,
            window: [0, 0, w, h],
            origin: [0, 0],
        }
    }

    /// Whether it draws all of a `size` target.
    pub fn covers(&self, [w, h]: [u32; 2]) -> bool {
        self.window == [0, 0, w, h]
    }

    /// Slice, origin, window start and end, points packed as x | y << 16: how the
    /// rasteriser's and the shadow copy's shaders read a view.
    pub fn packed(&self) -> [u32; 4] {
        let [x0, y0, x1, y1] = self.window;
        [
            self.slice,
            pack_point(self.origin[0], self.origin[1]),
            pack_point(x0, y0),
            pack_point(x1, y1),
        ]
    }
}

pub(crate) fn pack_point(x: u32, y: u32) -> u32 {
    x | (y << 16)
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
    pub views: &'a [RasterView],
    pub size: [u32; 2],
    pub cull_back_faces: bool,
}

/// Large triangles the queue holds after its tile entries (`LARGE_CAPACITY` in the shader).
const LARGE_CAPACITY: u64 = 65536;

/// Room in one technique's queues: tile entries and triangle records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QueueSizes {
    pub entries: u32,
    pub records: u32,
}

/// The rasteriser's queue sizes, per technique, kept across frames. How many tile entries and
/// records a frame needs depends on the scene and the views, not only on the target size, so
/// every frame reads its counts back ([`RasterQueues::grow`]): a frame whose queues
/// overflowed lost triangles, and the renderer draws it again with larger queues.
#[derive(Clone, Debug, Default)]
pub struct RasterQueues {
    sizes: std::collections::HashMap<String, QueueSizes>,
    /// Tile entries of opaque triangles, large triangles and tile entries of alpha-tested
    /// triangles the last finished frame queued, per technique.
    last: std::collections::HashMap<String, [u32; 3]>,
}

impl RasterQueues {
    /// The sizes `technique` draws with; a first guess from its tile count until a frame
    /// has shown what it needs.
    pub fn sizes(&mut self, technique: &str, tiles: u64) -> QueueSizes {
        *self.sizes.entry(technique.into()).or_insert_with(|| {
            let entries = (tiles * 16).clamp(1 << 17, 1 << 22) as u32;
            QueueSizes {
                entries,
                records: entries / 2,
            }
        })
    }

    /// Workgroups of the tile and the large pass of `technique`, from the counts of the last
    /// finished frame. Any number draws every entry (the workgroups loop); these only balance
    /// the work.
    pub fn workgroups(&self, technique: &str) -> [u32; 2] {
        match self.last.get(technique) {
            None => [TILE_WORKGROUPS; 2],
            Some(&[entries, large, _]) => [
                entries
                    .div_ceil(ENTRIES_PER_TILE_WORKGROUP)
                    .clamp(MIN_TILE_WORKGROUPS, MAX_TILE_WORKGROUPS),
                if large == 0 {
                    IDLE_LARGE_WORKGROUPS
                } else {
                    TILE_WORKGROUPS
                },
            ],
        }
    }

    /// Workgroups of the alpha-tested tile pass of `technique`, as [`RasterQueues::workgroups`]
    /// for its entries.
    pub fn alpha_workgroups(&self, technique: &str) -> u32 {
        match self.last.get(technique) {
            None => TILE_WORKGROUPS,
            Some(&[_, _, alpha]) => alpha
                .div_ceil(ENTRIES_PER_TILE_WORKGROUP)
                .clamp(MIN_TILE_WORKGROUPS, MAX_TILE_WORKGROUPS),
        }
    }

    /// Sets the sizes `technique` draws with from now on (tests use tiny ones to force the
    /// overflow path).
    pub fn set(&mut self, technique: &str, sizes: QueueSizes) {
        self.sizes.insert(technique.into(), sizes);
    }

    /// Reads the counts of a finished frame (the `{technique}.tile_count` buffers) and grows
    /// the queues that overflowed to 1.5 times what was asked; returns the names of those
    /// techniques (empty when nothing was lost). Errors when a queue would not fit in one
    /// storage buffer binding of this device.
    pub fn grow(&mut self, result: &FrameResult, binding_limit: u64) -> Result<Vec<String>> {
        let mut overflowed = Vec::new();
        let Self { sizes: all, last } = self;
        for (name, sizes) in all {
            let Some(bytes) = result.buffer(&format!("{name}.tile_count")) else {
                continue;
            };
            let count = |i: usize| {
                bytes
                    .get(i * 4..i * 4 + 4)
                    .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            };
            // Every entry counts in [0]; the alpha-tested ones in [3] as well.
            let (entries, large, records, alpha) = (count(0), count(1), count(2), count(3));
            last.insert(
                name.clone(),
                [entries - alpha.min(entries), large, alpha.min(entries)],
            );
            if large as u64 > LARGE_CAPACITY {
                return Err(RenderError::Limit {
                    what: format!("{name}: triangles covering more than 256 tiles"),
                    requested: large as u64,
                    limit: LARGE_CAPACITY,
                });
            }
            if entries <= sizes.entries && records <= sizes.records {
                continue;
            }
            let more = |n: u32, have: u32| have.max((n as u64 * 3 / 2).min(u32::MAX as u64) as u32);
            let grown = QueueSizes {
                entries: more(entries, sizes.entries),
                records: more(records, sizes.records),
            };
            let queue_bytes = (grown.entries as u64 + 2 * LARGE_CAPACITY) * 8;
            let record_bytes = grown.records as u64 * TRIANGLE_RECORD_BYTES;
            for (what, bytes) in [
                ("tile queue", queue_bytes),
                ("triangle records", record_bytes),
            ] {
                if bytes > binding_limit {
                    return Err(RenderError::Limit {
                        what: format!("{name}: rasteriser {what} in bytes"),
                        requested: bytes,
                        limit: binding_limit,
                    });
                }
            }
            *sizes = grown;
            overflowed.push(name.clone());
        }
        overflowed.sort();
        Ok(overflowed)
    }
}
/// `TriRecord` in the shader: a triangle's edge equations, depth plane, id, view and rectangle.
const TRIANGLE_RECORD_BYTES: u64 = 64;

pub struct Rasterizer {
    /// triangles, tiles, large, window clear
    visibility: [ComputePipeline; 4],
    depth: [ComputePipeline; 4],
    /// The alpha-tested triangle and tile passes.
    visibility_alpha: [ComputePipeline; 2],
    depth_alpha: [ComputePipeline; 2],
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
        let alpha = [("ALPHA_TEST", ShaderDefValue::Bool(true))];
        let depth_alpha = [
            ("DEPTH_ONLY", ShaderDefValue::Bool(true)),
            ("ALPHA_TEST", ShaderDefValue::Bool(true)),
        ];
        // Without wgpu's runtime checks: 0.02-0.04 ms a frame at 4K (BENCHMARKS.md, session 6).
        let hot = |lib: &mut ShaderLibrary, path: &str, entry: &str, defs: &[_]| {
            // SAFETY: what the raster kernels index, they index in range: chunks below the
            // chunk count; vertices and positions through the scene's indices, which
            // `Scene::validate` checked before upload, in chunks `SceneGpu` built; views below
            // the view count (at most MAX_VIEWS, asserted in `record`) or as stored in the
            // records by the triangle pass; queue slots, large slots and records below the
            // capacities they are checked against before every write, and read below the
            // counts clamped to those capacities; target texels at pixels of a rectangle
            // clamped to the view's window (DEPTH_ONLY wraps them into the power-of-two map),
            // in slices that `record` asserts lie in the target; the clip polygon's four
            // corners at most; workgroup masks below 3 and 8. Every loop runs to a bound:
            // pixel and tile rectangles are clamped, as integers, to the window (`poly_rect`,
            // whatever the view matrices hold), counts to capacities. Divisors are non-zero
            // constants, workgroup counts, or spans of non-empty tile rectangles. Workgroup
            // memory is written, then a barrier, before it is read.
            unsafe { ComputePipeline::new_unchecked(ctx, lib, path, entry, defs) }
        };
        Ok(Self {
            visibility: [
                hot(lib, "raster/triangles.wgsl", "main", &[])?,
                hot(lib, "raster/tiles.wgsl", "main", &[])?,
                hot(lib, "raster/tiles.wgsl", "large", &[])?,
                ComputePipeline::new(ctx, lib, "raster/clear.wgsl", "main", &[])?,
            ],
            depth: [
                hot(lib, "raster/triangles.wgsl", "main", &depth_only)?,
                hot(lib, "raster/tiles.wgsl", "main", &depth_only)?,
                hot(lib, "raster/tiles.wgsl", "large", &depth_only)?,
                ComputePipeline::new(ctx, lib, "raster/clear.wgsl", "main", &depth_only)?,
            ],
            // With wgpu's runtime checks: they also sample textures and index the attributes,
            // the materials and the alpha entries, and are not the hot path.
            visibility_alpha: [
                ComputePipeline::new(ctx, lib, "raster/triangles.wgsl", "main", &alpha)?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "main", &alpha)?,
            ],
            depth_alpha: [
                ComputePipeline::new(ctx, lib, "raster/triangles.wgsl", "main", &depth_alpha)?,
                ComputePipeline::new(ctx, lib, "raster/tiles.wgsl", "main", &depth_alpha)?,
            ],
        })
    }

    /// Clears the views' windows of `target` and rasterises every scene triangle into them.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        scene: &SceneInFrame,
        job: &RasterJob<'_>,
        kind: RasterTarget,
        target: Buf,
        queues: &mut RasterQueues,
    ) -> Result<()> {
        let views = job.views.len();
        assert!((1..=MAX_VIEWS).contains(&views), "1 to {MAX_VIEWS} views");
        let [w, h] = job.size;
        for v in job.views {
            let [x0, y0, x1, y1] = v.window;
            assert!(
                x0 < x1 && x1 <= w && y0 < y1 && y1 <= h,
                "window {:?} in {w}x{h}",
                v.window
            );
            assert!(
                v.origin == [0, 0]
                    || (kind == RasterTarget::Depth && w.is_power_of_two() && h.is_power_of_two()),
                "stored with an origin: depth targets of power-of-two sizes only"
            );
        }
        let tiles = (w.div_ceil(TILE_SIZE) * h.div_ceil(TILE_SIZE)) as u64 * views as u64;
        let t = job.technique;
        // Past its capacity a queue drops triangles (holes), and its count keeps growing: the
        // count is read back so that the renderer can grow the queue and draw again.
        let QueueSizes {
            entries: capacity,
            records: record_capacity,
        } = queues.sizes(t, tiles);
        // A large triangle takes two entries: its id and view, then its tile rectangle.
        let queue = g.buffer(
            &format!("{t}.tile_queue"),
            (capacity as u64 + 2 * LARGE_CAPACITY) * 8,
        )?;
        let count = g.buffer(&format!("{t}.tile_count"), 16)?;
        g.readback_late(count);
        let records = g.buffer(
            &format!("{t}.triangle_records"),
            record_capacity as u64 * TRIANGLE_RECORD_BYTES,
        )?;
        let slice_bytes = w as u64 * h as u64 * kind.bytes_per_texel();
        // The kernels write without index checks: every view's slice must lie in the target.
        let target_bytes = g.buffer_size(target).unwrap_or(0);
        for v in job.views {
            assert!(
                (v.slice as u64 + 1) * slice_bytes <= target_bytes,
                "view slice {} beyond a target of {target_bytes} bytes",
                v.slice
            );
        }
        // Whole slices are cleared by the copy engine, windows by the clear pass below.
        let whole: Vec<u32> = job
            .views
            .iter()
            .filter(|v| v.covers(job.size))
            .map(|v| v.slice)
            .collect();
        g.pass(&format!("{t}.clear"))
            .uses(target, true)
            .uses(count, true)
            .encode(move |enc, res| {
                for &s in &whole {
                    enc.clear_buffer(
                        res.buffer(target),
                        s as u64 * slice_bytes,
                        Some(slice_bytes),
                    );
                }
                enc.clear_buffer(res.buffer(count), 0, None);
            })?;
        let mut view_proj = [[[0.0; 4]; 4]; MAX_VIEWS];
        let mut view_params = [[0u32; 4]; MAX_VIEWS];
        for (i, v) in job.views.iter().enumerate() {
            view_proj[i] = v.view_proj.to_cols_array_2d();
            view_params[i] = v.packed();
        }
        let params = RasterParams {
            view_proj,
            viewport: [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32],
            config: [
                job.cull_back_faces as u32,
                capacity,
                views as u32,
                // The alpha-tested chunks after these are drawn by their own passes below.
                scene.first_alpha_chunk,
            ],
            views: view_params,
            limits: [record_capacity, 0, 0, 0],
        };
        let pipelines = match kind {
            RasterTarget::Visibility => &self.visibility,
            RasterTarget::Depth => &self.depth,
        };
        let [triangles, tiles, large, clear] = pipelines;
        let windowed = job
            .views
            .iter()
            .filter(|v| !v.covers(job.size))
            .map(|v| (v.window[2] - v.window[0]) * (v.window[3] - v.window[1]))
            .max();
        let max = g.ctx().limits.max_compute_workgroups_per_dimension;
        if let Some(texels) = windowed {
            let n = texels.div_ceil(256);
            g.pass(&format!("{t}.clear_windows"))
                .constants(&params)
                .write(target)
                .dispatch(clear, [n.min(max), n.div_ceil(max), views as u32])?;
        }
        let SceneInFrame {
            positions,
            indices,
            instances,
            chunks,
            attributes,
            materials,
            color_textures,
            ..
        } = *scene;
        let n = scene.first_alpha_chunk.max(1);
        let groups = [n.min(max), n.div_ceil(max), 1];
        let [tile_groups, large_groups] = queues.workgroups(t).map(|n| n.min(max));
        // The three passes bind the same resources; they differ in entry point and dispatch.
        // Large before tiles, so that the near walls and floors that take the large path are
        // in the target before the many smaller triangles behind them.
        let stages = [
            ("rasterize", groups, triangles),
            ("rasterize_large", [large_groups, 1, 1], large),
            ("rasterize_tiles", [tile_groups, 1, 1], tiles),
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
        let alpha_chunks = scene.chunk_count - scene.first_alpha_chunk;
        if alpha_chunks == 0 {
            return Ok(());
        }
        let alpha_params = RasterParams {
            config: [params.config[0], capacity, views as u32, alpha_chunks],
            limits: [record_capacity, scene.first_alpha_chunk, 0, 0],
            ..params
        };
        let [alpha_triangles, alpha_tiles] = match kind {
            RasterTarget::Visibility => &self.visibility_alpha,
            RasterTarget::Depth => &self.depth_alpha,
        };
        let alpha_tile_groups = queues.alpha_workgroups(t).min(max);
        let stages = [
            (
                "rasterize_alpha",
                [alpha_chunks.min(max), alpha_chunks.div_ceil(max), 1],
                alpha_triangles,
            ),
            (
                "rasterize_alpha_tiles",
                [alpha_tile_groups, 1, 1],
                alpha_tiles,
            ),
        ];
        for (stage, dispatch, pipeline) in stages {
            g.pass(&format!("{t}.{stage}"))
                .constants(&alpha_params)
                .write(target)
                .write(queue)
                .write(count)
                .write(records)
                .read(positions)
                .read(indices)
                .read(instances)
                .read(chunks)
                .read(attributes)
                .read(materials)
                .read(color_textures)
                .sampler(SamplerKind::LinearRepeat)
                .dispatch(pipeline, dispatch)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(name: &str, c: [u32; 4]) -> FrameResult {
        FrameResult {
            buffers: vec![(
                format!("{name}.tile_count"),
                bytemuck::cast_slice(&c).to_vec(),
            )],
            ..Default::default()
        }
    }

    #[test]
    fn queues_grow_only_when_a_frame_overflowed_them() {
        let mut q = RasterQueues::default();
        let start = q.sizes("gbuffer", 100);
        assert_eq!(start.entries, 1 << 17, "the floor for a small target");
        let fits = counts("gbuffer", [start.entries, 3, start.records, 0]);
        assert!(q.grow(&fits, u64::MAX).unwrap().is_empty());
        assert_eq!(q.sizes("gbuffer", 100), start);
        // A count past the capacity: grown to 1.5 times the count, the other queue kept.
        let over = counts("gbuffer", [start.entries * 2, 0, 10, 0]);
        assert_eq!(
            q.grow(&over, u64::MAX).unwrap(),
            vec!["gbuffer".to_string()]
        );
        let grown = q.sizes("gbuffer", 100);
        assert_eq!(grown.entries, start.entries * 3);
        assert_eq!(grown.records, start.records);
        // Techniques whose counts the frame did not read back are left alone.
        assert!(
            q.grow(&counts("other", [u32::MAX; 4]), u64::MAX)
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn workgroups_follow_the_last_frame_counts_within_their_bounds() {
        let mut q = RasterQueues::default();
        q.sizes("gbuffer", 100);
        assert_eq!(
            q.workgroups("gbuffer"),
            [TILE_WORKGROUPS; 2],
            "no frame yet"
        );
        let mut after = |entries, large| {
            q.grow(&counts("gbuffer", [entries, large, 0, 0]), u64::MAX)
                .unwrap();
            q.workgroups("gbuffer")
        };
        assert_eq!(after(130_001, 0), [32_501, IDLE_LARGE_WORKGROUPS]);
        assert_eq!(after(9, 48), [MIN_TILE_WORKGROUPS, TILE_WORKGROUPS]);
        assert_eq!(after(u32::MAX, 1), [MAX_TILE_WORKGROUPS, TILE_WORKGROUPS]);
    }

    #[test]
    fn a_queue_beyond_the_binding_limit_is_an_error_naming_it() {
        let mut q = RasterQueues::default();
        q.sizes("sun_shadows", 100);
        let err = q
            .grow(&counts("sun_shadows", [1 << 24, 0, 0, 0]), 1 << 20)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("sun_shadows") && err.contains("tile queue"),
            "{err}"
        );
        let err = q
            .grow(
                &counts("sun_shadows", [0, LARGE_CAPACITY as u32 + 1, 0, 0]),
                u64::MAX,
            )
            .unwrap_err()
            .to_string();
        assert!(err.contains("256 tiles"), "{err}");
    }
}
