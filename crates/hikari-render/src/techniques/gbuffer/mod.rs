//! G-buffer: the compute rasteriser writes a visibility buffer, then `gbuffer.resolve` turns it
//! into the G-buffer textures. CPU twin: [`crate::techniques::gbuffer::reference`].

pub mod overrides;
pub mod reference;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{Buf, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::scene::raster::{RasterJob, RasterQueues, RasterTarget, RasterView, Rasterizer};
use crate::scene::upload::SceneInFrame;
use crate::shader::ShaderLibrary;
use crate::view::View;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const MATERIAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const MOTION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const EMISSIVE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const INSTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub const VERTEX_NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Snorm;
/// `gbuffer.instance` of sky pixels.
pub const NO_INSTANCE: u32 = u32::MAX;

/// The G-buffer of a frame.
#[derive(Clone, Copy, Debug)]
pub struct GBuffer {
    /// One u64 a pixel: reverse-Z depth bits << 32 | visibility id (0: sky).
    pub visibility: Buf,
    /// Reverse-Z NDC depth; 0 is the sky.
    pub depth: Tex,
    /// xy: octahedral shading normal; zw: octahedral anisotropy direction.
    pub normal: Tex,
    /// rgb: base colour; a: interior mask (0 outdoors, 1 indoors).
    pub albedo: Tex,
    /// Perceptual roughness, metalness, anisotropy strength, material occlusion.
    pub material: Tex,
    /// xy: previous minus current pixel position; z: view-space depth in metres.
    pub motion: Tex,
    /// Emitted luminance in nits.
    pub emissive: Tex,
    /// Scene instance index, [`NO_INSTANCE`] for the sky.
    pub instance: Tex,
    /// xyz: the interpolated vertex normal before the normal map (facing the camera on
    /// double-sided surfaces), for the reflection probes' horizon occlusion; 0 on the sky.
    pub vertex_normal: Tex,
}

pub struct GBufferPass {
    resolve: ComputePipeline,
}

impl GBufferPass {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            resolve: ComputePipeline::new(ctx, lib, "gbuffer/resolve.wgsl", "main", &[])?,
        })
    }

    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        raster: &'r Rasterizer,
        scene: &SceneInFrame,
        view: &View,
        size: [u32; 2],
        queues: &mut RasterQueues,
    ) -> Result<GBuffer> {
        self.record_as(g, raster, scene, view, size, queues, "gbuffer")
    }

    /// The G-buffer of another camera (a reflection probe's cube face), its textures and
    /// passes named `{name}.*` and its rasteriser queues its own.
    #[allow(clippy::too_many_arguments)]
    pub fn record_as<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        raster: &'r Rasterizer,
        scene: &SceneInFrame,
        view: &View,
        [width, height]: [u32; 2],
        queues: &mut RasterQueues,
        name: &str,
    ) -> Result<GBuffer> {
        let tex = |g: &mut FrameGraph<'r>, what: &str, format| {
            g.texture(
                &format!("{name}.{what}"),
                TextureDesc::d2(width, height, format),
            )
        };
        let gb = GBuffer {
            visibility: g.buffer(
                &format!("{name}.visibility"),
                width as u64 * height as u64 * 8,
            )?,
            depth: tex(g, "depth", DEPTH_FORMAT)?,
            normal: tex(g, "normal", NORMAL_FORMAT)?,
            albedo: tex(g, "albedo", ALBEDO_FORMAT)?,
            material: tex(g, "material", MATERIAL_FORMAT)?,
            motion: tex(g, "motion", MOTION_FORMAT)?,
            emissive: tex(g, "emissive", EMISSIVE_FORMAT)?,
            instance: tex(g, "instance", INSTANCE_FORMAT)?,
            vertex_normal: tex(g, "vertex_normal", VERTEX_NORMAL_FORMAT)?,
        };
        raster.record(
            g,
            scene,
            &RasterJob {
                technique: name,
                views: &[RasterView::full(view.view_proj(), 0, [width, height])],
                size: [width, height],
                cull_back_faces: true,
            },
            RasterTarget::Visibility,
            gb.visibility,
            queues,
        )?;
        g.pass(&format!("{name}.resolve"))
            .constants(view)
            .read(gb.visibility)
            .read(scene.positions)
            .read(scene.prev_positions)
            .read(scene.attributes)
            .read(scene.indices)
            .read(scene.instances)
            .read(scene.materials)
            .read(scene.chunks)
            .read(scene.color_textures)
            .read(scene.data_textures)
            .sampler(SamplerKind::LinearRepeat)
            .write(gb.depth)
            .write(gb.normal)
            .write(gb.albedo)
            .write(gb.material)
            .write(gb.motion)
            .write(gb.emissive)
            .write(gb.instance)
            .write(gb.vertex_normal)
            .dispatch_threads(&self.resolve, [width, height, 1])?;
        Ok(gb)
    }
}
