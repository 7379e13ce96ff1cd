//! The frame graph: passes declare what they read and write, resources come from a pool or
//! live across frames by name, and every pass is timed on the GPU under its name.
//!
//! A frame is recorded as straight-line code (see `frame.rs`), then executed in recording
//! order. Recording order *is* the schedule: the graph does not reorder passes; it uses the
//! declarations to size lifetimes (so transient textures with disjoint lifetimes share memory),
//! to check each pass's bindings against its shader, and to find what `--dump` asks for.
//!
//! ```ignore
//! let hdr = g.texture("lighting.hdr", TextureDesc::d2(w, h, Rgba16Float));
//! g.pass("direct_lighting.sun")
//!     .read(gbuffer.depth)        // @binding(0)
//!     .read(gbuffer.normal)       // @binding(1)
//!     .write(hdr)                 // @binding(2)
//!     .constants(&params)         // @binding(3), a uniform
//!     .dispatch_threads(&pipeline, [w, h, 1])?;
//! ```
//!
//! A transient texture's contents are undefined until a pass of this frame writes it: the
//! memory may have held another texture a moment ago.

mod execute;
mod poison;
mod readback;
mod resources;
mod runtime;
mod timing;
mod traffic;

pub use poison::{PassReads, Poison, ReadTexture};
pub use readback::ImageRgba32;
pub use resources::{Buf, PoolStats, Res, Tex, TextureDesc};
pub use runtime::{FrameResult, GraphRuntime, History, TimestampMode};
pub use timing::PassTiming;
pub use traffic::Traffic;

use std::sync::Arc;

use bytemuck::Pod;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::pipeline::{BindingKind, BindingSlot, ComputePipeline, PipelineInfo, RasterPipeline};
use resources::{PhysicalBuffer, PhysicalTexture};

/// Fixed samplers a pass can bind with [`PassBuilder::sampler`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    LinearClamp,
    NearestClamp,
    NearestRepeat,
    LinearRepeat,
    /// Depth comparison (greater-or-equal, for reverse-Z shadow maps), linear.
    ShadowCompare,
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum TexSource {
    Transient,
    Persistent,
    HistoryPrev,
    HistoryCur,
    Imported,
}

pub(crate) struct VirtualTexture {
    pub name: String,
    pub desc: TextureDesc,
    pub source: TexSource,
    pub first: Option<usize>,
    pub last: Option<usize>,
    pub written: bool,
    pub physical: Option<Arc<PhysicalTexture>>,
}

pub(crate) struct VirtualBuffer {
    pub name: String,
    pub size: u64,
    pub transient: bool,
    pub first: Option<usize>,
    pub last: Option<usize>,
    pub written: bool,
    pub physical: Option<Arc<PhysicalBuffer>>,
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum Binding {
    /// A texture and the one mip level its view covers (`None`: every level when sampled,
    /// level 0 when a storage texture).
    Texture(Tex, Option<u32>),
    Buffer(Buf),
    Constants {
        offset: u64,
        size: u64,
    },
    Sampler(SamplerKind),
}

/// Each binding of a pass with the slot its pipeline declares for it: group 0's, then each
/// binding set's, in group order.
pub(crate) fn bound_slots<'a>(
    info: &'a crate::pipeline::PipelineInfo,
    bindings: &'a [Binding],
    set_bindings: &'a [Vec<Binding>],
) -> impl Iterator<Item = (&'a crate::pipeline::BindingSlot, &'a Binding)> {
    std::iter::once((info.slots.as_slice(), bindings))
        .chain(
            info.sets
                .iter()
                .zip(set_bindings)
                .map(|(s, b)| (s.slots.as_slice(), b.as_slice())),
        )
        .flat_map(|(slots, bindings)| slots.iter().zip(bindings))
}

/// The physical resources of a pass, for the closures of raster and custom passes.
pub struct PassResources<'a> {
    pub(crate) textures: &'a [VirtualTexture],
    pub(crate) buffers: &'a [VirtualBuffer],
}

