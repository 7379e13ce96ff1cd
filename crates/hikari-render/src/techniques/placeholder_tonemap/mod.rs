//! PLACEHOLDER exposure and tonemap, until the tonemapping issue replaces it.
//! CPU twin: [`crate::techniques::placeholder_tonemap::reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TonemapParams {
    pub exposure: [f32; 4],
}

impl TonemapParams {
    pub fn from_ev100(ev100: f32) -> Self {
        Self {
            exposure: [
                crate::techniques::placeholder_tonemap::reference::exposure_from_ev100(ev100),
                0.0,
                0.0,
                0.0,
            ],
        }
    }
}

pub struct PlaceholderTonemap {
    apply: ComputePipeline,
}

impl PlaceholderTonemap {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            apply: ComputePipeline::new(ctx, lib, "placeholder_tonemap/apply.wgsl", "main", &[])?,
        })
    }

    /// sRGB-encoded 8-bit image of `hdr` (radiance in nits).
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        hdr: Tex,
        size: [u32; 2],
        params: &TonemapParams,
    ) -> Result<Tex> {
        let ldr = g.texture(
            "placeholder_tonemap.ldr",
            TextureDesc::d2(size[0], size[1], LDR_FORMAT),
        )?;
        g.pass("placeholder_tonemap.apply")
            .read(hdr)
            .write(ldr)
            .constants(params)
            .dispatch_threads(&self.apply, [size[0], size[1], 1])?;
        Ok(ldr)
    }
}
