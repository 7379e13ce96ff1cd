//! A renderer: a GPU context, the techniques, an uploaded scene, and the frame graph's state.

use hikari_scene::Scene;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::frame::{self, FrameOutputs, FrameSettings, FrameState, Techniques};
use crate::graph::{FrameResult, GraphRuntime, ImageRgba32, Res};
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
    state: FrameState,
}

impl Renderer {
    pub fn new(ctx: GpuContext, scene: &Scene) -> Result<Self> {
        let techniques = Techniques::new(&ctx)?;
        let scene_gpu = SceneGpu::upload(&ctx, scene)?;
        Ok(Self {
            runtime: GraphRuntime::new(),
            techniques,
            scene: scene_gpu,
            state: FrameState::default(),
            ctx,
        })
    }

    pub fn scene(&self) -> &SceneGpu {
        &self.scene
    }

    /// Renders one frame; with `read_images`, copies the HDR and LDR results back.
    pub fn render(&mut self, settings: &FrameSettings, read_images: bool) -> Result<RenderedFrame> {
        let mut result = self.render_reading(settings, |out| {
            if read_images {
                vec![out.hdr.into(), out.ldr.into()]
            } else {
                vec![]
            }
        })?;
        let hdr = result.take_image("direct_lighting.radiance");
        let ldr = result.take_image("placeholder_tonemap.ldr");
        Ok(RenderedFrame { result, hdr, ldr })
    }

    /// Renders one frame and copies back whatever `pick` names of its resources (G-buffer
    /// textures, shadow maps...); they appear in the result under their graph names.
    pub fn render_reading(
        &mut self,
        settings: &FrameSettings,
        pick: impl FnOnce(&FrameOutputs) -> Vec<Res>,
    ) -> Result<FrameResult> {
        settings
            .settings
            .validate()
            .map_err(|e| RenderError::Graph(format!("settings: {e}")))?;
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
        let out = frame::record(
            &mut g,
            &self.techniques,
            &self.scene,
            settings,
            &mut self.state,
        )?;
        for r in pick(&out) {
            g.readback(r);
        }
        g.execute()
    }
}