impl PassResources<'_> {
    pub fn texture(&self, t: Tex) -> &wgpu::Texture {
        &self.textures[t.0 as usize]
            .physical
            .as_ref()
            .expect("declared by the pass")
            .texture
    }

    /// The whole texture as its natural view (2D, 2D array or 3D).
    pub fn view(&self, t: Tex) -> wgpu::TextureView {
        let p = self.textures[t.0 as usize]
            .physical
            .as_ref()
            .expect("declared by the pass");
        p.view(resources::ViewKey {
            dimension: p.default_dimension(),
            single_mip: false,
            base_mip: 0,
        })
    }

    pub fn buffer(&self, b: Buf) -> &wgpu::Buffer {
        &self.buffers[b.0 as usize]
            .physical
            .as_ref()
            .expect("declared by the pass")
            .buffer
    }
}

pub(crate) type RasterRecord<'r> =
    Box<dyn FnOnce(&mut wgpu::RenderPass<'_>, &PassResources<'_>) + 'r>;
pub(crate) type EncoderRecord<'r> =
    Box<dyn FnOnce(&mut wgpu::CommandEncoder, &PassResources<'_>) + 'r>;

pub(crate) enum PassKind<'r> {
    Compute {
        pipeline: &'r ComputePipeline,
        groups: [u32; 3],
    },
    Raster {
        pipeline: &'r RasterPipeline,
        colors: Vec<(Tex, Option<[f64; 4]>)>,
        depth: Option<(Tex, Option<f32>)>,
        record: RasterRecord<'r>,
    },
    Encoder {
        record: EncoderRecord<'r>,
    },
}

pub(crate) struct PassNode<'r> {
    pub name: String,
    pub kind: PassKind<'r>,
    /// Group 0.
    pub bindings: Vec<Binding>,
    /// Groups 1..: the pipeline's binding sets, in group order.
    pub set_bindings: Vec<Vec<Binding>>,
}

/// One frame being recorded. Made by [`GraphRuntime::begin_frame`], consumed by
/// [`FrameGraph::execute`].
pub struct FrameGraph<'r> {
    pub(crate) ctx: &'r GpuContext,
    pub(crate) rt: &'r mut GraphRuntime,
    pub(crate) textures: Vec<VirtualTexture>,
    pub(crate) buffers: Vec<VirtualBuffer>,
    pub(crate) passes: Vec<PassNode<'r>>,
    pub(crate) constants: Vec<u8>,
    pub(crate) readbacks: Vec<Res>,
    pub(crate) late_readbacks: Vec<Buf>,
    pub(crate) sets: Vec<SetData>,
}

/// A shared binding set of this frame (the sun's shadow maps, the BVH), made once by the
/// technique that owns it with [`FrameGraph::binding_set`] and bound by any pass whose shader
/// imports its module, with [`PassBuilder::set`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindingSet(pub(crate) u32);

pub(crate) struct SetData {
    pub name: String,
    pub bindings: Vec<Binding>,
    pub expect_write: Vec<Option<bool>>,
}

/// Builds a [`BindingSet`]: the resources in `@binding` order of the set's module.
pub struct SetBuilder<'g, 'r> {
    g: &'g mut FrameGraph<'r>,
    data: SetData,
}

impl SetBuilder<'_, '_> {
    fn bind(mut self, b: Binding, write: Option<bool>) -> Self {
        self.data.bindings.push(b);
        self.data.expect_write.push(write);
        self
    }

    pub fn read(self, r: impl Into<Res>) -> Self {
        self.bind(PassBuilder::res_binding(r.into()), Some(false))
    }

    pub fn write(self, r: impl Into<Res>) -> Self {
        self.bind(PassBuilder::res_binding(r.into()), Some(true))
    }

    pub fn constants<T: Pod>(self, value: &T) -> Self {
        let b = self.g.push_constants(value);
        self.bind(b, None)
    }

