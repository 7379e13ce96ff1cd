//! GPU ray tracing against hikari-bvh's compressed 8-wide BVH: closest hit and any hit, two
//! levels (TLAS over instances, then BLAS), in a compute kernel (`shaders/bvh/traverse.wgsl`,
//! importable as `hikari::bvh` by later passes: AO, GI, shadows).
//!
//! ```ignore
//! let mut trace = BvhTrace::new(&ctx, &mut lib)?;
//! trace.upload_blases(&ctx, &blases)?;      // once, and again after refits
//! trace.upload_tlas(&ctx, &tlas)?;          // every frame
//! trace.record(&mut g, rays, hits, count, TraceMode::Closest, RayOrder::Coherent)?;
//! ```
//!
//! [`RayOrder`] says whether neighbouring rays in the buffer take similar paths; it picks one of
//! two kernel configurations, measured best for each kind of ray (BENCHMARKS.md).
//!
//! The kernel is the twin of `hikari_bvh::traverse` (tests/render/bvh_trace.rs checks it against it
//! and against brute force). Its stack holds one entry per tree level below the root, TLAS and
//! BLAS together; scenes deeper than [`STACK_SIZE`] are refused when recorded.
//!
//! The kernel runs without wgpu's runtime checks (bounds clamping on every load, a counter in
//! every loop), which made the first kernel 35-40% slower and the current one 5%
//! (BENCHMARKS.md). What makes that safe is checked here, on the CPU, before anything reaches
//! the GPU: every tree uploaded is walked once (`check_tree`: child and primitive indices in
//! range, children after their parent, meta bytes well formed, depth measured rather than
//! trusted), every instance record must point at an uploaded BLAS, and the ray and hit buffers
//! must hold `count` records.
//!
//! Alpha cut-outs: hits on triangles marked non-opaque (`hikari_bvh::TRIANGLE_NON_OPAQUE`,
//! see `bvh::blases`) count only where the material's alpha passes its cut-off, which the
//! kernel evaluates from [`BvhAlpha`] and the scene's sRGB texture array
//! ([`BvhTrace::upload_alpha`]). Until that is uploaded, placeholders stand in (one zeroed
//! record of each table, a 1 x 1 texture), which is all a BVH without marked triangles needs:
//! tracing plain meshes takes no extra call. A TLAS that reaches marked triangles of an
//! instance the uploaded alpha data does not cover (any, before an upload) is refused when
//! recorded. [`BvhAlpha::opaque`] with no textures makes every marked triangle opaque.

use bytemuck::{Pod, Zeroable};
use hikari_bvh::layout::{MAX_LEAF_TRIANGLES, META_INTERNAL, WIDTH};
use hikari_bvh::{Blas, InstanceRecord, PackedBlases, Tlas, TriangleRecord, WideNode};
use naga_oil::compose::ShaderDefValue;
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{BindingSet, Buf, FrameGraph, SamplerKind, Tex};
use crate::pipeline::ComputePipeline;
use crate::scene::bvh::{AlphaInstance, AlphaTriangle, BvhAlpha};
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
    /// 0, or the width of the row-major image the rays form ([`RayOrder::Image`]).
    pub image_width: u32,
    pub pad0: u32,
    pub pad1: u32,
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

/// How the rays of one dispatch relate; it picks the kernel configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayOrder {
    /// Neighbouring rays take similar paths: camera rays in pixel order (best in small 2D
    /// tiles, as 8 x 8 workgroups generate them), shadow rays from neighbouring pixels. One ray
    /// per invocation keeps a warp's lanes in step on the same nodes.
    Coherent,
    /// Rays go anywhere (AO, diffuse GI, random shadow samples): each invocation traces several
    /// rays and starts the next one as soon as it finishes one.
    Incoherent,
    /// Coherent rays forming a row-major image `width` pixels wide (the ray count a whole
    /// number of rows), e.g. camera rays per pixel: traced in 8 x 8 pixel tiles, whose rays
    /// stay together far longer than those of a 32-pixel strip of one row. Hits are written
    /// where the rays are read, so the layout of both buffers stays row-major.
    Image { width: u32 },
}

