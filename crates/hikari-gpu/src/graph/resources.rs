//! Resource descriptions, handles, and the physical GPU objects behind them.

use std::sync::{
    Arc, Mutex,
    atomic::{AtomicU64, Ordering},
};

use crate::context::GpuContext;

static NEXT_PHYSICAL_ID: AtomicU64 = AtomicU64::new(1);

pub(crate) fn next_id() -> u64 {
    NEXT_PHYSICAL_ID.fetch_add(1, Ordering::Relaxed)
}

/// A texture as a pass asks for it. Two equal descriptions can share one physical texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureDesc {
    /// Width, height, and depth (3D) or array layers (2D).
    pub size: [u32; 3],
    pub dimension: wgpu::TextureDimension,
    pub format: wgpu::TextureFormat,
    pub mip_levels: u32,
}

impl TextureDesc {
    pub fn d2(width: u32, height: u32, format: wgpu::TextureFormat) -> Self {
        Self {
            size: [width, height, 1],
            dimension: wgpu::TextureDimension::D2,
            format,
            mip_levels: 1,
        }
    }

    pub fn d3(width: u32, height: u32, depth: u32, format: wgpu::TextureFormat) -> Self {
        Self {
            size: [width, height, depth],
            dimension: wgpu::TextureDimension::D3,
            format,
            mip_levels: 1,
        }
    }

    /// A 2D array, e.g. six layers for a cube map.
    pub fn d2_array(width: u32, height: u32, layers: u32, format: wgpu::TextureFormat) -> Self {
        Self {
            size: [width, height, layers],
            dimension: wgpu::TextureDimension::D2,
            format,
            mip_levels: 1,
        }
    }

    pub fn with_mips(mut self, mip_levels: u32) -> Self {
        self.mip_levels = mip_levels;
        self
    }

    pub fn extent(&self) -> wgpu::Extent3d {
        wgpu::Extent3d {
            width: self.size[0],
            height: self.size[1],
            depth_or_array_layers: self.size[2],
        }
    }

    /// Checks the description against the device limits, naming what is too large.
    pub fn check(&self, ctx: &GpuContext, name: &str) -> crate::Result<()> {
        let lim = &ctx.limits;
        let (what, max) = match self.dimension {
            wgpu::TextureDimension::D3 => ("3D texture", lim.max_texture_dimension_3d),
            wgpu::TextureDimension::D2 => ("2D texture", lim.max_texture_dimension_2d),
            wgpu::TextureDimension::D1 => ("1D texture", lim.max_texture_dimension_1d),
        };
        let dims = if self.dimension == wgpu::TextureDimension::D3 {
            3
        } else {
            2
        };
        for (axis, &v) in self.size.iter().enumerate().take(dims) {
            if v == 0 || v > max {
                return Err(crate::RenderError::Limit {
                    what: format!("{what} `{name}` size along axis {axis}"),
                    requested: v as u64,
                    limit: max as u64,
                });
            }
        }
        if self.dimension == wgpu::TextureDimension::D2
            && self.size[2] > lim.max_texture_array_layers
        {
            return Err(crate::RenderError::Limit {
                what: format!("array layers of `{name}`"),
                requested: self.size[2] as u64,
                limit: lim.max_texture_array_layers as u64,
            });
        }
        Ok(())
    }
}

/// Handle to a texture of the frame being recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Tex(pub(crate) u32);

/// Handle to a buffer of the frame being recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Buf(pub(crate) u32);

/// Either kind of resource, for declaring reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Res {
    Tex(Tex),
    Buf(Buf),
}

impl From<Tex> for Res {
    fn from(t: Tex) -> Self {
        Res::Tex(t)
    }
}

impl From<Buf> for Res {
    fn from(b: Buf) -> Self {
        Res::Buf(b)
    }
}

/// Every usage the format allows, so that one pooled texture serves any pass.
pub(crate) fn texture_usage(ctx: &GpuContext, format: wgpu::TextureFormat) -> wgpu::TextureUsages {
    let allowed = ctx
        .adapter
        .get_texture_format_features(format)
        .allowed_usages;
    let mut usage = wgpu::TextureUsages::TEXTURE_BINDING
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::COPY_DST;
    for extra in [
        wgpu::TextureUsages::STORAGE_BINDING,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    ] {
        if allowed.contains(extra) {
            usage |= extra;
        }
    }
    usage
}

pub(crate) const BUFFER_USAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::UNIFORM)
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::COPY_DST)
    .union(wgpu::BufferUsages::INDIRECT)
    .union(wgpu::BufferUsages::INDEX)
    .union(wgpu::BufferUsages::VERTEX);

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ViewKey {
    pub dimension: wgpu::TextureViewDimension,
    /// Storage and attachment views must cover a single mip level.
    pub single_mip: bool,
    /// The first mip level the view covers.
    pub base_mip: u32,
}

/// A texture that exists on the GPU, with the views made of it so far.
pub(crate) struct PhysicalTexture {
    pub id: u64,
    pub desc: TextureDesc,
    pub texture: wgpu::Texture,
    views: Mutex<Vec<(ViewKey, wgpu::TextureView)>>,
}

