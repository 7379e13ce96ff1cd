//! Running a recorded frame, in the steps a reader can follow: find what to read back, upload
//! the pass constants, plan timestamps and transient lifetimes, encode the passes (taking
//! transients from the pool as their lifetimes begin), encode the read-backs, submit, and
//! read timings and resources back. Temporal state does not advance here: the frame is
//! committed ([`GraphRuntime::commit_frame`]) once its owner accepts it.

use std::time::Instant;

use super::poison;
use super::readback::{self, ImageRgba32};
use super::resources::{PhysicalBuffer, ViewKey};
use super::runtime::{FrameResult, GraphRuntime, TimestampMode};
use super::timing::PassTiming;
use super::{
    Buf, FrameGraph, PassKind, PassNode, PassResources, Res, Tex, TexSource, VirtualBuffer,
    VirtualTexture,
};
use crate::context::GpuContext;
use crate::error::{RenderError, Result};

pub(crate) fn execute(mut g: FrameGraph<'_>, commit: bool) -> Result<FrameResult> {
    let t_start = Instant::now();
    let ctx = g.ctx;
    let late: Vec<Buf> = std::mem::take(&mut g.late_readbacks);
    if g.rt.wait_for_readbacks {
        g.readbacks.extend(late.iter().map(|b| Res::Buf(*b)));
    }
    let late = if g.rt.wait_for_readbacks {
        vec![]
    } else {
        late
    };
    let copies = plan_readbacks(&mut g, &late)?;
    let FrameGraph {
        rt,
        mut textures,
        mut buffers,
        passes,
        constants,
        ..
    } = g;
    upload_constants(rt, ctx, &constants);
    let timing = TimestampPlan::new(rt, ctx, &passes);
    let lifetimes = Lifetimes::of(&textures, &buffers, passes.len());
    check_memory(ctx, &textures, &buffers, &lifetimes)?;

    let mut encoder = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("hikari.frame"),
        });
    let mut encoded = encode_passes(
        rt,
        ctx,
        &mut encoder,
        passes,
        &timing,
        &lifetimes,
        &mut textures,
        &mut buffers,
    );
    let staging = encode_readbacks(ctx, &mut encoder, &copies, &textures, &buffers);
    let late_staging: Vec<(Res, wgpu::Buffer)> = {
        let late: Vec<Res> = late.iter().map(|b| Res::Buf(*b)).collect();
        encode_readbacks(ctx, &mut encoder, &late, &textures, &buffers)
    };
    if timing.enabled {
        rt.timer
            .as_ref()
            .unwrap()
            .resolve(&mut encoder, timing.query_pairs(encoded.slots));
    }
    let cpu_encode_us = t_start.elapsed().as_secs_f64() * 1e6;
    ctx.queue.submit([encoder.finish()]);

    let reads = std::mem::take(&mut encoded.reads);
    let poisoned = encoded.poisoned.take();
    let (timings, gpu_span_ms) = read_timings(rt, ctx, &timing, encoded)?;
    let (images, mut out_buffers) = read_back(ctx, staging, &textures, &buffers)?;
    out_buffers.extend(collect_late(rt, ctx)?);
    for (r, buf) in late_staging {
        let Res::Buf(b) = r else { continue };
        let ready = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let flag = ready.clone();
        buf.slice(..).map_async(wgpu::MapMode::Read, move |_| {
            flag.store(true, std::sync::atomic::Ordering::Release)
        });
        rt.pending
            .push((buffers[b.0 as usize].name.clone(), buf, ready));
    }
    let allocations = textures
        .iter()
        .filter_map(|t| t.physical.as_ref().map(|p| (t.name.clone(), p.id)))
        .collect();
    let result = FrameResult {
        frame: rt.frame,
        timings,
        gpu_span_ms,
        cpu_encode_us,
        images,
        buffers: out_buffers,
        allocations,
        reads,
        poisoned,
    };
    if commit {
        rt.commit_frame();
    }
    Ok(result)
}