/// How an invocation that finished a ray picks its next one (with more than one ray per
/// invocation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refill {
    /// The ray `workgroup` further on in the chunk.
    Stride,
    /// The chunk's next untaken ray (a workgroup atomic).
    Dynamic,
    /// Waits until at least `min_free` lanes of its subgroup (or all) are free, then they all
    /// take the chunk's next rays together, so neighbouring rays start in step. Needs
    /// `wgpu::Features::SUBGROUP`; `min_free` is 4, 8, 16, 24 or 32.
    Subgroup { min_free: u32 },
}

/// How a trace kernel is built. [`TraceConfig::coherent`] and [`TraceConfig::incoherent`] are
/// the fastest configurations measured on an NVIDIA H200 for each [`RayOrder`]
/// (BENCHMARKS.md, "Ray tracing core"); the other settings exist to measure against them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceConfig {
    /// Invocations per workgroup: 32, 64 or 128.
    pub workgroup: u32,
    /// Rays each invocation traces, one after the other, from its workgroup's chunk of
    /// `workgroup * rays_per_thread` consecutive rays: 1, 4, 8, 16 or 32.
    pub rays_per_thread: u32,
    pub refill: Refill,
    /// Triangles an iteration of the walk tests at most: 1, 2, 3, 4, or 0 for all of a node's
    /// hit triangles. Lanes with triangles left do those in the next iterations while their
    /// warp's other lanes test nodes.
    pub triangles_per_step: u32,
    /// Keep wgpu's runtime checks (bounds clamping, loop counters); slower, for comparison.
    pub runtime_checks: bool,
    /// Test hits on triangles marked non-opaque against the scene's alpha (cut-outs). Off, the
    /// cut-out code is left out of the kernel (its registers slow every ray by 4-8 % on an
    /// H200) and a TLAS that reaches marked triangles is refused.
    pub alpha: bool,
}

impl TraceConfig {
    /// For [`RayOrder::Coherent`] and [`RayOrder::Image`]: one ray per invocation.
    pub fn coherent() -> Self {
        Self {
            workgroup: 64,
            rays_per_thread: 1,
            refill: Refill::Stride,
            triangles_per_step: 2,
            runtime_checks: false,
            alpha: false,
        }
    }

    /// For [`RayOrder::Incoherent`]: 8 rays per invocation, the next free one of the chunk as
    /// soon as one is done; one triangle per step.
    pub fn incoherent() -> Self {
        Self {
            rays_per_thread: 8,
            refill: Refill::Dynamic,
            triangles_per_step: 1,
            ..Self::coherent()
        }
    }

    pub fn for_order(order: RayOrder) -> Self {
        match order {
            RayOrder::Coherent | RayOrder::Image { .. } => Self::coherent(),
            RayOrder::Incoherent => Self::incoherent(),
        }
    }

