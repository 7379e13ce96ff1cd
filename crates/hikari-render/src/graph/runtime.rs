//! What outlives a frame (pool, history, persistent resources, caches) and the execution of
//! a recorded frame.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use super::readback::{self, ImageRgba32};
use super::resources::{
    PhysicalBuffer, PhysicalTexture, Pool, PoolStats, TextureDesc, ViewKey, next_id,
};
use super::timing::{GpuTimer, PassTiming};
use super::{Binding, FrameGraph, PassKind, PassResources, Res, SamplerKind, Tex, TexSource};
use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::pipeline::{BindingKind, PipelineInfo};

/// The two textures of a temporal resource for this frame; see
/// [`FrameGraph::history_texture`].
#[derive(Clone, Copy, Debug)]
pub struct History {
    pub prev: Tex,
    pub cur: Tex,
    pub valid: bool,
}

/// What one executed frame reports.
#[derive(Debug, Default)]
pub struct FrameResult {
    pub frame: u64,
    /// One entry per pass, in execution order.
    pub timings: Vec<PassTiming>,
    /// GPU time from the first pass's start to the last pass's end.
    pub gpu_span_ms: Option<f64>,
    /// CPU time of `execute` up to submission (allocation, bind groups, encoding).
    pub cpu_encode_us: f64,
    /// Textures asked for with `readback` or `--dump`.
    pub images: Vec<ImageRgba32>,
    /// Buffers asked for with `readback` or `--dump`, as raw bytes.
    pub buffers: Vec<(String, Vec<u8>)>,
    /// Which physical texture each used texture got, by name: equal ids share memory.
    pub allocations: Vec<(String, u64)>,
}

impl FrameResult {
    /// Removes and returns the read-back image of the resource named `name`.
    pub fn take_image(&mut self, name: &str) -> Option<ImageRgba32> {
        let i = self.images.iter().position(|i| i.name == name)?;
        Some(self.images.remove(i))
    }

    /// The read-back bytes of the buffer named `name`.
    pub fn buffer(&self, name: &str) -> Option<&[u8]> {
        self.buffers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, b)| b.as_slice())
    }
}

impl FrameResult {
    pub fn image(&self, name: &str) -> Option<&ImageRgba32> {
        self.images.iter().find(|i| i.name == name)
    }
}

struct HistoryEntry {
    desc: TextureDesc,
    textures: [Arc<PhysicalTexture>; 2],
    parity: usize,
    frames_written: u64,
    used: bool,
}

/// Everything the frame graph keeps between frames. Make one per renderer.
pub struct GraphRuntime {
    pub(crate) frame: u64,
    pool: Pool,
    persistent_textures: HashMap<String, Arc<PhysicalTexture>>,
    persistent_buffers: HashMap<String, Arc<PhysicalBuffer>>,
    history: HashMap<String, HistoryEntry>,
    imported_textures: HashMap<wgpu::Texture, (Arc<PhysicalTexture>, u64)>,
    imported_buffers: HashMap<wgpu::Buffer, (Arc<PhysicalBuffer>, u64)>,
    bind_groups: HashMap<Vec<u64>, wgpu::BindGroup>,
    constants: Option<Arc<PhysicalBuffer>>,
    samplers: HashMap<SamplerKind, (u64, wgpu::Sampler)>,
    timer: Option<GpuTimer>,
    timestamps: TimestampMode,
    dumps: Vec<String>,
}

/// How much of the frame gets GPU timestamps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimestampMode {
    /// None at all.
    Off,
    /// One at the start of the first pass and one at the end of the last: the frame's span
    /// without the cost of timing each pass.
    Frame,
    /// At the start and end of every pass.
    Pass,
}

/// Frames an imported resource is remembered after its last import.
const IMPORT_KEEP_FRAMES: u64 = 4;
/// Bind groups kept before the cache starts over.
const BIND_CACHE_MAX: usize = 4096;

impl Default for GraphRuntime {
    fn default() -> Self {
        Self::new()
    }
}

