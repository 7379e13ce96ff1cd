//! The GPU copy of the frame's ray-tracing scene: the packed BLAS list (uploaded at load,
//! then only the refitted BLAS rewritten in place), the two TLAS rewritten every frame, and
//! the cut-out data of `bvh::BvhAlpha`.

use bytemuck::{Pod, Zeroable};
use hikari_bvh::{InstanceRecord, PackedBlases, TriangleRecord, WideNode};
use hikari_scene::Scene;

use super::frame_bvh::{FrameBvh, FrameBvhStats, FrameTlases};
use super::settings::SceneRtSettings;
use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::FrameGraph;
use crate::reference::octahedral;
use crate::scene::bvh::{AlphaInstance, AlphaTriangle, BvhAlpha};
use crate::scene::bvh_trace::{BvhBuffers, STACK_SIZE};
use crate::scene::upload::{SceneGpu, VertexAttr, snorm16x2};

/// A storage buffer that grows (by half again) when its contents outgrow it, else is
/// rewritten in place.
struct Growing {
    name: &'static str,
    buffer: wgpu::Buffer,
}

impl Growing {
    fn new<T: Pod + Zeroable>(ctx: &GpuContext, name: &'static str, data: &[T]) -> Result<Self> {
        let mut g = Self {
            name,
            buffer: create(ctx, name, 16),
        };
        g.write(ctx, data)?;
        Ok(g)
    }

    /// Writes `data` from the start (one zeroed record when empty: bindings cannot be empty,
    /// and a zeroed node has no children). Returns the bytes written.
    fn write<T: Pod + Zeroable>(&mut self, ctx: &GpuContext, data: &[T]) -> Result<u64> {
        let zero = [T::zeroed()];
        let data = if data.is_empty() { &zero[..] } else { data };
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let len = bytes.len() as u64;
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        if len > limit {
            return Err(RenderError::Limit {
                what: format!("size in bytes of `{}`", self.name),
                requested: len,
                limit,
            });
        }
        if self.buffer.size() < len {
            let grown = (len + len / 2).min(limit).next_multiple_of(16).max(len);
            self.buffer = create(ctx, self.name, grown);
        }
        ctx.queue.write_buffer(&self.buffer, 0, bytes);
        Ok(len)
    }
}

