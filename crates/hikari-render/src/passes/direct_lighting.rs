//! Deferred direct light from the sun, with placeholder sky and ambient light.
//! CPU twin: [`crate::reference::direct_lighting`].

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use hikari_scene::Sun;

use super::gbuffer::GBuffer;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::view::View;

pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SunParams {
    pub direction_lux: [f32; 4],
    pub color: [f32; 4],
    pub sky_zenith: [f32; 4],
    pub sky_horizon: [f32; 4],
}

/// Placeholder sky radiance (nits) until the atmosphere issue: a clear-day blue zenith and a
/// paler horizon, of the order of a real clear sky (a few thousand nits).
pub const PLACEHOLDER_SKY_ZENITH: Vec3 = Vec3::new(1800.0, 3200.0, 6500.0);
pub const PLACEHOLDER_SKY_HORIZON: Vec3 = Vec3::new(6000.0, 7000.0, 8000.0);

impl SunParams {
    pub fn new(sun: Option<&Sun>) -> Self {
        let (dir, lux, color) = match sun {
            Some(s) => (s.direction.normalize(), s.illuminance_lux, s.color),
            None => (Vec3::Y, 0.0, Vec3::ONE),
        };
        Self {
            direction_lux: dir.extend(lux).to_array(),
            color: color.extend(1.0).to_array(),
            sky_zenith: PLACEHOLDER_SKY_ZENITH.extend(0.0).to_array(),
            sky_horizon: PLACEHOLDER_SKY_HORIZON.extend(0.0).to_array(),
        }
    }
}

pub struct DirectLighting {
    sun: ComputePipeline,
}

impl DirectLighting {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            sun: ComputePipeline::new(ctx, lib, "direct_lighting/sun.wgsl", "main", &[])?,
        })
    }

    /// Radiance in nits of every pixel: lit surfaces, or the placeholder sky where depth is 0.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        gb: &GBuffer,
        view: &View,
        params: &SunParams,
    ) -> Result<Tex> {
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let radiance = g.texture(
            "direct_lighting.radiance",
            TextureDesc::d2(w, h, RADIANCE_FORMAT),
        )?;
        g.pass("direct_lighting.sun")
            .constants(view)
            .read(gb.depth)
            .read(gb.normal)
            .read(gb.albedo)
            .write(radiance)
            .constants(params)
            .dispatch_threads(&self.sun, [w, h, 1])?;
        Ok(radiance)
    }
}