    /// Entry shader and shader defs.
    fn shader(
        &self,
        ctx: &GpuContext,
    ) -> Result<(&'static str, Vec<(&'static str, ShaderDefValue)>)> {
        let bad = |what: &str, v: u32, allowed: &str| RenderError::Pass {
            pass: "bvh_trace".into(),
            message: format!("TraceConfig::{what} is {v}; it must be one of {allowed}"),
        };
        let mut defs = Vec::new();
        if self.alpha {
            defs.push("BVH_ALPHA");
        }
        match self.workgroup {
            32 => defs.push("TRACE_WORKGROUP_32"),
            64 => {}
            128 => defs.push("TRACE_WORKGROUP_128"),
            v => return Err(bad("workgroup", v, "32, 64, 128")),
        }
        match self.rays_per_thread {
            1 => defs.push("TRACE_RAYS_PER_THREAD_1"),
            4 => defs.push("TRACE_RAYS_PER_THREAD_4"),
            8 => {}
            16 => defs.push("TRACE_RAYS_PER_THREAD_16"),
            32 => defs.push("TRACE_RAYS_PER_THREAD_32"),
            v => return Err(bad("rays_per_thread", v, "1, 4, 8, 16, 32")),
        }
        match self.refill {
            Refill::Stride => {}
            Refill::Dynamic => defs.push("TRACE_DYNAMIC_FETCH"),
            Refill::Subgroup { min_free } => {
                if !ctx.has(wgpu::Features::SUBGROUP) {
                    return Err(RenderError::Pass {
                        pass: "bvh_trace".into(),
                        message: "Refill::Subgroup needs subgroup operations, which this GPU \
                                  does not offer; use Refill::Stride or Refill::Dynamic"
                            .into(),
                    });
                }
                defs.push("TRACE_WARP_REFILL");
                match min_free {
                    4 => defs.push("TRACE_REFILL_MIN_4"),
                    8 => defs.push("TRACE_REFILL_MIN_8"),
                    16 => {}
                    24 => defs.push("TRACE_REFILL_MIN_24"),
                    32 => defs.push("TRACE_REFILL_MIN_32"),
                    v => return Err(bad("refill min_free", v, "4, 8, 16, 24, 32")),
                }
            }
        }
        match self.triangles_per_step {
            0 => defs.push("BVH_TRIANGLES_PER_STEP_ALL"),
            1 => defs.push("BVH_TRIANGLES_PER_STEP_1"),
            2 => {}
            3 => defs.push("BVH_TRIANGLES_PER_STEP_3"),
            4 => defs.push("BVH_TRIANGLES_PER_STEP_4"),
            v => return Err(bad("triangles_per_step", v, "0 (all), 1, 2, 3, 4")),
        }
        Ok((
            "bvh/trace.wgsl",
            defs.into_iter()
                .map(|d| (d, ShaderDefValue::Bool(true)))
                .collect(),
        ))
    }

    /// Rays one workgroup traces.
    fn rays_per_workgroup(&self) -> u32 {
        self.workgroup * self.rays_per_thread
    }
}

/// The two pipelines of one configuration.
struct Kernels {
    config: TraceConfig,
    closest: ComputePipeline,
    any: ComputePipeline,
}

impl Kernels {
    fn new(ctx: &GpuContext, lib: &mut ShaderLibrary, config: TraceConfig) -> Result<Self> {
        let (path, defs) = config.shader(ctx)?;
        let build = |lib: &mut ShaderLibrary, entry: &str| {
            if config.runtime_checks {
                ComputePipeline::new(ctx, lib, path, entry, &defs)
            } else {
                // SAFETY: the kernel indexes only (a) the BVH buffers, with indices that
                // `check_tree` and `check_instances` prove in range before any upload, walking
                // each tree from its root exactly as the kernel does; (b) rays and hits below
                // `params.count`, which `record` checks both buffers hold; the alpha tables
                // (`bvh_accept_candidate`), with indices it compares with their arrayLength
                // first, and the texture array, whose layer index sampling clamps; (c) its stack, whose
                // depth `import` bounds by STACK_SIZE with depths measured by `check_tree`; (d)
                // vector components 0..2 of its own making; `trace_ray_index` maps 0..count
                // one to one onto itself. Loops end: every iteration consumes
                // a hit bit or pops, and children lie after their parent (checked), so the walk
                // is finite for every ray, NaN included; each invocation takes rays from a
                // counter that only grows. Integer divisors are never zero (`trace_ray_index`:
                // `record` refuses an image width of 0); workgroup memory is written before it
                // is read (trace.wgsl).
                unsafe { ComputePipeline::new_unchecked(ctx, lib, path, entry, &defs) }
            }
        };
        Ok(Self {
            config,
            closest: build(lib, "closest_hit")?,
            any: build(lib, "any_hit")?,
        })
    }
}

/// The BVH's resources in a frame, in binding order of the binding set `bvh` of
/// `hikari::bvh` (a linear, repeating sampler follows them at binding 7).
#[derive(Clone, Copy, Debug)]
pub struct BvhBuffers {
    pub blas_nodes: Buf,
    pub triangles: Buf,
    pub tlas_nodes: Buf,
    pub instances: Buf,
    /// [`AlphaInstance`] records (binding 4).
    pub alpha_instances: Buf,
    /// [`AlphaTriangle`] records (binding 5).
    pub alpha_triangles: Buf,
    /// The scene's sRGB texture array (binding 6), or a 1 x 1 placeholder.
    pub alpha_textures: Tex,
}