fn create(ctx: &GpuContext, name: &str, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(name),
        size: size.next_multiple_of(4).max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// The BVH handles of one frame: the GI rays' and the shadow rays' (same BLAS list).
#[derive(Clone, Copy, Debug)]
pub struct SceneRtBuffers {
    pub gi: BvhBuffers,
    pub shadow: BvhBuffers,
}

/// One scene BVH on the GPU for every ray traced in the frame.
pub struct SceneRt {
    pub cpu: FrameBvh,
    /// Where each BLAS lies in the packed lists (node, triangle offsets).
    offsets: Vec<(u32, u32)>,
    blas_nodes: wgpu::Buffer,
    triangles: wgpu::Buffer,
    gi_nodes: Growing,
    gi_instances: Growing,
    shadow_nodes: Growing,
    shadow_instances: Growing,
    alpha_instances: wgpu::Buffer,
    alpha_triangles: wgpu::Buffer,
    alpha_textures: wgpu::Texture,
    /// Deepest BLAS and TLAS, in nodes on a root-to-leaf path.
    blas_depth: u32,
    tlas_depth: u32,
    last: Option<FrameBvhStats>,
    /// Scene meshes whose BLAS the last [`SceneRt::update`] refitted.
    last_refitted: Vec<usize>,
    /// Per scene mesh: its first vertex in `SceneGpu::positions` and `attributes`.
    vertex_base: Vec<u64>,
    /// The time the raster's vertices show (`None`: the rest pose).
    raster_time: Option<f32>,
    /// The time `SceneGpu::prev_positions` shows: last frame's `raster_time`.
    prev_raster_time: Option<f32>,
    /// Per deforming scene mesh, the positions the raster shows when not the rest pose
    /// (what goes to `prev_positions` next frame).
    shown_positions: std::collections::HashMap<usize, Vec<[f32; 4]>>,
}

impl SceneRt {
    /// Builds every BLAS in its rest pose, both TLAS over every instance (so that a frame
    /// that never updates still traces the whole scene), and uploads them with the cut-out
    /// data and `color_textures` (`SceneGpu::textures.color`, which the alpha test samples).
    pub fn new(ctx: &GpuContext, scene: &Scene, color_textures: &wgpu::Texture) -> Result<Self> {
        let mut cpu = FrameBvh::new(scene).map_err(bvh_error)?;
        let packed = PackedBlases::new(&cpu.blases);
        let alpha = BvhAlpha::for_scene(scene);
        let blas_depth = cpu.blases.iter().map(|b| b.stats.depth).max().unwrap_or(0);
        let everything = SceneRtSettings {
            cull: false,
            ..SceneRtSettings::default()
        };
        let first = cpu
            .update(glam::Vec3::ZERO, &glam::Mat4::IDENTITY, &everything)
            .map_err(bvh_error)?;
        let mut rt = Self {
            offsets: packed.offsets.clone(),
            blas_nodes: init_buffer::<WideNode>(ctx, "bvh.blas_nodes", &packed.nodes)?,
            triangles: init_buffer::<TriangleRecord>(ctx, "bvh.triangles", &packed.triangles)?,
            gi_nodes: Growing::new::<WideNode>(ctx, "bvh.tlas_nodes", &[])?,
            gi_instances: Growing::new::<InstanceRecord>(ctx, "bvh.instances", &[])?,
            shadow_nodes: Growing::new::<WideNode>(ctx, "bvh.shadow_tlas_nodes", &[])?,
            shadow_instances: Growing::new::<InstanceRecord>(ctx, "bvh.shadow_instances", &[])?,
            alpha_instances: init_buffer::<AlphaInstance>(
                ctx,
                "bvh.alpha_instances",
                &alpha.instances,
            )?,
            alpha_triangles: init_buffer::<AlphaTriangle>(
                ctx,
                "bvh.alpha_triangles",
                &alpha.triangles,
            )?,
            alpha_textures: color_textures.clone(),
            blas_depth,
            tlas_depth: 0,
            last: None,
            last_refitted: Vec::new(),
            vertex_base: scene
                .meshes
                .iter()
                .scan(0u64, |base, m| {
                    let first = *base;
                    *base += m.positions.len() as u64;
                    Some(first)
                })
                .collect(),
            raster_time: None,
            prev_raster_time: None,
            shown_positions: Default::default(),
            cpu,
        };
        rt.upload(ctx, &first)?;
        Ok(rt)
    }

    /// Writes what `frame` changed: the refitted BLAS in place (a refit keeps every node
    /// and triangle where it was) and both TLAS. Returns the bytes written.
    pub fn upload(&mut self, ctx: &GpuContext, frame: &FrameTlases) -> Result<u64> {
        let mut bytes = 0;
        for &m in &frame.refitted {
            let (Some(blas), Some(&(node, tri))) = (self.cpu.blases.get(m), self.offsets.get(m))
            else {
                continue;
            };
            let nodes: &[u8] = bytemuck::cast_slice(&blas.nodes);
            let tris: &[u8] = bytemuck::cast_slice(&blas.triangles);
            if !nodes.is_empty() {
                let at = node as u64 * std::mem::size_of::<WideNode>() as u64;
                ctx.queue.write_buffer(&self.blas_nodes, at, nodes);
            }
            if !tris.is_empty() {
                let at = tri as u64 * std::mem::size_of::<TriangleRecord>() as u64;
                ctx.queue.write_buffer(&self.triangles, at, tris);
            }
            bytes += (nodes.len() + tris.len()) as u64;
        }
        bytes += self.gi_nodes.write(ctx, &frame.gi.nodes)?;
        bytes += self.gi_instances.write(ctx, &frame.gi.instances)?;
        bytes += self.shadow_nodes.write(ctx, &frame.shadow.nodes)?;
        bytes += self.shadow_instances.write(ctx, &frame.shadow.instances)?;
        self.tlas_depth = frame.gi.stats.depth.max(frame.shadow.stats.depth);
        Ok(bytes)
    }

    /// One frame's update on the CPU and its upload; the stats are also kept for
    /// [`SceneRt::last_stats`].
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        camera: glam::Vec3,
        view_proj: &glam::Mat4,
        s: &SceneRtSettings,
    ) -> Result<FrameBvhStats> {
        let frame = self.cpu.update(camera, view_proj, s).map_err(bvh_error)?;
        let bytes = self.upload(ctx, &frame)?;
        self.last_refitted.clone_from(&frame.refitted);
        let stats = FrameBvhStats {
            upload_bytes: bytes,
            ..frame.stats
        };
        self.last = Some(stats);
        Ok(stats)
    }

    /// Scene meshes whose BLAS the last [`SceneRt::update`] refitted (their pose at that
    /// frame's time is `cpu.pose_at(mesh, time)`).
    pub fn refitted(&self) -> &[usize] {
        &self.last_refitted
    }

    /// The last [`SceneRt::update`]'s stats (`None` before the first).
    pub fn last_stats(&self) -> Option<FrameBvhStats> {
        self.last
    }

    /// Rewrites the rasteriser's positions and normals of every deforming mesh for `time`
    /// (all of them, unthrottled: the picture is exact, only the BVH may lag) when it differs
    /// from what they show, and `SceneGpu::prev_positions` of those meshes with what they
    /// showed until now, so that the G-buffer's motion sees the deformation. Call it once a
    /// frame: a frame at the same time as the last still copies the last pose over (the
    /// motion of a mesh that stopped is 0). Returns the bytes of positions and normals
    /// written (0: the raster draws what it drew, cached shadow cascades stay valid); the
    /// frame's stats count both. Tangents keep their rest pose.
    pub fn update_raster(&mut self, ctx: &GpuContext, scene: &SceneGpu, time: Option<f32>) -> u64 {
        let moved = time != self.raster_time;
        if !moved && self.prev_raster_time == self.raster_time {
            return 0;
        }
        let start = std::time::Instant::now();
        let mut bytes = 0;
        let mut prev_bytes = 0u64;
        let meshes: Vec<usize> = self.cpu.animated_meshes().collect();
        for m in meshes {
            let base = self.vertex_base[m] as usize;
            // What the raster shows now becomes last frame's pose.
            let end = self
                .vertex_base
                .get(m + 1)
                .map_or(scene.cpu.positions.len(), |&e| e as usize);
            let shown: &[[f32; 4]] = match self.shown_positions.get(&m) {
                Some(p) => p,
                None => scene.cpu.positions.get(base..end).unwrap_or(&[]),
            };
            ctx.queue.write_buffer(
                &scene.prev_positions,
                base as u64 * 16,
                bytemuck::cast_slice(shown),
            );
            prev_bytes += shown.len() as u64 * 16;
            if !moved {
                continue;
            }
            let Some((positions, normals)) = self.cpu.pose_at(m, time) else {
                continue;
            };
            let Some(rest) = scene.cpu.attributes.get(base..base + positions.len()) else {
                continue;
            };
            let p4: Vec<[f32; 4]> = positions.iter().map(|p| p.extend(1.0).to_array()).collect();
            let attrs: Vec<VertexAttr> = rest
                .iter()
                .zip(normals.iter())
                .map(|(a, n)| VertexAttr {
                    normal: snorm16x2(octahedral::encode(n.normalize_or(glam::Vec3::Y))),
                    ..*a
                })
                .collect();
            ctx.queue.write_buffer(
                &scene.positions,
                base as u64 * 16,
                bytemuck::cast_slice(&p4),
            );
            let attr_size = std::mem::size_of::<VertexAttr>() as u64;
            ctx.queue.write_buffer(
                &scene.attributes,
                base as u64 * attr_size,
                bytemuck::cast_slice(&attrs),
            );
            bytes += (p4.len() * 16) as u64 + attrs.len() as u64 * attr_size;
            self.shown_positions.insert(m, p4);
        }
        self.prev_raster_time = self.raster_time;
        self.raster_time = time;
        if let Some(s) = &mut self.last {
            s.upload_bytes += bytes + prev_bytes;
            s.raster_ms += start.elapsed().as_secs_f64() * 1e3;
        }
        bytes
    }

    /// Imports both BVH into a frame (the BLAS list and cut-out data once, shared).
    pub fn import(&self, g: &mut FrameGraph<'_>) -> Result<SceneRtBuffers> {
        let need = self.blas_depth.saturating_sub(1) + self.tlas_depth.saturating_sub(1);
        if need > STACK_SIZE {
            return Err(RenderError::Limit {
                what: "traversal stack entries the BVH depth needs".into(),
                requested: need as u64,
                limit: STACK_SIZE as u64,
            });
        }
        let blas_nodes = g.import_buffer("bvh.blas_nodes", &self.blas_nodes);
        let triangles = g.import_buffer("bvh.triangles", &self.triangles);
        let alpha_instances = g.import_buffer("bvh.alpha_instances", &self.alpha_instances);
        let alpha_triangles = g.import_buffer("bvh.alpha_triangles", &self.alpha_triangles);
        let alpha_textures = g.import_texture("bvh.alpha_textures", &self.alpha_textures);
        let with = |tlas_nodes, instances| BvhBuffers {
            blas_nodes,
            triangles,
            tlas_nodes,
            instances,
            alpha_instances,
            alpha_triangles,
            alpha_textures,
        };
        let gi = with(
            g.import_buffer("bvh.tlas_nodes", &self.gi_nodes.buffer),
            g.import_buffer("bvh.instances", &self.gi_instances.buffer),
        );
        let shadow = with(
            g.import_buffer("bvh.shadow_tlas_nodes", &self.shadow_nodes.buffer),
            g.import_buffer("bvh.shadow_instances", &self.shadow_instances.buffer),
        );
        Ok(SceneRtBuffers { gi, shadow })
    }
}

fn bvh_error(e: hikari_bvh::BvhError) -> RenderError {
    RenderError::Graph(format!("scene BVH: {e}"))
}

fn init_buffer<T: Pod>(ctx: &GpuContext, name: &str, data: &[T]) -> Result<wgpu::Buffer> {
    ctx.storage_buffer(name, bytemuck::cast_slice(data))
}