impl GraphRuntime {
    pub fn new() -> Self {
        Self {
            frame: 0,
            pool: Pool::default(),
            persistent_textures: HashMap::new(),
            persistent_buffers: HashMap::new(),
            history: HashMap::new(),
            imported_textures: HashMap::new(),
            imported_buffers: HashMap::new(),
            bind_groups: HashMap::new(),
            constants: None,
            samplers: HashMap::new(),
            timer: None,
            timestamps: TimestampMode::Pass,
            dumps: Vec::new(),
        }
    }

    /// How the GPU is timed (per pass by default, when the device supports timestamps).
    pub fn set_timestamps(&mut self, mode: TimestampMode) {
        self.timestamps = mode;
    }

    /// Names of resources to read back after each frame (`--dump gbuffer.normal`). A name that
    /// no resource of the frame has is an error at `execute`, listing the names there are.
    pub fn set_dumps(&mut self, names: Vec<String>) {
        self.dumps = names;
    }

    pub fn pool_stats(&self) -> PoolStats {
        self.pool.stats
    }

    pub fn begin_frame<'r>(&'r mut self, ctx: &'r GpuContext) -> FrameGraph<'r> {
        FrameGraph {
            ctx,
            rt: self,
            textures: Vec::new(),
            buffers: Vec::new(),
            passes: Vec::new(),
            constants: Vec::new(),
            readbacks: Vec::new(),
        }
    }

    pub(crate) fn persistent_texture(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        desc: TextureDesc,
    ) -> (Arc<PhysicalTexture>, bool) {
        if let Some(p) = self.persistent_textures.get(name)
            && p.desc == desc
        {
            return (p.clone(), false);
        }
        let p = PhysicalTexture::create(ctx, name, desc);
        self.persistent_textures.insert(name.into(), p.clone());
        self.bind_groups.clear();
        (p, true)
    }

    pub(crate) fn persistent_buffer(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        size: u64,
    ) -> (Arc<PhysicalBuffer>, bool) {
        if let Some(p) = self.persistent_buffers.get(name)
            && p.size == size
        {
            return (p.clone(), false);
        }
        let p = PhysicalBuffer::create(ctx, name, size);
        self.persistent_buffers.insert(name.into(), p.clone());
        self.bind_groups.clear();
        (p, true)
    }

    pub(crate) fn history_texture(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        desc: TextureDesc,
    ) -> (Arc<PhysicalTexture>, Arc<PhysicalTexture>, bool) {
        let fresh = self.history.get(name).is_none_or(|h| h.desc != desc);
        if fresh {
            self.bind_groups.clear();
            self.history.insert(
                name.into(),
                HistoryEntry {
                    desc,
                    textures: [
                        PhysicalTexture::create(ctx, &format!("{name}.a"), desc),
                        PhysicalTexture::create(ctx, &format!("{name}.b"), desc),
                    ],
                    parity: 0,
                    frames_written: 0,
                    used: false,
                },
            );
        }
        let h = self.history.get_mut(name).unwrap();
        h.used = true;
        (
            h.textures[h.parity].clone(),
            h.textures[1 - h.parity].clone(),
            h.frames_written > 0,
        )
    }

    pub(crate) fn imported_texture(
        &mut self,
        texture: &wgpu::Texture,
        desc: TextureDesc,
    ) -> Arc<PhysicalTexture> {
        let frame = self.frame;
        let e = self
            .imported_textures
            .entry(texture.clone())
            .or_insert_with(|| (PhysicalTexture::wrap(texture.clone(), desc), frame));
        e.1 = frame;
        e.0.clone()
    }

    pub(crate) fn imported_buffer(&mut self, buffer: &wgpu::Buffer) -> Arc<PhysicalBuffer> {
        let frame = self.frame;
        let e = self
            .imported_buffers
            .entry(buffer.clone())
            .or_insert_with(|| {
                (
                    Arc::new(PhysicalBuffer {
                        id: next_id(),
                        size: buffer.size(),
                        buffer: buffer.clone(),
                    }),
                    frame,
                )
            });
        e.1 = frame;
        e.0.clone()
    }