    pub fn sampler(self, s: SamplerKind) -> Self {
        self.bind(Binding::Sampler(s), None)
    }

    pub fn finish(self) -> BindingSet {
        self.g.sets.push(self.data);
        BindingSet(self.g.sets.len() as u32 - 1)
    }
}

impl<'r> FrameGraph<'r> {
    /// Starts the binding set `name`: the resources of a shared WGSL module that declares
    /// them as `@group(#{NAME_GROUP}) @binding(i)`, in binding order.
    pub fn binding_set<'g>(&'g mut self, name: &str) -> SetBuilder<'g, 'r> {
        SetBuilder {
            g: self,
            data: SetData {
                name: name.into(),
                bindings: Vec::new(),
                expect_write: Vec::new(),
            },
        }
    }

    pub fn ctx(&self) -> &'r GpuContext {
        self.ctx
    }

    /// Index of the frame being recorded (0 for the first).
    pub fn frame_index(&self) -> u64 {
        self.rt.frame
    }

    fn add_texture(
        &mut self,
        name: &str,
        desc: TextureDesc,
        source: TexSource,
        physical: Option<Arc<PhysicalTexture>>,
    ) -> Tex {
        let written = !matches!(source, TexSource::Transient);
        self.textures.push(VirtualTexture {
            name: name.into(),
            desc,
            source,
            first: None,
            last: None,
            written,
            physical,
        });
        Tex(self.textures.len() as u32 - 1)
    }

    /// The description of `t`.
    pub fn texture_desc(&self, t: Tex) -> TextureDesc {
        self.textures[t.0 as usize].desc
    }

    /// The name of `t`.
    pub fn texture_name(&self, t: Tex) -> &str {
        &self.textures[t.0 as usize].name
    }

    /// The last texture named `name` that a pass of this frame has written so far (what
    /// `--dump` would read), if any.
    pub fn find_written_texture(&self, name: &str) -> Option<Tex> {
        self.textures
            .iter()
            .rposition(|t| t.name == name && t.written)
            .map(|i| Tex(i as u32))
    }

    /// The names of the textures passes of this frame have written so far, sorted, once each.
    pub fn written_texture_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .textures
            .iter()
            .filter(|t| t.written)
            .map(|t| t.name.clone())
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// A texture that lives for this frame only. Its name (`technique.what`) is what
    /// `--dump` and timings show.
    pub fn texture(&mut self, name: &str, desc: TextureDesc) -> Result<Tex> {
        desc.check(self.ctx, name)?;
        Ok(self.add_texture(name, desc, TexSource::Transient, None))
    }

    /// A texture kept across frames under `name`, e.g. atmosphere LUTs rebuilt only when their
    /// inputs change. Returns `true` with it when it was (re)created this frame and so holds
    /// zeros.
    pub fn persistent_texture(&mut self, name: &str, desc: TextureDesc) -> Result<(Tex, bool)> {
        desc.check(self.ctx, name)?;
        let (p, created) = self.rt.persistent_texture(self.ctx, name, desc);
        Ok((
            self.add_texture(name, desc, TexSource::Persistent, Some(p)),
            created,
        ))
    }

    /// A pair of textures for temporal techniques: `prev` holds what `cur` held last frame.
    /// `valid` is false on the first frame and after a size or format change, when `prev`
    /// holds zeros and must not be blended in.
    pub fn history_texture(&mut self, name: &str, desc: TextureDesc) -> Result<History> {
        desc.check(self.ctx, name)?;
        let (prev, cur, valid) = self.rt.history_texture(self.ctx, name, desc);
        let prev = self.add_texture(
            &format!("{name}.prev"),
            desc,
            TexSource::HistoryPrev,
            Some(prev),
        );
        let cur = self.add_texture(name, desc, TexSource::HistoryCur, Some(cur));
        Ok(History { prev, cur, valid })
    }

    /// A texture made outside the graph (e.g. a baked probe atlas).
    pub fn import_texture(&mut self, name: &str, texture: &wgpu::Texture) -> Tex {
        let desc = TextureDesc {
            size: [
                texture.width(),
                texture.height(),
                texture.depth_or_array_layers(),
            ],
            dimension: texture.dimension(),
            format: texture.format(),
            mip_levels: texture.mip_level_count(),
        };
        let p = self.rt.imported_texture(texture, desc);
        self.add_texture(name, desc, TexSource::Imported, Some(p))
    }

    fn add_buffer(
        &mut self,
        name: &str,
        size: u64,
        transient: bool,
        physical: Option<Arc<PhysicalBuffer>>,
    ) -> Buf {
        self.buffers.push(VirtualBuffer {
            name: name.into(),
            size,
            transient,
            first: None,
            last: None,
            written: !transient,
            physical,
        });
        Buf(self.buffers.len() as u32 - 1)
    }

    fn check_buffer_size(&self, name: &str, size: u64) -> Result<()> {
        let limit = self.ctx.limits.max_storage_buffer_binding_size;
        if size == 0 || size > limit {
            return Err(RenderError::Limit {
                what: format!("size in bytes of buffer `{name}`"),
                requested: size,
                limit,
            });
        }
        Ok(())
    }

    /// A storage buffer that lives for this frame only.
    pub fn buffer(&mut self, name: &str, size: u64) -> Result<Buf> {
        self.check_buffer_size(name, size)?;
        Ok(self.add_buffer(name, size.next_multiple_of(4), true, None))
    }

    /// A storage buffer kept across frames under `name` (e.g. a BVH). Returns `true` with it
    /// when it was (re)created this frame.
    pub fn persistent_buffer(&mut self, name: &str, size: u64) -> Result<(Buf, bool)> {
        self.check_buffer_size(name, size)?;
        let size = size.next_multiple_of(4);
        let (p, created) = self.rt.persistent_buffer(self.ctx, name, size);
        Ok((self.add_buffer(name, size, false, Some(p)), created))
    }

    /// A buffer made outside the graph (scene geometry, a BVH a library user built).
    pub fn import_buffer(&mut self, name: &str, buffer: &wgpu::Buffer) -> Buf {
        let p = self.rt.imported_buffer(buffer);
        self.add_buffer(name, buffer.size(), false, Some(p))
    }

    /// Size in bytes of a buffer of this frame (as declared, or the imported buffer's size);
    /// `None` for a handle that is not of this frame.
    pub fn buffer_size(&self, b: Buf) -> Option<u64> {
        self.buffers.get(b.0 as usize).map(|v| v.size)
    }

    /// Asks for `res` to be copied back to the CPU after the frame; it appears in
    /// [`FrameResult::images`] (textures) or [`FrameResult::buffers`] under its name.
    pub fn readback(&mut self, res: impl Into<Res>) {
        self.readbacks.push(res.into());
    }

    /// Whether `--dump` asks for a resource named `name` this frame: a technique records an
    /// image that the frame itself does not need (it evaluates it inline) only then.
    pub fn dump_requested(&self, name: &str) -> bool {
        self.rt.dumps.iter().any(|d| d == name)
    }

    /// Asks for a buffer to be copied back without making anyone wait for it (the
    /// rasteriser's queue counts): while the runtime waits for read-backs (the default, for
    /// offline renders) it behaves as [`FrameGraph::readback`]; in a runtime that does not
    /// ([`GraphRuntime::set_wait_for_readbacks`]), the bytes appear in the
    /// [`FrameResult::buffers`] of a later frame, once the GPU has finished this one.
    pub fn readback_late(&mut self, b: Buf) {
        self.late_readbacks.push(b);
    }

    /// Starts a pass named `technique.stage`.
    pub fn pass<'g>(&'g mut self, name: &str) -> PassBuilder<'g, 'r> {
        PassBuilder {
            g: self,
            name: name.into(),
            sets: Vec::new(),
            bindings: Vec::new(),
            expect_write: Vec::new(),
            uses: Vec::new(),
            colors: Vec::new(),
            depth: None,
        }
    }

    fn touch(&mut self, res: Res, pass: usize, write: bool, pass_name: &str) -> Result<()> {
        let (first, last, written, name) = match res {
            Res::Tex(t) => {
                let v = self
                    .textures
                    .get_mut(t.0 as usize)
                    .ok_or_else(|| RenderError::Pass {
                        pass: pass_name.into(),
                        message: "texture handle from another frame".into(),
                    })?;
                (&mut v.first, &mut v.last, &mut v.written, v.name.clone())
            }
            Res::Buf(b) => {
                let v = self
                    .buffers
                    .get_mut(b.0 as usize)
                    .ok_or_else(|| RenderError::Pass {
                        pass: pass_name.into(),
                        message: "buffer handle from another frame".into(),
                    })?;
                (&mut v.first, &mut v.last, &mut v.written, v.name.clone())
            }
        };
        if !write && !*written {
            return Err(RenderError::Pass {
                pass: pass_name.into(),
                message: format!("reads `{name}`, which no earlier pass of this frame wrote"),
            });
        }
        *written |= write;
        first.get_or_insert(pass);
        *last = Some(pass);
        Ok(())
    }

    fn push_constants<T: Pod>(&mut self, value: &T) -> Binding {
        // Constants bind as uniforms, or as storage on adapters that take them so
        // (`GpuContext::uniforms_as_storage`): aligned for both.
        let limits = &self.ctx.limits;
        let align = limits
            .min_uniform_buffer_offset_alignment
            .max(limits.min_storage_buffer_offset_alignment) as usize;
        let offset = self.constants.len().next_multiple_of(align);
        self.constants.resize(offset, 0);
        self.constants.extend_from_slice(bytemuck::bytes_of(value));
        Binding::Constants {
            offset: offset as u64,
            size: std::mem::size_of::<T>().next_multiple_of(16) as u64,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn add_pass(
        &mut self,
        name: String,
        kind: PassKind<'r>,
        bindings: Vec<Binding>,
        expect_write: Vec<Option<bool>>,
        sets: Vec<BindingSet>,
        uses: Vec<(Res, bool)>,
        info: Option<&PipelineInfo>,
    ) -> Result<()> {
        let index = self.passes.len();
        let mut set_bindings = Vec::new();
        // Reads first, so a pass that reads and writes the same resource still needs an
        // earlier writer.
        let mut touched: Vec<(Res, bool)> = Vec::new();
        if let Some(info) = info {
            self.check_bindings(&name, &info.label, &info.slots, &bindings, &expect_write)?;
            touched.extend(Self::accesses(&bindings, &info.slots));
            for layout in &info.sets {
                let set = sets
                    .iter()
                    .map(|s| &self.sets[s.0 as usize])
                    .find(|s| s.name == layout.name)
                    .ok_or_else(|| RenderError::Pass {
                        pass: name.clone(),
                        message: format!(
                            "`{}` imports the binding set `{}` (@group({})), which the pass does not bind with `.set(...)`",
                            info.label, layout.name, layout.group
                        ),
                    })?;
                let label = format!("{} set `{}`", info.label, layout.name);
                // A set offers a resource at each binding of its module; a pipeline uses those
                // its entry point reaches (naga_oil leaves the others out of the shader).
                let mut bindings = Vec::with_capacity(layout.slots.len());
                let mut expect = Vec::with_capacity(layout.slots.len());
                for slot in &layout.slots {
                    let i = slot.binding as usize;
                    let b = set.bindings.get(i).ok_or_else(|| RenderError::Pass {
                        pass: name.clone(),
                        message: format!(
                            "`{label}` declares @binding({i}) `{}`, but the set binds {} resources",
                            slot.name,
                            set.bindings.len()
                        ),
                    })?;
                    bindings.push(*b);
                    expect.push(set.expect_write[i]);
                }
                self.check_bindings(&name, &label, &layout.slots, &bindings, &expect)?;
                touched.extend(Self::accesses(&bindings, &layout.slots));
                set_bindings.push(bindings);
            }
            for s in &sets {
                let set = &self.sets[s.0 as usize];
                if !info.sets.iter().any(|l| l.name == set.name) {
                    return Err(RenderError::Pass {
                        pass: name.clone(),
                        message: format!(
                            "binds the set `{}`, which `{}` does not import",
                            set.name, info.label
                        ),
                    });
                }
            }
        } else {
            for (b, w) in bindings.iter().zip(&expect_write) {
                match b {
                    Binding::Texture(t, _) => touched.push((Res::Tex(*t), *w == Some(true))),
                    Binding::Buffer(b) => touched.push((Res::Buf(*b), *w == Some(true))),
                    _ => {}
                }
            }
        }
        touched.extend(uses);
        if let PassKind::Raster { colors, depth, .. } = &kind {
            for (t, clear) in colors {
                touched.push((Res::Tex(*t), clear.is_some()));
            }
            if let Some((t, clear)) = depth {
                touched.push((Res::Tex(*t), clear.is_some()));
            }
        }
        for (res, write) in touched {
            self.touch(res, index, write, &name)?;
        }
        self.passes.push(PassNode {
            name,
            kind,
            bindings,
            set_bindings,
        });
        Ok(())
    }

    /// The resources `bindings` touch, as (resource, written) with reads first: a slot that
    /// reads and writes gives both.
    fn accesses(bindings: &[Binding], slots: &[BindingSlot]) -> Vec<(Res, bool)> {
        let mut out = Vec::new();
        for (b, slot) in bindings.iter().zip(slots) {
            let res = match b {
                Binding::Texture(t, _) => Res::Tex(*t),
                Binding::Buffer(b) => Res::Buf(*b),
                _ => continue,
            };
            let writes = slot.kind.writes();
            let reads = !writes
                || matches!(
                    slot.kind,
                    BindingKind::StorageTexture {
                        access: wgpu::StorageTextureAccess::ReadWrite,
                        ..
                    }
                );
            out.push((res, !reads));
            if reads && writes {
                out.push((res, true));
            }
        }
        out
    }

    fn check_bindings(
        &self,
        pass: &str,
        label: &str,
        slots: &[BindingSlot],
        bindings: &[Binding],
        expect_write: &[Option<bool>],
    ) -> Result<()> {
        let err = |message: String| RenderError::Pass {
            pass: pass.into(),
            message,
        };
        if bindings.len() != slots.len() {
            let wanted: Vec<String> = slots
                .iter()
                .map(|s| format!("{}: {}", s.binding, s.name))
                .collect();
            return Err(err(format!(
                "binds {} resources but `{}` declares {} ({})",
                bindings.len(),
                label,
                slots.len(),
                wanted.join(", ")
            )));
        }
        for ((b, slot), ew) in bindings.iter().zip(slots).zip(expect_write) {
            let here = format!("@binding({}) `{}` of `{}`", slot.binding, slot.name, label);
            match (b, &slot.kind) {
                (Binding::Texture(t, level), BindingKind::SampledTexture { view, .. })
                | (Binding::Texture(t, level), BindingKind::StorageTexture { view, .. }) => {
                    let v = &self.textures[t.0 as usize];
                    if let Some(level) = level
                        && *level >= v.desc.mip_levels
                    {
                        return Err(err(format!(
                            "{here} binds mip level {level} but `{}` has {}",
                            v.name, v.desc.mip_levels
                        )));
                    }
                    let ok_dim = match view {
                        wgpu::TextureViewDimension::D3 => {
                            v.desc.dimension == wgpu::TextureDimension::D3
                        }
                        wgpu::TextureViewDimension::D1 => {
                            v.desc.dimension == wgpu::TextureDimension::D1
                        }
                        // Six square faces a cube.
                        wgpu::TextureViewDimension::Cube
                        | wgpu::TextureViewDimension::CubeArray => {
                            v.desc.dimension == wgpu::TextureDimension::D2
                                && v.desc.size[0] == v.desc.size[1]
                                && v.desc.size[2].is_multiple_of(6)
                                && (v.desc.size[2] == 6
                                    || *view == wgpu::TextureViewDimension::CubeArray)
                        }
                        _ => v.desc.dimension == wgpu::TextureDimension::D2,
                    };
                    if !ok_dim {
                        return Err(err(format!(
                            "{here} is a {view:?} view but `{}` is {:?}",
                            v.name, v.desc.dimension
                        )));
                    }
                    if let BindingKind::StorageTexture { format, .. } = &slot.kind
                        && *format != v.desc.format
                    {
                        return Err(err(format!(
                            "{here} wants format {format:?} but `{}` is {:?}",
                            v.name, v.desc.format
                        )));
                    }
                }
                (Binding::Buffer(_), BindingKind::Storage { .. } | BindingKind::Uniform) => {}
                (Binding::Constants { .. }, BindingKind::Uniform) => {}
                (
                    Binding::Sampler(SamplerKind::LinearClamp | SamplerKind::LinearRepeat),
                    BindingKind::Sampler {
                        filtering: false, ..
                    },
                ) => {
                    return Err(err(format!(
                        "{here} gathers integer texels, which takes SamplerKind::NearestClamp"
                    )));
                }
                (Binding::Sampler(_), BindingKind::Sampler { .. }) => {}
                (b, k) => return Err(err(format!("{here} is {k:?} but the pass binds {b:?}"))),
            }
            if let Some(w) = ew
                && *w != slot.kind.writes()
            {
                let (said, is) = if *w {
                    ("write", "read-only")
                } else {
                    ("read", "writable")
                };
                return Err(err(format!("{here} is {is} but the pass says `{said}`")));
            }
        }
        Ok(())
    }

    /// Runs the frame (allocates, encodes, submits, and reads back timings and readbacks)
    /// and commits it: temporal state advances. See [`FrameGraph::execute_uncommitted`].
    pub fn execute(self) -> Result<FrameResult> {
        execute::execute(self, true)
    }

    /// Runs the frame without advancing temporal state: the caller then accepts it with
    /// [`GraphRuntime::commit_frame`] or throws it away with [`GraphRuntime::discard_frame`],
    /// so that a frame drawn twice steps history, frame index and time slices once.
    pub fn execute_uncommitted(self) -> Result<FrameResult> {
        execute::execute(self, false)
    }
}

/// Builds one pass; finish with `dispatch*`, `draw` or `encode`.
pub struct PassBuilder<'g, 'r> {
    g: &'g mut FrameGraph<'r>,
    name: String,
    sets: Vec<BindingSet>,
    bindings: Vec<Binding>,
    /// Per binding: `Some(true)` for `.write`, `Some(false)` for `.read`, `None` otherwise.
    expect_write: Vec<Option<bool>>,
    uses: Vec<(Res, bool)>,
    colors: Vec<(Tex, Option<[f64; 4]>)>,
    depth: Option<(Tex, Option<f32>)>,
}

impl<'r> PassBuilder<'_, 'r> {
    fn bind(mut self, b: Binding, write: Option<bool>) -> Self {
        self.bindings.push(b);
        self.expect_write.push(write);
        self
    }

    fn res_binding(r: Res) -> Binding {
        match r {
            Res::Tex(t) => Binding::Texture(t, None),
            Res::Buf(b) => Binding::Buffer(b),
        }
    }

    /// Binds a shared binding set to the group its shader gave it.
    pub fn set(mut self, s: BindingSet) -> Self {
        self.sets.push(s);
        self
    }

    /// Binds the next slot to a resource the pass reads.
    pub fn read(self, r: impl Into<Res>) -> Self {
        self.bind(Self::res_binding(r.into()), Some(false))
    }

    /// Binds the next slot to a resource the pass writes (or reads and writes).
    pub fn write(self, r: impl Into<Res>) -> Self {
        self.bind(Self::res_binding(r.into()), Some(true))
    }

    /// Binds the next slot, a storage texture, to mip level `level` of `t`, which it writes.
    pub fn write_mip(self, t: Tex, level: u32) -> Self {
        self.bind(Binding::Texture(t, Some(level)), Some(true))
    }

    /// Binds the next slot to mip level `level` of `t` alone, which it reads (so that a pass
    /// can read one level and write the next).
    pub fn read_mip(self, t: Tex, level: u32) -> Self {
        self.bind(Binding::Texture(t, Some(level)), Some(false))
    }

    /// Binds the next slot to a uniform holding `value`.
    pub fn constants<T: Pod>(self, value: &T) -> Self {
        let b = self.g.push_constants(value);
        self.bind(b, None)
    }

    pub fn sampler(self, s: SamplerKind) -> Self {
        self.bind(Binding::Sampler(s), None)
    }

    /// Declares a use that is not a binding: a buffer a raster closure binds as index buffer,
    /// a texture a custom pass copies.
    pub fn uses(mut self, r: impl Into<Res>, write: bool) -> Self {
        self.uses.push((r.into(), write));
        self
    }

    /// A color attachment; `clear` of `None` loads what is there.
    pub fn color(mut self, t: Tex, clear: Option<[f64; 4]>) -> Self {
        self.colors.push((t, clear));
        self
    }

    /// The depth attachment; `clear` of `None` loads what is there.
    pub fn depth(mut self, t: Tex, clear: Option<f32>) -> Self {
        self.depth = Some((t, clear));
        self
    }

    pub fn dispatch(self, pipeline: &'r ComputePipeline, groups: [u32; 3]) -> Result<()> {
        let max = self.g.ctx.limits.max_compute_workgroups_per_dimension;
        if let Some(&n) = groups.iter().find(|&&n| n > max) {
            return Err(RenderError::Limit {
                what: format!("workgroups of pass `{}`", self.name),
                requested: n as u64,
                limit: max as u64,
            });
        }
        let kind = PassKind::Compute { pipeline, groups };
        self.g.add_pass(
            self.name,
            kind,
            self.bindings,
            self.expect_write,
            self.sets,
            self.uses,
            Some(&pipeline.info),
        )
    }

    /// Dispatches enough workgroups to cover `threads` invocations.
    pub fn dispatch_threads(self, pipeline: &'r ComputePipeline, threads: [u32; 3]) -> Result<()> {
        let groups = pipeline.groups_for(threads);
        self.dispatch(pipeline, groups)
    }

    /// A raster pass: the graph sets the pipeline and group 0, `record` draws.
    pub fn draw(
        self,
        pipeline: &'r RasterPipeline,
        record: impl FnOnce(&mut wgpu::RenderPass<'_>, &PassResources<'_>) + 'r,
    ) -> Result<()> {
        let kind = PassKind::Raster {
            pipeline,
            colors: self.colors,
            depth: self.depth,
            record: Box::new(record),
        };
        self.g.add_pass(
            self.name,
            kind,
            self.bindings,
            self.expect_write,
            self.sets,
            self.uses,
            Some(&pipeline.info),
        )
    }

    /// A pass that records commands itself (copies, clears); it declares its resources with
    /// [`PassBuilder::uses`]. It is not timed on the GPU.
    pub fn encode(
        self,
        record: impl FnOnce(&mut wgpu::CommandEncoder, &PassResources<'_>) + 'r,
    ) -> Result<()> {
        if !self.bindings.is_empty() {
            return Err(RenderError::Pass {
                pass: self.name,
                message: "an encoder pass binds nothing; declare resources with `uses`".into(),
            });
        }
        let kind = PassKind::Encoder {
            record: Box::new(record),
        };
        self.g
            .add_pass(self.name, kind, vec![], vec![], vec![], self.uses, None)
    }
}
