//! The BRDF's directional albedo tables (hikari-math, docs/brdf.md) on the GPU: one storage
//! buffer, uploaded once, bound as the binding set `brdf_tables` of `hikari::brdf_tables` by
//! every pass that evaluates `hikari::brdf`.

use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::graph::{BindingSet, FrameGraph, SamplerKind};

pub struct BrdfTables {
    buffer: wgpu::Buffer,
    /// The N x N (E, E_w) entries as a filterable texture: Rg32Float where the adapter filters
    /// 32-bit floats, else Rgba16Float.
    texture: wgpu::Texture,
}

impl BrdfTables {
    pub fn new(ctx: &GpuContext) -> Self {
        let data = hikari_math::brdf::albedo::albedo_tables().gpu_data();
        let buffer = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("brdf.tables"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let n = hikari_math::brdf::albedo::ALBEDO_TABLE_SIZE as u32;
        let grid = &data[..(n * n) as usize];
        let (format, bytes): (wgpu::TextureFormat, Vec<u8>) =
            if ctx.features.contains(wgpu::Features::FLOAT32_FILTERABLE) {
                (
                    wgpu::TextureFormat::Rg32Float,
                    bytemuck::cast_slice(grid).to_vec(),
                )
            } else {
                let halves: Vec<half::f16> = grid
                    .iter()
                    .flat_map(|[e, w]| [*e, *w, 0.0, 0.0].map(half::f16::from_f32))
                    .collect();
                (
                    wgpu::TextureFormat::Rgba16Float,
                    bytemuck::cast_slice(&halves).to_vec(),
                )
            };
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("brdf.albedo"),
                size: wgpu::Extent3d {
                    width: n,
                    height: n,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &bytes,
        );
        Self { buffer, texture }
    }

    /// The binding set `brdf_tables` for this frame.
    pub fn binding_set(&self, g: &mut FrameGraph<'_>) -> BindingSet {
        let b = g.import_buffer("brdf.tables", &self.buffer);
        let t = g.import_texture("brdf.albedo", &self.texture);
        g.binding_set("brdf_tables")
            .read(b)
            .read(t)
            .sampler(SamplerKind::LinearClamp)
            .finish()
    }
}