/// What `readback` and `--dump` ask for, checked and kept alive (with the late read-backs) to
/// the end of the frame.
fn plan_readbacks(g: &mut FrameGraph<'_>, late: &[Buf]) -> Result<Vec<Res>> {
    let n = g.passes.len();
    let mut copies = g.readbacks.clone();
    copies.extend(dump_requests(g)?);
    copies.dedup();
    let late: Vec<Res> = late.iter().map(|b| Res::Buf(*b)).collect();
    for r in copies.iter().chain(&late) {
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
    Ok(copies)
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
            (None, Some(b)) => out.push(Res::Buf(Buf(b as u32))),
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

/// Pass constants go up in one write before the frame's commands.
fn upload_constants(rt: &mut GraphRuntime, ctx: &GpuContext, constants: &[u8]) {
    if constants.is_empty() {
        return;
    }
    let need = (constants.len() as u64 + 256).next_power_of_two();
    if rt.constants.as_ref().is_none_or(|c| c.size < need) {
        rt.constants = Some(PhysicalBuffer::create(ctx, "hikari.constants", need));
        rt.bind_groups.clear();
    }
    ctx.queue
        .write_buffer(&rt.constants.as_ref().unwrap().buffer, 0, constants);
}

/// Which passes get timestamps, and whether consecutive compute passes share a wgpu pass.
struct TimestampPlan {
    mode: TimestampMode,
    enabled: bool,
    /// Passes that are timed (all but encoder passes).
    timed_count: u32,
    /// Per pass: the last pass of the run of compute passes it is merged into.
    run_end: Vec<usize>,
}

impl TimestampPlan {
    fn new(rt: &mut GraphRuntime, ctx: &GpuContext, passes: &[PassNode<'_>]) -> Self {
        let timed_count = passes.iter().filter(|p| is_timed(&p.kind)).count() as u32;
        let mode = rt.timestamps;
        if mode != TimestampMode::Off && rt.timer.as_ref().is_none_or(|t| t.passes() < timed_count)
        {
            rt.timer = super::timing::GpuTimer::new(ctx, timed_count);
        }
        let enabled = mode != TimestampMode::Off && rt.timer.is_some() && timed_count > 0;
        // Without per-pass timestamps, consecutive compute passes share one wgpu compute pass:
        // wgpu still places the barriers each dispatch needs, and the GPU skips a pass boundary.
        let n = passes.len();
        let merge = mode != TimestampMode::Pass;
        let mut run_end: Vec<usize> = (0..n).collect();
        for i in (0..n.saturating_sub(1)).rev() {
            let both_compute = matches!(passes[i].kind, PassKind::Compute { .. })
                && matches!(passes[i + 1].kind, PassKind::Compute { .. });
            if merge && both_compute {
                run_end[i] = run_end[i + 1];
            }
        }
        Self {
            mode,
            enabled,
            timed_count,
            run_end,
        }
    }

    fn merges(&self) -> bool {
        self.mode != TimestampMode::Pass
    }

    /// Query slots of the timed pass `slot`: its own pair, or in frame mode only the frame's
    /// first begin (query 0) and last end (query 1).
    fn queries(&self, slot: u32) -> (Option<u32>, Option<u32>) {
        match self.mode {
            TimestampMode::Pass => (Some(2 * slot), Some(2 * slot + 1)),
            _ => (
                (slot == 0).then_some(0),
                (slot + 1 == self.timed_count).then_some(1),
            ),
        }
    }

    /// Queries of a merged run of compute passes from `slot` to `last_slot`.
    fn run_queries(&self, slot: u32, last_slot: u32) -> (Option<u32>, Option<u32>) {
        match self.mode {
            TimestampMode::Pass => self.queries(slot),
            _ => (
                (slot == 0).then_some(0),
                (last_slot + 1 == self.timed_count).then_some(1),
            ),
        }
    }

    fn query_pairs(&self, slots: u32) -> u32 {
        if self.mode == TimestampMode::Pass {
            slots
        } else {
            1
        }
    }
}

fn is_timed(k: &PassKind<'_>) -> bool {
    !matches!(k, PassKind::Encoder { .. })
}

/// When each transient is taken from and given back to the pool: index `i` lists what pass
/// `i` takes first and gives back last (`n`: the read-backs after the last pass).
struct Lifetimes {
    acquire_at: Vec<Vec<Res>>,
    release_at: Vec<Vec<Res>>,
}

impl Lifetimes {
    fn of(textures: &[VirtualTexture], buffers: &[VirtualBuffer], n: usize) -> Self {
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
                acquire_at[f].push(Res::Buf(Buf(i as u32)));
                release_at[l].push(Res::Buf(Buf(i as u32)));
            }
        }
        Self {
            acquire_at,
            release_at,
        }
    }

    fn acquire(
        &self,
        at: usize,
        rt: &mut GraphRuntime,
        ctx: &GpuContext,
        textures: &mut [VirtualTexture],
        buffers: &mut [VirtualBuffer],
    ) {
        let frame = rt.frame;
        for r in &self.acquire_at[at] {
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
    }

    fn release(
        &self,
        at: usize,
        rt: &mut GraphRuntime,
        textures: &[VirtualTexture],
        buffers: &[VirtualBuffer],
    ) {
        for r in &self.release_at[at] {
            match *r {
                Res::Tex(t) => rt
                    .pool
                    .release_texture(textures[t.0 as usize].physical.as_ref().unwrap().id),
                Res::Buf(b) => rt
                    .pool
                    .release_buffer(buffers[b.0 as usize].physical.as_ref().unwrap().id),
            }
        }
    }
}

/// Bytes a texture takes, every mip level and layer (formats without a copy size, depth and
/// stencil, counted at 4 bytes a texel).
fn texture_bytes(v: &VirtualTexture) -> u64 {
    let block = u64::from(v.desc.format.block_copy_size(None).unwrap_or(4));
    let [w, h, d] = v.desc.size.map(u64::from);
    (0..v.desc.mip_levels)
        .map(|m| {
            let depth = if v.desc.dimension == wgpu::TextureDimension::D3 {
                (d >> m).max(1)
            } else {
                d
            };
            (w >> m).max(1) * (h >> m).max(1) * depth * block
        })
        .sum()
}

/// Refuses a frame whose resources need more memory than the GPU has, before it runs: what
/// lives across frames, plus the most the transients need at once (they share memory by
/// lifetime, as the pool hands them out). Imported resources are the owner's and not counted.
fn check_memory(
    ctx: &GpuContext,
    textures: &[VirtualTexture],
    buffers: &[VirtualBuffer],
    lifetimes: &Lifetimes,
) -> Result<()> {
    let Some(limit) = ctx.memory_bytes else {
        return Ok(());
    };
    let mut kept = 0u64;
    let mut largest_name = String::new();
    let mut largest_bytes = 0u64;
    let mut consider = |bytes: u64, name: &str| {
        if bytes > largest_bytes {
            largest_bytes = bytes;
            largest_name = name.to_string();
        }
    };
    for t in textures {
        if matches!(
            t.source,
            TexSource::Persistent | TexSource::HistoryPrev | TexSource::HistoryCur
        ) {
            let b = texture_bytes(t);
            kept += b;
            consider(b, &t.name);
        }
    }
    for b in buffers
        .iter()
        .filter(|b| !b.transient && b.physical.is_some())
    {
        kept += b.size;
        consider(b.size, &b.name);
    }
    let (mut live, mut peak) = (0u64, 0u64);
    for at in 0..lifetimes.acquire_at.len() {
        for r in &lifetimes.acquire_at[at] {
            let bytes = match *r {
                Res::Tex(t) => texture_bytes(&textures[t.0 as usize]),
                Res::Buf(b) => buffers[b.0 as usize].size,
            };
            live += bytes;
            match *r {
                Res::Tex(t) => consider(bytes, &textures[t.0 as usize].name),
                Res::Buf(b) => consider(bytes, &buffers[b.0 as usize].name),
            }
        }
        peak = peak.max(live);
        for r in &lifetimes.release_at[at] {
            live -= match *r {
                Res::Tex(t) => texture_bytes(&textures[t.0 as usize]),
                Res::Buf(b) => buffers[b.0 as usize].size,
            };
        }
    }
    let need = kept + peak;
    if need > limit {
        return Err(RenderError::Limit {
            what: format!(
                "GPU memory in bytes that this frame's textures and buffers need (the largest: \
                 `{largest_name}`, {} MB)",
                largest_bytes / 1_000_000
            ),
            requested: need,
            limit,
        });
    }
    Ok(())
}

/// What encoding the passes leaves for reading timings: per pass its name, its timestamp
/// slot if timed, and its CPU encoding time.
struct Encoded {
    passes: Vec<(String, Option<u32>, f64, super::Traffic)>,
    slots: u32,
    reads: Vec<poison::PassReads>,
    poisoned: Option<poison::Poison>,
}

#[allow(clippy::too_many_arguments)]
fn encode_passes(
    rt: &mut GraphRuntime,
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    passes: Vec<PassNode<'_>>,
    timing: &TimestampPlan,
    lifetimes: &Lifetimes,
    textures: &mut [VirtualTexture],
    buffers: &mut [VirtualBuffer],
) -> Encoded {
    let n = passes.len();
    let mut out = Vec::with_capacity(n);
    let mut slot = 0u32;
    let mut open_compute: Option<wgpu::ComputePass<'static>> = None;
    let mut reads_out = Vec::new();
    let mut poisoned = None;
    for (i, pass) in passes.into_iter().enumerate() {
        let PassNode {
            name,
            kind,
            bindings,
            set_bindings,
        } = pass;
        lifetimes.acquire(i, rt, ctx, textures, buffers);
        let info = match &kind {
            PassKind::Compute { pipeline, .. } => Some(&pipeline.info),
            PassKind::Raster { pipeline, .. } => Some(&pipeline.info),
            PassKind::Encoder { .. } => None,
        };
        if let Some(info) = info.filter(|_| rt.record_reads || rt.poison.is_some()) {
            let reads = poison::reads_of(&name, info, &bindings, &set_bindings, textures);
            let target = rt.poison.as_ref().filter(|p| p.pass == name).and_then(|p| {
                textures
                    .iter()
                    .position(|v| v.name == p.texture)
                    .filter(|_| reads.textures.iter().any(|r| r.name == p.texture))
            });
            if let Some(t) = target {
                drop(open_compute.take());
                if poison::poison(ctx, encoder, &textures[t]) {
                    poisoned = rt.poison.take();
                }
            }
            if rt.record_reads {
                reads_out.push(reads);
            }
        }
        let traffic = info.map_or_else(Default::default, |info| {
            super::traffic::of_pass(info, &bindings, &set_bindings, textures, buffers)
        });
        let tp = Instant::now();
        let res = PassResources { textures, buffers };
        let timed = is_timed(&kind);
        if !matches!(kind, PassKind::Compute { .. }) {
            drop(open_compute.take());
        }
        match kind {
            PassKind::Compute { pipeline, groups } => {
                let bgs = rt.bind_groups_of(ctx, &pipeline.info, &bindings, &set_bindings, &res);
                let timer = rt.timer.as_ref().filter(|_| timing.enabled);
                if open_compute.is_none() || !timing.merges() {
                    // The encoder accepts a new pass only once the previous one has ended.
                    drop(open_compute.take());
                    let last_slot = slot + (timing.run_end[i] - i) as u32;
                    let label = if timing.run_end[i] == i {
                        name.as_str()
                    } else {
                        "hikari.compute"
                    };
                    let cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some(label),
                        timestamp_writes: timer
                            .and_then(|t| t.compute_writes(timing.run_queries(slot, last_slot))),
                    });
                    open_compute = Some(cp.forget_lifetime());
                }
                let cp = open_compute.as_mut().unwrap();
                cp.set_pipeline(&pipeline.pipeline);
                for (k, bg) in bgs.iter().enumerate() {
                    cp.set_bind_group(k as u32, bg, &[]);
                }
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
                let bgs = rt.bind_groups_of(ctx, &pipeline.info, &bindings, &set_bindings, &res);
                let timer = rt.timer.as_ref().filter(|_| timing.enabled);
                let attach = |t: Tex| {
                    res.textures[t.0 as usize]
                        .physical
                        .as_ref()
                        .unwrap()
                        .view(ViewKey {
                            dimension: wgpu::TextureViewDimension::D2,
                            single_mip: true,
                            base_mip: 0,
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
                    label: Some(&name),
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
                    timestamp_writes: timer.and_then(|t| t.render_writes(timing.queries(slot))),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(&pipeline.pipeline);
                for (k, bg) in bgs.iter().enumerate() {
                    rp.set_bind_group(k as u32, bg, &[]);
                }
                record(&mut rp, &res);
            }
            PassKind::Encoder { record } => record(encoder, &res),
        }
        out.push((
            name,
            timed.then_some(slot),
            tp.elapsed().as_secs_f64() * 1e6,
            traffic,
        ));
        if timed {
            slot += 1;
        }
        lifetimes.release(i, rt, textures, buffers);
    }
    drop(open_compute);
    // Readbacks of resources no pass touched never reach here (checked above), but a
    // persistent one could be first used at `n`: make sure it is resolved.
    lifetimes.acquire(n, rt, ctx, textures, buffers);
    Encoded {
        passes: out,
        slots: slot,
        reads: reads_out,
        poisoned,
    }
}

/// Copies each read-back resource into a mappable buffer.
fn encode_readbacks(
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    copies: &[Res],
    textures: &[VirtualTexture],
    buffers: &[VirtualBuffer],
) -> Vec<(Res, wgpu::Buffer)> {
    let mut staging = Vec::new();
    for r in copies {
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
                let p = buffers[b.0 as usize].physical.as_ref().unwrap();
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
    staging
}

/// The GPU time of each pass (waiting for the frame when timestamps are on).
fn read_timings(
    rt: &GraphRuntime,
    ctx: &GpuContext,
    timing: &TimestampPlan,
    encoded: Encoded,
) -> Result<(Vec<PassTiming>, Option<f64>)> {
    let slots = encoded.slots as usize;
    let (gpu, gpu_span_ms) = if timing.enabled {
        let (pairs, span) = rt
            .timer
            .as_ref()
            .unwrap()
            .read(ctx, timing.query_pairs(encoded.slots))?;
        match timing.mode {
            TimestampMode::Pass => (pairs, span),
            _ => (vec![None; slots], pairs[0]),
        }
    } else {
        (vec![None; slots], None)
    };
    let timings = encoded
        .passes
        .into_iter()
        .map(|(name, s, cpu_us, traffic)| PassTiming {
            name,
            gpu_ms: s.and_then(|s| gpu[s as usize]),
            cpu_us,
            traffic,
        })
        .collect();
    Ok((timings, gpu_span_ms))
}

/// Waits for the read-backs and decodes them.
#[allow(clippy::type_complexity)]
fn read_back(
    ctx: &GpuContext,
    staging: Vec<(Res, wgpu::Buffer)>,
    textures: &[VirtualTexture],
    buffers: &[VirtualBuffer],
) -> Result<(Vec<ImageRgba32>, Vec<(String, Vec<u8>)>)> {
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
                let mut image = readback::decode_image(&v.name, &v.desc, &data)?;
                image.texture = Some(t);
                images.push(image);
            }
            Res::Buf(b) => out_buffers.push((buffers[b.0 as usize].name.clone(), data)),
        }
    }
    Ok((images, out_buffers))
}

/// The late read-backs whose copies the GPU has finished, without waiting for the others.
fn collect_late(rt: &mut GraphRuntime, ctx: &GpuContext) -> Result<Vec<(String, Vec<u8>)>> {
    if rt.pending.is_empty() {
        return Ok(vec![]);
    }
    ctx.device
        .poll(wgpu::PollType::Poll)
        .map_err(|e| RenderError::Device(e.to_string()))?;
    let mut out = Vec::new();
    let mut keep = Vec::new();
    for (name, buf, ready) in std::mem::take(&mut rt.pending) {
        if ready.load(std::sync::atomic::Ordering::Acquire) {
            let data = buf
                .slice(..)
                .get_mapped_range()
                .map_err(|e| RenderError::Gpu {
                    during: "late read back".into(),
                    message: e.to_string(),
                })?
                .to_vec();
            out.push((name, data));
        } else {
            keep.push((name, buf, ready));
        }
    }
    rt.pending = keep;
    Ok(out)
}

/// The bind groups of a pass, group 0 first, then each binding set in group order.
impl GraphRuntime {
    fn bind_groups_of(
        &mut self,
        ctx: &GpuContext,
        info: &crate::pipeline::PipelineInfo,
        bindings: &[super::Binding],
        set_bindings: &[Vec<super::Binding>],
        res: &PassResources<'_>,
    ) -> Vec<wgpu::BindGroup> {
        let mut out = vec![self.bind_group(
            ctx,
            info.id,
            &info.label,
            &info.bind_group_layout,
            &info.slots,
            bindings,
            res,
        )];
        for (layout, bindings) in info.sets.iter().zip(set_bindings) {
            out.push(self.bind_group(
                ctx,
                layout.id,
                &layout.name,
                &layout.layout,
                &layout.slots,
                bindings,
                res,
            ));
        }
        out
    }
}
