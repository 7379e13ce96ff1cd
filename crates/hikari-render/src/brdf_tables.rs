//! The BRDF's directional albedo tables (hikari-math, docs/brdf.md) on the GPU: one storage
//! buffer, uploaded once, bound as the binding set `brdf_tables` of `hikari::brdf_tables` by
//! every pass that evaluates `hikari::brdf`.

use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::graph::{BindingSet, FrameGraph};

pub struct BrdfTables {
    buffer: wgpu::Buffer,
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
        Self { buffer }
    }

    /// The binding set `brdf_tables` for this frame.
    pub fn binding_set(&self, g: &mut FrameGraph<'_>) -> BindingSet {
        let b = g.import_buffer("brdf.tables", &self.buffer);
        g.binding_set("brdf_tables").read(b).finish()
    }
}
