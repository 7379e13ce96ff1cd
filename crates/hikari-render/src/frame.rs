//! One frame, top to bottom. Each numbered step is the step of the same number in
//! ARCHITECTURE.md; the steps not yet built say which issue brings them.

use hikari_scene::Camera;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex};
use crate::passes::direct_lighting::{DirectLighting, SunParams};
use crate::passes::gbuffer::GBufferPass;
use crate::passes::placeholder_tonemap::{PlaceholderTonemap, TonemapParams};
use crate::scene_gpu::SceneGpu;
use crate::shader::{self, ShaderLibrary};
use crate::view::View;

/// What a frame depends on besides the scene.
#[derive(Clone, Debug)]
pub struct FrameSettings {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    /// Exposure value at ISO 100 of the placeholder exposure.
    pub ev100: f32,
}

/// Every technique's pipelines, built once.
pub struct Techniques {
    pub gbuffer: GBufferPass,
    pub direct_lighting: DirectLighting,
    pub placeholder_tonemap: PlaceholderTonemap,
}

impl Techniques {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features))?;
        Ok(Self {
            gbuffer: GBufferPass::new(ctx, &mut lib)?,
            direct_lighting: DirectLighting::new(ctx, &mut lib)?,
            placeholder_tonemap: PlaceholderTonemap::new(ctx, &mut lib)?,
        })
    }
}

/// The frame's final images.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    /// Linear radiance in nits (Rgba16Float), for the EXR.
    pub hdr: Tex,
    /// Display-encoded sRGB (Rgba8Unorm), for the PNG.
    pub ldr: Tex,
}

pub fn record<'r>(
    g: &mut FrameGraph<'r>,
    t: &'r Techniques,
    scene: &'r SceneGpu,
    sun: &SunParams,
    s: &FrameSettings,
) -> Result<FrameOutputs> {
    let size = [s.width, s.height];

    // 1. Update: camera; the sun comes from the scene until the atmosphere issue derives it
    //    from time and date.
    let view = View::new(&s.camera, s.width, s.height);

    // 2. Atmosphere LUTs, 3. sky SH, 4. irradiance probes, 5. reflection probes, 6. clouds,
    //    7. shadow maps: their issues add them here.

    // 8. G-buffer.
    let gbuffer = t.gbuffer.record(g, scene, &view, size)?;

    // 9. Ray tracing and 10. denoising: the ray-tracing issues add them here.

    // 11. Deferred lighting (sun, placeholder sky and ambient).
    let hdr = t.direct_lighting.record(g, &gbuffer, &view, sun)?;

    // 12. Haze and 13. TAA: their issues add them here.

    // 14. Exposure and tonemap (placeholder).
    let ldr = t
        .placeholder_tonemap
        .record(g, hdr, size, &TonemapParams::from_ev100(s.ev100))?;

    Ok(FrameOutputs { hdr, ldr })
}