impl BvhBuffers {
    /// The binding set `bvh`, for any pass whose shader imports `hikari::bvh`.
    pub fn binding_set(&self, g: &mut FrameGraph<'_>) -> BindingSet {
        g.binding_set("bvh")
            .read(self.blas_nodes)
            .read(self.triangles)
            .read(self.tlas_nodes)
            .read(self.instances)
            .read(self.alpha_instances)
            .read(self.alpha_triangles)
            .read(self.alpha_textures)
            .sampler(SamplerKind::LinearRepeat)
            .finish()
    }
}

/// One GPU buffer that is rewritten in place while the contents fit.
struct Upload {
    buffer: wgpu::Buffer,
    /// Bytes in use (the buffer may be larger after a shrink).
    len: u64,
}

/// Where one uploaded BLAS lies in the packed buffers, and its measured depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct BlasSpan {
    node_offset: u32,
    triangle_offset: u32,
    nodes: u32,
    depth: u32,
    /// Some triangle is marked non-opaque.
    non_opaque: bool,
}

/// Pipelines plus the GPU copy of a BVH scene (all BLAS packed, and the TLAS).
pub struct BvhTrace {
    coherent: Kernels,
    /// `None` when both orders use the same configuration.
    incoherent: Option<Kernels>,
    blas_nodes: Option<Upload>,
    triangles: Option<Upload>,
    tlas_nodes: Option<Upload>,
    instances: Option<Upload>,
    alpha_instances: Upload,
    alpha_triangles: Upload,
    /// The scene's sRGB texture array, or a 1 x 1 placeholder.
    alpha_textures: wgpu::Texture,
    /// Instance records uploaded in `alpha_instances` (0 for the placeholder).
    alpha_instance_count: u32,
    /// One more than the largest instance index of the TLAS whose BLAS has non-opaque
    /// triangles (0: none), which the alpha instance records must cover.
    alpha_instances_needed: u32,
    blases: Vec<BlasSpan>,
    /// Deepest BLAS, in nodes on a root-to-leaf path.
    blas_depth: u32,
    tlas_depth: u32,
}