    fn sampler(&mut self, ctx: &GpuContext, kind: SamplerKind) -> (u64, wgpu::Sampler) {
        self.samplers
            .entry(kind)
            .or_insert_with(|| {
                let (filter, address, compare) = match kind {
                    SamplerKind::LinearClamp => (
                        wgpu::FilterMode::Linear,
                        wgpu::AddressMode::ClampToEdge,
                        None,
                    ),
                    SamplerKind::NearestClamp => (
                        wgpu::FilterMode::Nearest,
                        wgpu::AddressMode::ClampToEdge,
                        None,
                    ),
                    SamplerKind::NearestRepeat => {
                        (wgpu::FilterMode::Nearest, wgpu::AddressMode::Repeat, None)
                    }
                    SamplerKind::LinearRepeat => {
                        (wgpu::FilterMode::Linear, wgpu::AddressMode::Repeat, None)
                    }
                    SamplerKind::ShadowCompare => (
                        wgpu::FilterMode::Linear,
                        wgpu::AddressMode::ClampToEdge,
                        Some(wgpu::CompareFunction::GreaterEqual),
                    ),
                };
                let s = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("hikari.sampler"),
                    address_mode_u: address,
                    address_mode_v: address,
                    address_mode_w: address,
                    mag_filter: filter,
                    min_filter: filter,
                    mipmap_filter: if filter == wgpu::FilterMode::Linear {
                        wgpu::MipmapFilterMode::Linear
                    } else {
                        wgpu::MipmapFilterMode::Nearest
                    },
                    compare,
                    ..Default::default()
                });
                (next_id(), s)
            })
            .clone()
    }

    fn bind_group(
        &mut self,
        ctx: &GpuContext,
        info: &PipelineInfo,
        bindings: &[Binding],
        res: &PassResources<'_>,
    ) -> wgpu::BindGroup {
        let constants = self.constants.clone();
        let mut key: Vec<u64> = Vec::with_capacity(1 + bindings.len() * 2);
        key.push(info.id);
        for (b, slot) in bindings.iter().zip(&info.slots) {
            match b {
                Binding::Texture(t) => {
                    key.push(res.textures[t.0 as usize].physical.as_ref().unwrap().id);
                    key.push(matches!(slot.kind, BindingKind::StorageTexture { .. }) as u64);
                }
                Binding::Buffer(bf) => {
                    key.push(res.buffers[bf.0 as usize].physical.as_ref().unwrap().id)
                }
                Binding::Constants { offset, .. } => {
                    key.push(constants.as_ref().unwrap().id);
                    key.push(*offset);
                }
                Binding::Sampler(s) => key.push(self.sampler(ctx, *s).0),
            }
        }
        if let Some(bg) = self.bind_groups.get(&key) {
            return bg.clone();
        }
        if self.bind_groups.len() >= BIND_CACHE_MAX {
            self.bind_groups.clear();
        }
        let mut views = Vec::new();
        let mut samplers = Vec::new();
        for (b, slot) in bindings.iter().zip(&info.slots) {
            match (b, &slot.kind) {
                (Binding::Texture(t), BindingKind::SampledTexture { view, .. }) => {
                    let p = res.textures[t.0 as usize].physical.as_ref().unwrap();
                    views.push(p.view(ViewKey {
                        dimension: *view,
                        single_mip: false,
                    }));
                }
                (Binding::Texture(t), BindingKind::StorageTexture { view, .. }) => {
                    let p = res.textures[t.0 as usize].physical.as_ref().unwrap();
                    views.push(p.view(ViewKey {
                        dimension: *view,
                        single_mip: true,
                    }));
                }
                (Binding::Sampler(s), _) => samplers.push(self.sampler(ctx, *s).1),
                _ => {}
            }
        }
        let (mut vi, mut si) = (0, 0);
        let entries: Vec<wgpu::BindGroupEntry> = bindings
            .iter()
            .zip(&info.slots)
            .map(|(b, slot)| wgpu::BindGroupEntry {
                binding: slot.binding,
                resource: match b {
                    Binding::Texture(_) => {
                        vi += 1;
                        wgpu::BindingResource::TextureView(&views[vi - 1])
                    }
                    Binding::Buffer(bf) => res.buffers[bf.0 as usize]
                        .physical
                        .as_ref()
                        .unwrap()
                        .buffer
                        .as_entire_binding(),
                    Binding::Constants { offset, size } => {
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &constants.as_ref().unwrap().buffer,
                            offset: *offset,
                            size: std::num::NonZeroU64::new(*size),
                        })
                    }
                    Binding::Sampler(_) => {
                        si += 1;
                        wgpu::BindingResource::Sampler(&samplers[si - 1])
                    }
                },
            })
            .collect();
        let bg = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&info.label),
            layout: &info.bind_group_layout,
            entries: &entries,
        });
        self.bind_groups.insert(key, bg.clone());
        bg
    }
}

