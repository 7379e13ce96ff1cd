//! The shadow denoiser (docs/area-lights.md, "Denoising the shadows"): the area-light pass's
//! shadowed light over its unshadowed light is the visibility, which `area_lights.temporal`
//! accumulates over frames and `area_lights.spatial` filters; the pixel's light is then the
//! noise-free unshadowed light times that visibility. CPU twins: [`super::reference`]'s
//! `denoise_temporal` and `denoise_spatial`.

use bytemuck::{Pod, Zeroable};

use super::settings::{AreaLightsSettings, MAX_DENOISE_RADIUS_PX};
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::view::View;

/// [`ShadowDenoiseParams::config`] `.x` bit: drop the history this frame.
pub const SHADOW_DENOISE_RESET: u32 = 1;

/// Fraction of view depth by which a history texel's depth may differ from where this
/// point was seen last frame (as ray-traced GI's accumulation's default).
pub const HISTORY_DEPTH_TOLERANCE: f32 = 0.05;

/// Distance to the centre's tangent plane, as a fraction of view depth, at which a spatial
/// tap's weight reaches 0 (as the GI denoiser's default).
pub const PLANE_TOLERANCE: f32 = 0.01;

/// Light (nits, lux) below which a channel's visibility is undefined (the shader's
/// `VISIBILITY_EPS`).
pub const VISIBILITY_EPS: f32 = 1e-5;

/// Largest visibility kept (the shader's `MAX_VISIBILITY`).
pub const MAX_VISIBILITY: f32 = 1024.0;

/// Format of the visibility textures (rgb: radiance channels, a: illuminance).
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const LENGTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The denoiser's uniform (`hikari::area_lights_denoise::ShadowDenoiseParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ShadowDenoiseParams {
    /// `SHADOW_DENOISE_*` flags, history length cap (frames), 0, 0.
    pub config: [u32; 4],
    /// History depth tolerance, plane tolerance (fractions of view depth), spatial radius in
    /// pixels on a fresh history, 0.
    pub values: [f32; 4],
}

impl ShadowDenoiseParams {
    /// `reset`: drop the history (a camera cut).
    pub fn new(s: &AreaLightsSettings, reset: bool) -> Self {
        Self {
            config: [
                if reset { SHADOW_DENOISE_RESET } else { 0 },
                s.denoise_history.max(1),
                0,
                0,
            ],
            values: [
                HISTORY_DEPTH_TOLERANCE,
                PLANE_TOLERANCE,
                s.denoise_radius_px.clamp(0.0, MAX_DENOISE_RADIUS_PX),
                0.0,
            ],
        }
    }

    pub fn reset(&self) -> bool {
        self.config[0] & SHADOW_DENOISE_RESET != 0
    }
}

/// The G-buffer and area-light textures the denoiser reads.
#[derive(Clone, Copy, Debug)]
pub struct ShadowDenoiseInputs {
    pub depth: Tex,
    pub normal: Tex,
    pub motion: Tex,
    /// `area_lights.radiance`: the shadowed light (nits, lux in a).
    pub shadowed: Tex,
    /// `area_lights.unshadowed`: the same lights without shadows.
    pub unshadowed: Tex,
}

/// What the denoiser writes, by the names `--dump` takes.
#[derive(Clone, Copy, Debug)]
pub struct DenoisedShadows {
    /// `area_lights.visibility_raw`: this frame's visibility, per channel.
    pub raw: Tex,
    /// `area_lights.visibility_accumulated`: the history after this frame.
    pub accumulated: Tex,
    /// `area_lights.visibility_history_length`: frames in it (R16Float; 0 on the sky).
    pub history_length: Tex,
    /// `area_lights.visibility_filtered`: after the spatial filter.
    pub filtered: Tex,
    /// `area_lights.denoised`: the pixel's light (nits, lux in a), what the deferred lighting
    /// adds.
    pub radiance: Tex,
}

pub struct ShadowDenoiser {
    temporal: ComputePipeline,
    spatial: ComputePipeline,
}

impl ShadowDenoiser {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            temporal: ComputePipeline::new(ctx, lib, "area_lights/temporal.wgsl", "main", &[])?,
            spatial: ComputePipeline::new(ctx, lib, "area_lights/spatial.wgsl", "main", &[])?,
        })
    }

    /// Both passes over a `size` image. The history is kept under `area_lights.visibility_*`;
    /// a resize or the first frame drops it, as `params`' reset does.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        view: &View,
        params: &ShadowDenoiseParams,
        inputs: &ShadowDenoiseInputs,
        size: [u32; 2],
    ) -> Result<DenoisedShadows> {
        let [w, h] = size;
        let d2 = |format| TextureDesc::d2(w, h, format);
        let raw = g.texture("area_lights.visibility_raw", d2(VISIBILITY_FORMAT))?;
        let vis = g.history_texture("area_lights.visibility_accumulated", d2(VISIBILITY_FORMAT))?;
        let len = g.history_texture("area_lights.visibility_history_length", d2(LENGTH_FORMAT))?;
        let vz = g.history_texture("area_lights.visibility_view_depth", d2(DEPTH_FORMAT))?;
        let mut params = *params;
        if !(vis.valid && len.valid && vz.valid) {
            params.config[0] |= SHADOW_DENOISE_RESET;
        }
        g.pass("area_lights.temporal")
            .constants(view)
            .constants(&params)
            .read(inputs.depth)
            .read(inputs.motion)
            .read(inputs.shadowed)
            .read(inputs.unshadowed)
            .read(vis.prev)
            .read(len.prev)
            .read(vz.prev)
            .write(raw)
            .write(vis.cur)
            .write(len.cur)
            .write(vz.cur)
            .dispatch_threads(&self.temporal, [w, h, 1])?;
        let filtered = g.texture("area_lights.visibility_filtered", d2(VISIBILITY_FORMAT))?;
        let radiance = g.texture("area_lights.denoised", d2(crate::lights::RADIANCE_FORMAT))?;
        g.pass("area_lights.spatial")
            .constants(view)
            .constants(&params)
            .read(inputs.depth)
            .read(inputs.normal)
            .read(vis.cur)
            .read(len.cur)
            .read(inputs.shadowed)
            .read(inputs.unshadowed)
            .write(filtered)
            .write(radiance)
            .dispatch_threads(&self.spatial, [w, h, 1])?;
        Ok(DenoisedShadows {
            raw,
            accumulated: vis.cur,
            history_length: len.cur,
            filtered,
            radiance,
        })
    }
}
