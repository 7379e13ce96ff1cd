//! G-buffer: depth (reverse-Z), octahedral normal, base colour and roughness.

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::{RasterDesc, RasterPipeline};
use crate::scene_gpu::SceneGpu;
use crate::shader::ShaderLibrary;
use crate::view::View;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The G-buffer textures of a frame.
#[derive(Clone, Copy, Debug)]
pub struct GBuffer {
    pub depth: Tex,
    pub normal: Tex,
    pub albedo: Tex,
}

pub struct GBufferPass {
    draw: RasterPipeline,
}

impl GBufferPass {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let draw = RasterPipeline::new(
            ctx,
            lib,
            "gbuffer/draw.wgsl",
            &RasterDesc {
                vertex_entry: "vs",
                fragment_entry: Some("fs"),
                color_formats: &[NORMAL_FORMAT, ALBEDO_FORMAT],
                depth: Some((DEPTH_FORMAT, wgpu::CompareFunction::Greater)),
                cull_mode: Some(wgpu::Face::Back),
            },
            &[],
        )?;
        Ok(Self { draw })
    }

    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        scene: &'r SceneGpu,
        view: &View,
        [width, height]: [u32; 2],
    ) -> Result<GBuffer> {
        let gb = GBuffer {
            depth: g.texture(
                "gbuffer.depth",
                TextureDesc::d2(width, height, DEPTH_FORMAT),
            )?,
            normal: g.texture(
                "gbuffer.normal",
                TextureDesc::d2(width, height, NORMAL_FORMAT),
            )?,
            albedo: g.texture(
                "gbuffer.albedo",
                TextureDesc::d2(width, height, ALBEDO_FORMAT),
            )?,
        };
        let vertices = g.import_buffer("scene.vertices", &scene.vertices);
        let instances = g.import_buffer("scene.instances", &scene.instances);
        let indices = g.import_buffer("scene.indices", &scene.indices);
        let draws = &scene.draws;
        g.pass("gbuffer.draw")
            .constants(view)
            .read(vertices)
            .read(instances)
            .uses(indices, false)
            .color(gb.normal, Some([0.0; 4]))
            .color(gb.albedo, Some([0.0; 4]))
            .depth(gb.depth, Some(0.0))
            .draw(&self.draw, move |rp, res| {
                rp.set_index_buffer(res.buffer(indices).slice(..), wgpu::IndexFormat::Uint32);
                for d in draws {
                    rp.draw_indexed(
                        d.first_index..d.first_index + d.index_count,
                        d.base_vertex,
                        d.instance..d.instance + 1,
                    );
                }
            })?;
        Ok(gb)
    }
}