/// Finds the resources `--dump` names; unknown names are an error that lists the known ones.
fn dump_requests(g: &FrameGraph<'_>) -> Result<Vec<Res>> {
    let mut out = Vec::new();
    for want in &g.rt.dumps {
        let t = g
            .textures
            .iter()
            .position(|t| &t.name == want && t.first.is_some());
        let b = g
            .buffers
            .iter()
            .position(|b| &b.name == want && b.first.is_some());
        match (t, b) {
            (Some(t), _) => out.push(Res::Tex(Tex(t as u32))),
            (None, Some(b)) => out.push(Res::Buf(super::Buf(b as u32))),
            (None, None) => {
                let mut names: Vec<&str> = g
                    .textures
                    .iter()
                    .filter(|t| t.first.is_some())
                    .map(|t| t.name.as_str())
                    .chain(
                        g.buffers
                            .iter()
                            .filter(|b| b.first.is_some())
                            .map(|b| b.name.as_str()),
                    )
                    .collect();
                names.sort();
                names.dedup();
                return Err(RenderError::Graph(format!(
                    "--dump {want}: no resource of that name in this frame; there are: {}",
                    names.join(", ")
                )));
            }
        }
    }
    Ok(out)
}

pub(crate) fn execute(mut g: FrameGraph<'_>) -> Result<FrameResult> {
    let t_start = Instant::now();
    let ctx = g.ctx;
    let n = g.passes.len();

    let mut copies = g.readbacks.clone();
    copies.extend(dump_requests(&g)?);
    copies.dedup();
    for r in &copies {
        let (first, last, written, name) = match *r {
            Res::Tex(t) => {
                let v = &mut g.textures[t.0 as usize];
                (&mut v.first, &mut v.last, v.written, &v.name)
            }
            Res::Buf(b) => {
                let v = &mut g.buffers[b.0 as usize];
                (&mut v.first, &mut v.last, v.written, &v.name)
            }
        };
        if !written {
            return Err(RenderError::Graph(format!(
                "read back of `{name}`, which no pass wrote"
            )));
        }
        // Keep it alive to the end of the frame so nothing else is placed in its memory.
        first.get_or_insert(n);
        *last = Some(n);
    }
    for r in &copies {
        if let Res::Tex(t) = r {
            let v = &g.textures[t.0 as usize];
            if readback::texel_bytes(v.desc.format).is_none() {
                return Err(RenderError::Graph(format!(
                    "cannot read back `{}`: format {:?}",
                    v.name, v.desc.format
                )));
            }
        }
    }

    let FrameGraph {
        rt,
        mut textures,
        mut buffers,
        passes,
        constants,
        ..
    } = g;

    // Pass constants go up in one write before the frame's commands.
    if !constants.is_empty() {
        let need = (constants.len() as u64 + 256).next_power_of_two();
        if rt.constants.as_ref().is_none_or(|c| c.size < need) {
            rt.constants = Some(PhysicalBuffer::create(ctx, "hikari.constants", need));
            rt.bind_groups.clear();
        }
        ctx.queue
            .write_buffer(&rt.constants.as_ref().unwrap().buffer, 0, &constants);
    }

    let timed = |k: &PassKind| !matches!(k, PassKind::Encoder { .. });
    let timed_count = passes.iter().filter(|p| timed(&p.kind)).count() as u32;
    let mode = rt.timestamps;
    if mode != TimestampMode::Off && rt.timer.as_ref().is_none_or(|t| t.passes() < timed_count) {
        rt.timer = GpuTimer::new(ctx, timed_count);
    }
    let use_timer = mode != TimestampMode::Off && rt.timer.is_some() && timed_count > 0;
    // Query slots for the timed pass `slot`: its own pair, or in frame mode only the frame's
    // first begin (query 0) and last end (query 1).
    let queries = |slot: u32| -> (Option<u32>, Option<u32>) {
        match mode {
            TimestampMode::Pass => (Some(2 * slot), Some(2 * slot + 1)),
            _ => (
                (slot == 0).then_some(0),
                (slot + 1 == timed_count).then_some(1),
            ),
        }
    };

    // Lifetimes -> when each transient is taken from and given back to the pool.
    let mut acquire_at: Vec<Vec<Res>> = vec![Vec::new(); n + 1];
    let mut release_at: Vec<Vec<Res>> = vec![Vec::new(); n + 1];
    for (i, t) in textures.iter().enumerate() {
        if let (TexSource::Transient, Some(f), Some(l)) = (t.source, t.first, t.last) {
            acquire_at[f].push(Res::Tex(Tex(i as u32)));
            release_at[l].push(Res::Tex(Tex(i as u32)));
        }
    }
    for (i, b) in buffers.iter().enumerate() {
        if let (true, Some(f), Some(l)) = (b.transient, b.first, b.last) {
            acquire_at[f].push(Res::Buf(super::Buf(i as u32)));
            release_at[l].push(Res::Buf(super::Buf(i as u32)));
        }
    }
    let frame = rt.frame;
    let acquire = |rt: &mut GraphRuntime,
                   list: &[Res],
                   textures: &mut [super::VirtualTexture],
                   buffers: &mut [super::VirtualBuffer]| {
        for r in list {
            match *r {
                Res::Tex(t) => {
                    let v = &mut textures[t.0 as usize];
                    v.physical = Some(rt.pool.acquire_texture(ctx, &v.name, v.desc, frame));
                }
                Res::Buf(b) => {
                    let v = &mut buffers[b.0 as usize];
                    v.physical = Some(rt.pool.acquire_buffer(ctx, &v.name, v.size, frame));
                }
            }
        }
    };
    let release = |rt: &mut GraphRuntime,
                   list: &[Res],
                   textures: &[super::VirtualTexture],
                   buffers: &[super::VirtualBuffer]| {
        for r in list {
            match *r {
                Res::Tex(t) => rt
                    .pool
                    .release_texture(textures[t.0 as usize].physical.as_ref().unwrap().id),
                Res::Buf(b) => rt
                    .pool
                    .release_buffer(buffers[b.0 as usize].physical.as_ref().unwrap().id),
            }
        }
    };

    // Without per-pass timestamps, consecutive compute passes share one wgpu compute pass:
    // wgpu still places the barriers each dispatch needs, and the GPU skips a pass boundary.
    let merge = mode != TimestampMode::Pass;
    let mut run_end: Vec<usize> = (0..n).collect();
    for i in (0..n.saturating_sub(1)).rev() {
        let both_compute = matches!(passes[i].kind, PassKind::Compute { .. })
            && matches!(passes[i + 1].kind, PassKind::Compute { .. });
        if merge && both_compute {
            run_end[i] = run_end[i + 1];
        }
    }

    let mut encoder = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("hikari.frame"),
        });
    let mut timings = Vec::with_capacity(n);
    let mut slot = 0u32;
    let mut open_compute: Option<wgpu::ComputePass<'static>> = None;
    for (i, pass) in passes.into_iter().enumerate() {
        acquire(rt, &acquire_at[i], &mut textures, &mut buffers);
        let tp = Instant::now();
        let res = PassResources {
            textures: &textures,
            buffers: &buffers,
        };
        let is_timed = timed(&pass.kind);
        if !matches!(pass.kind, PassKind::Compute { .. }) {
            drop(open_compute.take());
        }
        match pass.kind {
            PassKind::Compute { pipeline, groups } => {
                let bg = rt.bind_group(ctx, &pipeline.info, &pass.bindings, &res);
                if open_compute.is_none() || !merge {
                    // The encoder accepts a new pass only once the previous one has ended.
                    drop(open_compute.take());
                    let last_slot = slot + (run_end[i] - i) as u32;
                    let q = match mode {
                        TimestampMode::Pass => queries(slot),
                        _ => (
                            (slot == 0).then_some(0),
                            (last_slot + 1 == timed_count).then_some(1),
                        ),
                    };
                    let timer = if use_timer { rt.timer.as_ref() } else { None };
                    let label = if run_end[i] == i {
                        pass.name.as_str()
                    } else {
                        "hikari.compute"
                    };
                    let cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some(label),
                        timestamp_writes: timer.and_then(|t| t.compute_writes(q)),
                    });
                    open_compute = Some(cp.forget_lifetime());
                }
                let cp = open_compute.as_mut().unwrap();
                cp.set_pipeline(&pipeline.pipeline);
                cp.set_bind_group(0, &bg, &[]);
                if groups.iter().all(|&g| g > 0) {
                    cp.dispatch_workgroups(groups[0], groups[1], groups[2]);
                }
            }
            PassKind::Raster {
                pipeline,
                colors,
                depth,
                record,
            } => {
                let bg = rt.bind_group(ctx, &pipeline.info, &pass.bindings, &res);
                let timer = if use_timer { rt.timer.as_ref() } else { None };
                let attach = |t: Tex| {
                    res.textures[t.0 as usize]
                        .physical
                        .as_ref()
                        .unwrap()
                        .view(ViewKey {
                            dimension: wgpu::TextureViewDimension::D2,
                            single_mip: true,
                        })
                };
                let color_views: Vec<(wgpu::TextureView, Option<[f64; 4]>)> =
                    colors.iter().map(|(t, c)| (attach(*t), *c)).collect();
                let depth_view = depth.map(|(t, c)| (attach(t), c));
                let color_attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = color_views
                    .iter()
                    .map(|(v, clear)| {
                        Some(wgpu::RenderPassColorAttachment {
                            view: v,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: match clear {
                                    Some([r, g, b, a]) => wgpu::LoadOp::Clear(wgpu::Color {
                                        r: *r,
                                        g: *g,
                                        b: *b,
                                        a: *a,
                                    }),
                                    None => wgpu::LoadOp::Load,
                                },
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    })
                    .collect();
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&pass.name),
                    color_attachments: &color_attachments,
                    depth_stencil_attachment: depth_view.as_ref().map(|(v, clear)| {
                        wgpu::RenderPassDepthStencilAttachment {
                            view: v,
                            depth_ops: Some(wgpu::Operations {
                                load: match clear {
                                    Some(d) => wgpu::LoadOp::Clear(*d),
                                    None => wgpu::LoadOp::Load,
                                },
                                store: wgpu::StoreOp::Store,
                            }),
                            stencil_ops: None,
                        }
                    }),
                    timestamp_writes: timer.and_then(|t| t.render_writes(queries(slot))),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(&pipeline.pipeline);
                rp.set_bind_group(0, &bg, &[]);
                record(&mut rp, &res);
            }
            PassKind::Encoder { record } => record(&mut encoder, &res),
        }
        timings.push((
            pass.name,
            is_timed.then_some(slot),
            tp.elapsed().as_secs_f64() * 1e6,
        ));
        if is_timed {
            slot += 1;
        }
        release(rt, &release_at[i], &textures, &buffers);
    }
    drop(open_compute);
    // Readbacks of resources no pass touched never reach here (checked above), but a
    // persistent one could be first used at `n`: make sure it is resolved.
    acquire(rt, &acquire_at[n], &mut textures, &mut buffers);

    let mut staging = Vec::new();
    for r in &copies {
        match *r {
            Res::Tex(t) => {
                let v = &textures[t.0 as usize];
                let row = readback::padded_row_bytes(&v.desc).unwrap();
                let rows = v.desc.size[1] * v.desc.size[2];
                let buf = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("hikari.readback"),
                    size: row as u64 * rows as u64,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let aspect = if v.desc.format.is_depth_stencil_format() {
                    wgpu::TextureAspect::DepthOnly
                } else {
                    wgpu::TextureAspect::All
                };
                encoder.copy_texture_to_buffer(
                    wgpu::TexelCopyTextureInfo {
                        texture: &v.physical.as_ref().unwrap().texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d::ZERO,
                        aspect,
                    },
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buf,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(row),
                            rows_per_image: Some(v.desc.size[1]),
                        },
                    },
                    v.desc.extent(),
                );
                staging.push((*r, buf));
            }
            Res::Buf(b) => {
                let v = &buffers[b.0 as usize];
                let p = v.physical.as_ref().unwrap();
                let buf = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("hikari.readback"),
                    size: p.size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(&p.buffer, 0, &buf, 0, p.size);
                staging.push((*r, buf));
            }
        }
    }
    let query_pairs = if mode == TimestampMode::Pass { slot } else { 1 };
    if use_timer {
        rt.timer
            .as_ref()
            .unwrap()
            .resolve(&mut encoder, query_pairs);
    }
    let cpu_encode_us = t_start.elapsed().as_secs_f64() * 1e6;
    ctx.queue.submit([encoder.finish()]);

    let (gpu, gpu_span_ms) = if use_timer {
        let (pairs, span) = rt.timer.as_ref().unwrap().read(ctx, query_pairs)?;
        match mode {
            TimestampMode::Pass => (pairs, span),
            _ => (vec![None; slot as usize], pairs[0]),
        }
    } else {
        (vec![None; slot as usize], None)
    };
    let timings = timings
        .into_iter()
        .map(|(name, s, cpu_us)| PassTiming {
            name,
            gpu_ms: s.and_then(|s| gpu[s as usize]),
            cpu_us,
        })
        .collect();

    for (_, buf) in &staging {
        buf.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    }
    if !staging.is_empty() {
        ctx.wait_idle()?;
    }
    let mut images = Vec::new();
    let mut out_buffers = Vec::new();
    for (r, buf) in staging {
        let data = buf
            .slice(..)
            .get_mapped_range()
            .map_err(|e| RenderError::Gpu {
                during: "read back".into(),
                message: e.to_string(),
            })?
            .to_vec();
        match r {
            Res::Tex(t) => {
                let v = &textures[t.0 as usize];
                images.push(readback::decode_image(&v.name, &v.desc, &data)?);
            }
            Res::Buf(b) => out_buffers.push((buffers[b.0 as usize].name.clone(), data)),
        }
    }

    let allocations = textures
        .iter()
        .filter_map(|t| t.physical.as_ref().map(|p| (t.name.clone(), p.id)))
        .collect();

    for h in rt.history.values_mut() {
        if std::mem::take(&mut h.used) {
            h.parity = 1 - h.parity;
            h.frames_written += 1;
        }
    }
    let result = FrameResult {
        frame: rt.frame,
        timings,
        gpu_span_ms,
        cpu_encode_us,
        images,
        buffers: out_buffers,
        allocations,
    };
    rt.frame += 1;
    let f = rt.frame;
    let before = rt.imported_buffers.len() + rt.imported_textures.len();
    rt.imported_buffers
        .retain(|_, (_, last)| f - *last <= IMPORT_KEEP_FRAMES);
    rt.imported_textures
        .retain(|_, (_, last)| f - *last <= IMPORT_KEEP_FRAMES);
    let pruned = before != rt.imported_buffers.len() + rt.imported_textures.len();
    if rt.pool.trim(f) || pruned {
        // Cached bind groups hold their resources alive; start over so freed memory goes.
        rt.bind_groups.clear();
    }
    Ok(result)
}