impl BvhTrace {
    /// The measured best configuration for each [`RayOrder`].
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Self::with_configs(
            ctx,
            lib,
            TraceConfig {
                alpha: true,
                ..TraceConfig::coherent()
            },
            TraceConfig {
                alpha: true,
                ..TraceConfig::incoherent()
            },
        )
    }

    /// One configuration for both orders (to measure or test it).
    pub fn with_config(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        config: TraceConfig,
    ) -> Result<Self> {
        Self::with_configs(ctx, lib, config, config)
    }

    pub fn with_configs(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        coherent: TraceConfig,
        incoherent: TraceConfig,
    ) -> Result<Self> {
        let coherent_kernels = Kernels::new(ctx, lib, coherent)?;
        let incoherent = if incoherent == coherent {
            None
        } else {
            Some(Kernels::new(ctx, lib, incoherent)?)
        };
        Ok(Self {
            coherent: coherent_kernels,
            incoherent,
            blas_nodes: None,
            triangles: None,
            tlas_nodes: None,
            instances: None,
            alpha_instances: new_upload(
                ctx,
                "bvh.alpha_instances",
                bytemuck::bytes_of(&AlphaInstance::zeroed()),
            ),
            alpha_triangles: new_upload(
                ctx,
                "bvh.alpha_triangles",
                bytemuck::bytes_of(&AlphaTriangle::zeroed()),
            ),
            alpha_textures: placeholder_texture(ctx),
            alpha_instance_count: 0,
            alpha_instances_needed: 0,
            blases: Vec::new(),
            blas_depth: 0,
            tlas_depth: 0,
        })
    }

    /// Uploads the cut-out data of the scene the BVH was built from ([`BvhAlpha::for_scene`]),
    /// with its sRGB texture array (`SceneGpu::textures.color`, layers as
    /// `textures::LayerMap` numbers them; `None`: a 1 x 1 white texture, for alpha data
    /// that names no texture). Needed once the BVH has triangles marked non-opaque; call again
    /// when the scene's instances or materials change.
    pub fn upload_alpha(
        &mut self,
        ctx: &GpuContext,
        alpha: &BvhAlpha,
        color_textures: Option<&wgpu::Texture>,
    ) -> Result<()> {
        let color_textures = match color_textures {
            Some(t) => t.clone(),
            None => placeholder_texture(ctx),
        };
        if color_textures.dimension() != wgpu::TextureDimension::D2
            || !color_textures
                .usage()
                .contains(wgpu::TextureUsages::TEXTURE_BINDING)
        {
            return Err(RenderError::Pass {
                pass: "bvh_trace".into(),
                message: "upload_alpha needs the scene's 2D texture array (bindable for \
                          sampling), as `SceneGpu::textures.color`"
                    .into(),
            });
        }
        let inst: &[AlphaInstance] = if alpha.instances.is_empty() {
            &[AlphaInstance::zeroed()]
        } else {
            &alpha.instances
        };
        let tris: &[AlphaTriangle] = if alpha.triangles.is_empty() {
            &[AlphaTriangle::zeroed()]
        } else {
            &alpha.triangles
        };
        let inst_bytes: &[u8] = bytemuck::cast_slice(inst);
        let tri_bytes: &[u8] = bytemuck::cast_slice(tris);
        check_size(ctx, "bvh.alpha_instances", inst_bytes.len() as u64)?;
        check_size(ctx, "bvh.alpha_triangles", tri_bytes.len() as u64)?;
        upload_into(
            ctx,
            &mut self.alpha_instances,
            "bvh.alpha_instances",
            inst_bytes,
        );
        upload_into(
            ctx,
            &mut self.alpha_triangles,
            "bvh.alpha_triangles",
            tri_bytes,
        );
        self.alpha_instance_count = alpha.instances.len() as u32;
        self.alpha_textures = color_textures;
        Ok(())
    }

    fn kernels(&self, order: RayOrder) -> &Kernels {
        match (order, &self.incoherent) {
            (RayOrder::Incoherent, Some(k)) => k,
            _ => &self.coherent,
        }
    }

    /// The configuration used for rays of `order`.
    pub fn config(&self, order: RayOrder) -> TraceConfig {
        self.kernels(order).config
    }

    /// Uploads every BLAS, concatenated as [`PackedBlases`] lays them out (the offsets a TLAS
    /// built over the same list stores in its instance records). Call again after refits.
    pub fn upload_blases(&mut self, ctx: &GpuContext, blases: &[Blas]) -> Result<()> {
        self.upload_packed(ctx, &PackedBlases::new(blases))
    }

    /// [`BvhTrace::upload_blases`] for an already packed list. Every tree is checked first (see
    /// the module docs); a TLAS uploaded before stays only if the BLAS list kept its shape.
    pub fn upload_packed(&mut self, ctx: &GpuContext, packed: &PackedBlases) -> Result<()> {
        let mut spans = Vec::with_capacity(packed.offsets.len());
        for (i, &(node_offset, triangle_offset)) in packed.offsets.iter().enumerate() {
            let (node_end, tri_end) = packed
                .offsets
                .get(i + 1)
                .copied()
                .unwrap_or((packed.nodes.len() as u32, packed.triangles.len() as u32));
            let nodes = packed
                .nodes
                .get(node_offset as usize..node_end as usize)
                .ok_or_else(|| invalid(format!("BLAS {i}: node range out of the packed list")))?;
            let tris = tri_end.checked_sub(triangle_offset).ok_or_else(|| {
                invalid(format!("BLAS {i}: triangle range out of the packed list"))
            })?;
            if tri_end as usize > packed.triangles.len() {
                return Err(invalid(format!(
                    "BLAS {i}: triangle range out of the packed list"
                )));
            }
            let depth = check_tree(&format!("BLAS {i}"), nodes, tris as usize)?;
            let non_opaque = packed.triangles[triangle_offset as usize..tri_end as usize]
                .iter()
                .any(|t| !t.is_opaque());
            spans.push(BlasSpan {
                node_offset,
                triangle_offset,
                nodes: nodes.len() as u32,
                depth,
                non_opaque,
            });
        }
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
        if spans != self.blases {
            // The TLAS's instance records were checked against the old list.
            self.tlas_nodes = None;
            self.instances = None;
            self.tlas_depth = 0;
            self.alpha_instances_needed = 0;
        }
        self.blas_depth = spans.iter().map(|s| s.depth).max().unwrap_or(0);
        self.blases = spans;
        Ok(())
    }

    /// Uploads the TLAS (every frame: it is rebuilt from the instances that survive culling).
    /// Its instance records must point into the BLAS list given to [`BvhTrace::upload_blases`]
    /// before.
    pub fn upload_tlas(&mut self, ctx: &GpuContext, tlas: &Tlas) -> Result<()> {
        let depth = check_tree("TLAS", &tlas.nodes, tlas.instances.len())?;
        check_instances(&tlas.instances, &self.blases)?;
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
        self.tlas_depth = depth;
        self.alpha_instances_needed = tlas
            .instances
            .iter()
            .filter(|r| self.blases[r.blas_index as usize].non_opaque)
            .map(|r| r.instance_index + 1)
            .max()
            .unwrap_or(0);
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
        .sum::<u64>()
            + self.alpha_instances.len
            + self.alpha_triangles.len
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
            return Err(missing(
                "TLAS (upload_tlas, after the BLAS list it points into)",
            ));
        };
        let need = self.stack_needed();
        if need > STACK_SIZE {
            return Err(RenderError::Limit {
                what: "traversal stack entries the BVH depth needs".into(),
                requested: need as u64,
                limit: STACK_SIZE as u64,
            });
        }
        let alpha_kernels =
            self.coherent.config.alpha && self.incoherent.as_ref().is_none_or(|k| k.config.alpha);
        if self.alpha_instances_needed > 0 && !alpha_kernels {
            return Err(RenderError::Graph(
                "bvh_trace: the TLAS reaches triangles marked non-opaque (cut-outs), but the \
                 kernels were built without TraceConfig::alpha (BvhTrace::new has it)"
                    .into(),
            ));
        }
        if self.alpha_instances_needed > self.alpha_instance_count {
            return Err(RenderError::Graph(format!(
                "bvh_trace: the TLAS reaches triangles marked non-opaque (cut-outs) of instance \
                 {}, but the alpha data covers {} instances; upload the scene's \
                 (BvhTrace::upload_alpha with BvhAlpha::for_scene) after its TLAS",
                self.alpha_instances_needed - 1,
                self.alpha_instance_count
            )));
        }
        Ok(BvhBuffers {
            blas_nodes: g.import_buffer("bvh.blas_nodes", &bn.buffer),
            triangles: g.import_buffer("bvh.triangles", &tr.buffer),
            tlas_nodes: g.import_buffer("bvh.tlas_nodes", &tn.buffer),
            instances: g.import_buffer("bvh.instances", &inst.buffer),
            alpha_instances: g.import_buffer("bvh.alpha_instances", &self.alpha_instances.buffer),
            alpha_triangles: g.import_buffer("bvh.alpha_triangles", &self.alpha_triangles.buffer),
            alpha_textures: g.import_texture("bvh.alpha_textures", &self.alpha_textures),
        })
    }

    /// Workgroups for `count` rays of `order`: 2D once one dimension's limit is passed, with
    /// as few spare workgroups as the split allows.
    pub fn groups(&self, ctx: &GpuContext, count: u32, order: RayOrder) -> [u32; 3] {
        let per = self.config(order).rays_per_workgroup();
        let total = count.div_ceil(per).max(1);
        let max = ctx.limits.max_compute_workgroups_per_dimension.max(1);
        let y = total.div_ceil(max);
        [total.div_ceil(y), y, 1]
    }

    /// Adds the pass `bvh_trace.closest` or `bvh_trace.any`: reads `count` [`hikari_bvh::Ray`]s
    /// from `rays`, writes as many [`hikari_bvh::Hit`]s to `hits` (misses have
    /// `primitive == instance == u32::MAX` and `t = inf`). `order` picks the kernel
    /// configuration; results do not depend on it (except which of several hits at exactly
    /// the same distance is reported).
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        rays: Buf,
        hits: Buf,
        count: u32,
        mode: TraceMode,
        order: RayOrder,
    ) -> Result<()> {
        let pass = mode.pass_name();
        for (buf, what, per) in [(rays, "rays", RAY_BYTES), (hits, "hits", HIT_BYTES)] {
            let size = g.buffer_size(buf).ok_or_else(|| RenderError::Pass {
                pass: pass.into(),
                message: format!("the {what} buffer is not of this frame"),
            })?;
            if size < count as u64 * per {
                return Err(RenderError::Pass {
                    pass: pass.into(),
                    message: format!(
                        "the {what} buffer holds {size} bytes, but {count} records need {}",
                        count as u64 * per
                    ),
                });
            }
        }
        let image_width = match order {
            RayOrder::Image { width } => {
                if width == 0 || !count.is_multiple_of(width) {
                    return Err(RenderError::Pass {
                        pass: pass.into(),
                        message: format!(
                            "RayOrder::Image {{ width: {width} }} needs a width of at least 1 \
                             and a whole number of rows, but there are {count} rays"
                        ),
                    });
                }
                width
            }
            _ => 0,
        };
        let bvh = self.import(g)?;
        let kernels = self.kernels(order);
        let pipeline = match mode {
            TraceMode::Closest => &kernels.closest,
            TraceMode::Any => &kernels.any,
        };
        let params = TraceParams {
            count,
            image_width,
            ..Default::default()
        };
        let groups = if count == 0 {
            [0, 1, 1]
        } else {
            self.groups(g.ctx(), count, order)
        };
        let set = bvh.binding_set(g);
        g.pass(pass)
            .set(set)
            .read(rays)
            .write(hits)
            .constants(&params)
            .dispatch(pipeline, groups)
    }
}

