//! A renderer: a GPU context, the techniques, an uploaded scene, and the frame graph's state.

use hikari_scene::Scene;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::frame::{self, FrameSettings, Techniques};
use crate::graph::{FrameResult, GraphRuntime, ImageRgba32};
use crate::passes::direct_lighting::SunParams;
use crate::scene_gpu::SceneGpu;

/// A rendered frame: timings, and the images if they were asked for.
pub struct RenderedFrame {
    pub result: FrameResult,
    pub hdr: Option<ImageRgba32>,
    pub ldr: Option<ImageRgba32>,
}

pub struct Renderer {
    pub ctx: GpuContext,
    pub runtime: GraphRuntime,
    techniques: Techniques,
    scene: SceneGpu,
    sun: SunParams,
}

impl Renderer {
    pub fn new(ctx: GpuContext, scene: &Scene) -> Result<Self> {
        let techniques = Techniques::new(&ctx)?;
        let scene_gpu = SceneGpu::upload(&ctx, scene)?;
        Ok(Self {
            sun: SunParams::new(scene.sun.as_ref()),
            runtime: GraphRuntime::new(),
            techniques,
            scene: scene_gpu,
            ctx,
        })
    }

    pub fn scene(&self) -> &SceneGpu {
        &self.scene
    }

    /// Renders one frame; with `read_images`, copies the HDR and LDR results back.
    pub fn render(&mut self, settings: &FrameSettings, read_images: bool) -> Result<RenderedFrame> {
        let limit = self.ctx.limits.max_texture_dimension_2d;
        for (what, v) in [("width", settings.width), ("height", settings.height)] {
            if v == 0 || v > limit {
                return Err(RenderError::Limit {
                    what: format!("image {what}"),
                    requested: v as u64,
                    limit: limit as u64,
                });
            }
        }
        let mut g = self.runtime.begin_frame(&self.ctx);
        let out = frame::record(&mut g, &self.techniques, &self.scene, &self.sun, settings)?;
        if read_images {
            g.readback(out.hdr);
            g.readback(out.ldr);
        }
        let mut result = g.execute()?;
        let (hdr, ldr) = if read_images {
            let take = |r: &mut FrameResult, name: &str| {
                r.images
                    .iter()
                    .position(|i| i.name == name)
                    .map(|i| r.images.remove(i))
            };
            (
                take(&mut result, "direct_lighting.radiance"),
                take(&mut result, "placeholder_tonemap.ldr"),
            )
        } else {
            (None, None)
        };
        Ok(RenderedFrame { result, hdr, ldr })
    }
}