impl PhysicalTexture {
    pub fn create(ctx: &GpuContext, label: &str, desc: TextureDesc) -> Arc<Self> {
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: desc.extent(),
            mip_level_count: desc.mip_levels,
            sample_count: 1,
            dimension: desc.dimension,
            format: desc.format,
            usage: texture_usage(ctx, desc.format),
            view_formats: &[],
        });
        Arc::new(Self {
            id: next_id(),
            desc,
            texture,
            views: Mutex::new(Vec::new()),
        })
    }

    pub fn wrap(texture: wgpu::Texture, desc: TextureDesc) -> Arc<Self> {
        Arc::new(Self {
            id: next_id(),
            desc,
            texture,
            views: Mutex::new(Vec::new()),
        })
    }

    pub fn default_dimension(&self) -> wgpu::TextureViewDimension {
        match self.desc.dimension {
            wgpu::TextureDimension::D1 => wgpu::TextureViewDimension::D1,
            wgpu::TextureDimension::D3 => wgpu::TextureViewDimension::D3,
            wgpu::TextureDimension::D2 if self.desc.size[2] > 1 => {
                wgpu::TextureViewDimension::D2Array
            }
            wgpu::TextureDimension::D2 => wgpu::TextureViewDimension::D2,
        }
    }

    pub fn view(&self, key: ViewKey) -> wgpu::TextureView {
        let mut views = self.views.lock().unwrap();
        if let Some((_, v)) = views.iter().find(|(k, _)| *k == key) {
            return v.clone();
        }
        let v = self.texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(key.dimension),
            base_mip_level: key.base_mip,
            mip_level_count: key.single_mip.then_some(1),
            ..Default::default()
        });
        views.push((key, v.clone()));
        v
    }
}

pub(crate) struct PhysicalBuffer {
    pub id: u64,
    pub size: u64,
    pub buffer: wgpu::Buffer,
}

impl PhysicalBuffer {
    pub fn create(ctx: &GpuContext, label: &str, size: u64) -> Arc<Self> {
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: BUFFER_USAGE,
            mapped_at_creation: false,
        });
        Arc::new(Self {
            id: next_id(),
            size,
            buffer,
        })
    }
}

/// Counters of the transient pool, for tests and `--timings`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PoolStats {
    pub textures_created: u64,
    pub textures_alive: usize,
    pub buffers_created: u64,
    pub buffers_alive: usize,
}

struct Pooled<T> {
    item: Arc<T>,
    in_use: bool,
    last_frame: u64,
}

/// Transient textures and buffers, reused within a frame once their last reader is done and
/// across frames while the same descriptions keep being asked for.
#[derive(Default)]
pub(crate) struct Pool {
    textures: Vec<Pooled<PhysicalTexture>>,
    buffers: Vec<Pooled<PhysicalBuffer>>,
    pub stats: PoolStats,
}

/// Frames a pooled resource may stay unused before it is freed.
const POOL_KEEP_FRAMES: u64 = 4;

impl Pool {
    pub fn acquire_texture(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        desc: TextureDesc,
        frame: u64,
    ) -> Arc<PhysicalTexture> {
        if let Some(p) = self
            .textures
            .iter_mut()
            .find(|p| !p.in_use && p.item.desc == desc)
        {
            p.in_use = true;
            p.last_frame = frame;
            return p.item.clone();
        }
        let item = PhysicalTexture::create(ctx, name, desc);
        self.stats.textures_created += 1;
        self.textures.push(Pooled {
            item: item.clone(),
            in_use: true,
            last_frame: frame,
        });
        item
    }

    pub fn release_texture(&mut self, id: u64) {
        if let Some(p) = self.textures.iter_mut().find(|p| p.item.id == id) {
            p.in_use = false;
        }
    }

    pub fn acquire_buffer(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        size: u64,
        frame: u64,
    ) -> Arc<PhysicalBuffer> {
        if let Some(p) = self
            .buffers
            .iter_mut()
            .find(|p| !p.in_use && p.item.size == size)
        {
            p.in_use = true;
            p.last_frame = frame;
            return p.item.clone();
        }
        let item = PhysicalBuffer::create(ctx, name, size);
        self.stats.buffers_created += 1;
        self.buffers.push(Pooled {
            item: item.clone(),
            in_use: true,
            last_frame: frame,
        });
        item
    }

    pub fn release_buffer(&mut self, id: u64) {
        if let Some(p) = self.buffers.iter_mut().find(|p| p.item.id == id) {
            p.in_use = false;
        }
    }

    /// Frees what has not been used lately. Returns whether anything was freed.
    pub fn trim(&mut self, frame: u64) -> bool {
        let (nt, nb) = (self.textures.len(), self.buffers.len());
        for p in &mut self.textures {
            p.in_use = false;
        }
        for p in &mut self.buffers {
            p.in_use = false;
        }
        self.textures
            .retain(|p| frame.saturating_sub(p.last_frame) <= POOL_KEEP_FRAMES);
        self.buffers
            .retain(|p| frame.saturating_sub(p.last_frame) <= POOL_KEEP_FRAMES);
        self.stats.textures_alive = self.textures.len();
        self.stats.buffers_alive = self.buffers.len();
        nt != self.textures.len() || nb != self.buffers.len()
    }
}