fn invalid(message: String) -> RenderError {
    RenderError::Pass {
        pass: "bvh_trace".into(),
        message: format!("refusing to upload a malformed BVH: {message}"),
    }
}

/// Checks, for one tree (a BLAS with `prims` triangles, or the TLAS with `prims` instances),
/// everything the unchecked kernel relies on when it walks it from node 0, and returns its
/// depth in nodes (0 for an empty tree). Nodes the walk cannot reach are not looked at.
///
/// Per reached node and slot: an internal slot (imask bit set) has meta `0b001_11000 | slot`
/// and its child (`child_base` plus the internal slots before it) lies after the node and
/// inside the tree; a leaf slot has a unary count of 1 to 3 primitives at an offset that keeps
/// them within the node's 24 primitive bits and within the tree's primitives; an empty slot
/// has meta 0.
pub(crate) fn check_tree(what: &str, nodes: &[WideNode], prims: usize) -> Result<u32> {
    if nodes.is_empty() {
        return Ok(0);
    }
    let bad = |i: usize, s: usize, m: String| invalid(format!("{what}, node {i}, slot {s}: {m}"));
    // 0 = not reached; children always lie after their parent, so one forward sweep reaches
    // every node the kernel can.
    let mut depth = vec![0u32; nodes.len()];
    depth[0] = 1;
    let mut max_depth = 1;
    for i in 0..nodes.len() {
        let d = depth[i];
        if d == 0 {
            continue;
        }
        max_depth = max_depth.max(d);
        let n = &nodes[i];
        let imask = n.imask();
        let mut internal = 0u64;
        for s in 0..WIDTH {
            let m = n.meta(s);
            if imask & (1 << s) != 0 {
                if m != META_INTERNAL | s as u8 {
                    return Err(bad(i, s, format!("internal child with meta {m:#04x}")));
                }
                let child = n.child_base as u64 + internal;
                internal += 1;
                if child <= i as u64 || child >= nodes.len() as u64 {
                    return Err(bad(
                        i,
                        s,
                        format!(
                            "child node {child} is not after this node and within the {} nodes",
                            nodes.len()
                        ),
                    ));
                }
                depth[child as usize] = depth[child as usize].max(d + 1);
            } else if m != 0 {
                let count = match m >> 5 {
                    0b001 => 1u64,
                    0b011 => 2,
                    0b111 => 3,
                    _ => return Err(bad(i, s, format!("leaf meta {m:#04x}"))),
                };
                debug_assert!(count as usize <= MAX_LEAF_TRIANGLES);
                let offset = (m & 0x1f) as u64;
                let end = n.prim_base as u64 + offset + count;
                if offset + count > 24 || end > prims as u64 {
                    return Err(bad(
                        i,
                        s,
                        format!(
                            "leaf primitives up to {end} (offset {offset}) out of the {prims} \
                             primitives or past the node's 24"
                        ),
                    ));
                }
            }
        }
    }
    Ok(max_depth)
}

