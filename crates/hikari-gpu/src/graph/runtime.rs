//! What outlives a frame (pool, history, persistent resources, caches) and the execution of
//! a recorded frame.

use std::collections::HashMap;
use std::sync::Arc;

use super::readback::ImageRgba32;
use super::resources::{
    PhysicalBuffer, PhysicalTexture, Pool, PoolStats, TextureDesc, ViewKey, next_id,
};
use super::timing::{GpuTimer, PassTiming};
use super::{Binding, FrameGraph, PassResources, SamplerKind, Tex};
use crate::context::GpuContext;
use crate::pipeline::{BindingKind, BindingSlot};

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
    /// What each pass read, with [`GraphRuntime::set_record_reads`].
    pub reads: Vec<super::PassReads>,
    /// The texture overwritten with NaN and infinities this frame
    /// ([`GraphRuntime::poison_next_frame`]), if the pass and texture were found.
    pub poisoned: Option<super::Poison>,
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
    /// Removes and returns the read-back image of the texture `t` of this frame.
    pub fn take_image_of(&mut self, t: Tex) -> Option<ImageRgba32> {
        let i = self.images.iter().position(|i| i.texture == Some(t))?;
        Some(self.images.remove(i))
    }

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
    pub(crate) pool: Pool,
    persistent_textures: HashMap<String, Arc<PhysicalTexture>>,
    persistent_buffers: HashMap<String, Arc<PhysicalBuffer>>,
    history: HashMap<String, HistoryEntry>,
    pub(crate) imported_textures: HashMap<wgpu::Texture, (Arc<PhysicalTexture>, u64)>,
    pub(crate) imported_buffers: HashMap<wgpu::Buffer, (Arc<PhysicalBuffer>, u64)>,
    pub(crate) bind_groups: HashMap<Vec<u64>, wgpu::BindGroup>,
    pub(crate) constants: Option<Arc<PhysicalBuffer>>,
    samplers: HashMap<SamplerKind, (u64, wgpu::Sampler)>,
    pub(crate) timer: Option<GpuTimer>,
    pub(crate) timestamps: TimestampMode,
    pub(crate) dumps: Vec<String>,
    pub(crate) wait_for_readbacks: bool,
    /// Late read-backs in flight: name, staging buffer, set once it is mapped.
    pub(crate) pending: Vec<(String, wgpu::Buffer, Arc<std::sync::atomic::AtomicBool>)>,
    pub(crate) record_reads: bool,
    pub(crate) poison: Option<super::Poison>,
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
            wait_for_readbacks: true,
            pending: Vec::new(),
            record_reads: false,
            poison: None,
        }
    }

    /// Lists what each pass reads in every frame's [`FrameResult::reads`] (costs CPU time:
    /// for tests and the soak).
    pub fn set_record_reads(&mut self, on: bool) {
        self.record_reads = on;
    }

    /// Overwrites `poison.texture` with NaN, +Inf and -Inf before `poison.pass` runs in the
    /// next frame that has both ([`FrameResult::poisoned`] tells when it happened).
    pub fn poison_next_frame(&mut self, poison: super::Poison) {
        self.poison = Some(poison);
    }

    /// Whether `execute` waits for [`FrameGraph::readback_late`] buffers (the default, for
    /// offline renders that redraw a frame whose queues overflowed) or lets frames run ahead
    /// and delivers them with a later frame (interactive use).
    pub fn set_wait_for_readbacks(&mut self, wait: bool) {
        self.wait_for_readbacks = wait;
    }

    pub fn waits_for_readbacks(&self) -> bool {
        self.wait_for_readbacks
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
            late_readbacks: Vec::new(),
            sets: Vec::new(),
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

    /// The bind group of one group of a pipeline (`layout_id` identifies its layout), cached
    /// by the physical resources it binds.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn bind_group(
        &mut self,
        ctx: &GpuContext,
        layout_id: u64,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        slots: &[BindingSlot],
        bindings: &[Binding],
        res: &PassResources<'_>,
    ) -> wgpu::BindGroup {
        let constants = self.constants.clone();
        let mut key: Vec<u64> = Vec::with_capacity(1 + bindings.len() * 2);
        key.push(layout_id);
        for (b, slot) in bindings.iter().zip(slots) {
            match b {
                Binding::Texture(t, level) => {
                    key.push(res.textures[t.0 as usize].physical.as_ref().unwrap().id);
                    key.push(matches!(slot.kind, BindingKind::StorageTexture { .. }) as u64);
                    key.push(level.map_or(u64::MAX, u64::from));
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
        for (b, slot) in bindings.iter().zip(slots) {
            match (b, &slot.kind) {
                (Binding::Texture(t, level), BindingKind::SampledTexture { view, .. }) => {
                    let p = res.textures[t.0 as usize].physical.as_ref().unwrap();
                    views.push(p.view(ViewKey {
                        dimension: *view,
                        single_mip: level.is_some(),
                        base_mip: level.unwrap_or(0),
                    }));
                }
                (Binding::Texture(t, level), BindingKind::StorageTexture { view, .. }) => {
                    let p = res.textures[t.0 as usize].physical.as_ref().unwrap();
                    views.push(p.view(ViewKey {
                        dimension: *view,
                        single_mip: true,
                        base_mip: level.unwrap_or(0),
                    }));
                }
                (Binding::Sampler(s), _) => samplers.push(self.sampler(ctx, *s).1),
                _ => {}
            }
        }
        let (mut vi, mut si) = (0, 0);
        let entries: Vec<wgpu::BindGroupEntry> = bindings
            .iter()
            .zip(slots)
            .map(|(b, slot)| wgpu::BindGroupEntry {
                binding: slot.binding,
                resource: match b {
                    Binding::Texture(..) => {
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
            label: Some(label),
            layout,
            entries: &entries,
        });
        self.bind_groups.insert(key, bg.clone());
        bg
    }

    /// Accepts the frame just executed: temporal resources advance (what each history pass
    /// wrote becomes next frame's `prev`), the frame index steps on, and what the pool and the
    /// import caches no longer need is freed. A frame that is thrown away (drawn again, say)
    /// is [`GraphRuntime::discard_frame`]d instead, and temporal state stays where it was.
    pub fn commit_frame(&mut self) {
        for h in self.history.values_mut() {
            if std::mem::take(&mut h.used) {
                h.parity = 1 - h.parity;
                h.frames_written += 1;
            }
        }
        self.frame += 1;
        let f = self.frame;
        let before = self.imported_buffers.len() + self.imported_textures.len();
        self.imported_buffers
            .retain(|_, (_, last)| f - *last <= IMPORT_KEEP_FRAMES);
        self.imported_textures
            .retain(|_, (_, last)| f - *last <= IMPORT_KEEP_FRAMES);
        let pruned = before != self.imported_buffers.len() + self.imported_textures.len();
        if self.pool.trim(f) || pruned {
            // Cached bind groups hold their resources alive; start over so freed memory goes.
            self.bind_groups.clear();
        }
    }

    /// Forgets the frame just executed: history stays unflipped and the frame index unchanged,
    /// so the frame can be recorded and executed again as the same frame.
    pub fn discard_frame(&mut self) {
        for h in self.history.values_mut() {
            h.used = false;
        }
    }

    /// The texture of the temporal resource `name` that the next frame reads as its previous
    /// one (what the last committed frame wrote), so that tests can put bad values into a
    /// history; `None` if no frame has used it.
    pub fn history_for_next_frame(&self, name: &str) -> Option<&wgpu::Texture> {
        self.history
            .get(name)
            .map(|h| &h.textures[h.parity].texture)
    }

    /// Index of the next frame to be recorded: the number of frames committed so far.
    pub fn frame_index(&self) -> u64 {
        self.frame
    }
}