/// Every instance record must point at the start of an uploaded, non-empty BLAS.
fn check_instances(instances: &[InstanceRecord], blases: &[BlasSpan]) -> Result<()> {
    for (i, r) in instances.iter().enumerate() {
        let ok = blases.get(r.blas_index as usize).is_some_and(|b| {
            b.nodes > 0
                && b.node_offset == r.blas_node_offset
                && b.triangle_offset == r.blas_triangle_offset
        });
        if !ok {
            return Err(invalid(format!(
                "TLAS instance record {i} points at BLAS {} (nodes from {}, triangles from {}), \
                 which is not one of the {} uploaded BLAS or is empty; upload the BLAS list the \
                 TLAS was built over first",
                r.blas_index,
                r.blas_node_offset,
                r.blas_triangle_offset,
                blases.len()
            )));
        }
    }
    Ok(())
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
    match slot {
        Some(u) => upload_into(ctx, u, name, bytes),
        None => *slot = Some(new_upload(ctx, name, bytes)),
    }
}

/// Rewrites `u` in place while the bytes fit and fill at least half of it, else replaces it.
fn upload_into(ctx: &GpuContext, u: &mut Upload, name: &str, bytes: &[u8]) {
    let len = bytes.len() as u64;
    if u.buffer.size() >= len && u.buffer.size() <= len.saturating_mul(2) {
        ctx.queue.write_buffer(&u.buffer, 0, bytes);
        u.len = len;
    } else {
        *u = new_upload(ctx, name, bytes);
    }
}

fn new_upload(ctx: &GpuContext, name: &str, bytes: &[u8]) -> Upload {
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(name),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
    Upload {
        buffer,
        len: bytes.len() as u64,
    }
}

/// The texture array bound while no scene's is uploaded: one white, opaque texel (the format
/// of `SceneGpu::textures.color`).
fn placeholder_texture(ctx: &GpuContext) -> wgpu::Texture {
    ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("bvh.alpha_textures.placeholder"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &[255; 4],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_bvh::{BuildOptions, Mesh};

    /// Depth by recursion from the root, independent of `check_tree`'s forward sweep.
    fn depth_by_recursion(nodes: &[WideNode], i: usize) -> u32 {
        let n = &nodes[i];
        let mut below = 0;
        let mut k = 0;
        for s in 0..WIDTH {
            if n.imask() & (1 << s) != 0 {
                below = below.max(depth_by_recursion(nodes, (n.child_base + k) as usize));
                k += 1;
            }
        }
        1 + below
    }

    #[test]
    fn check_tree_measures_depth_and_accepts_built_trees() {
        for (seed, count) in [(1u64, 1usize), (2, 40), (3, 3000)] {
            let mesh = Mesh::random_soup(seed, count, 10.0, 2.0);
            let blas = Blas::from_mesh("soup", &mesh, &BuildOptions::default()).unwrap();
            let depth = check_tree("soup", &blas.nodes, blas.triangles.len()).unwrap();
            assert_eq!(depth, depth_by_recursion(&blas.nodes, 0));
            assert_eq!(depth, blas.stats.depth);
            // One primitive fewer than the leaves reference is refused.
            assert!(check_tree("soup", &blas.nodes, blas.triangles.len() - 1).is_err());
        }
        assert_eq!(check_tree("empty", &[], 0).unwrap(), 0);
    }

    #[test]
    fn a_leaf_past_the_nodes_24_primitive_bits_is_refused() {
        // Offset 22 with 3 primitives would set bit 24, which the kernel reads as a child node.
        let mut n = WideNode::default();
        n.set_meta(0, 0b111_00000 | 22);
        let e = check_tree("t", &[n], 100).unwrap_err().to_string();
        assert!(e.contains("past the node's 24"), "{e}");
        n.set_meta(0, 0b111_00000 | 21);
        assert_eq!(check_tree("t", &[n], 100).unwrap(), 1);
    }
}
