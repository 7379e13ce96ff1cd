//! A renderer: a GPU context, the techniques, an uploaded scene, and the frame graph's state.

use hikari_scene::Scene;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::frame::{self, FrameOutputs, FrameSettings, FrameState, Techniques};
use crate::graph::{FrameResult, GraphRuntime, ImageRgba32, Res};
use crate::raster::RasterQueues;
use crate::scene_gpu::SceneGpu;
use crate::scene_rt::{FrameBvhStats, SceneRt};
use crate::techniques::area_lights::AreaLightScene;

/// A rendered frame: timings, and the images if they were asked for.
pub struct RenderedFrame {
    pub result: FrameResult,
    pub hdr: Option<ImageRgba32>,
    pub ldr: Option<ImageRgba32>,
}

/// Frames drawn again at most after their rasteriser queues overflowed; each try grows the
/// queues to 1.5 times what the last one asked for, so one is nearly always enough.
const MAX_QUEUE_RETRIES: usize = 4;

pub struct Renderer {
    pub ctx: GpuContext,
    pub runtime: GraphRuntime,
    techniques: Techniques,
    scene: SceneGpu,
    /// The scene's area lights.
    area_lights: AreaLightScene,
    /// The one scene BVH of every ray the frame traces, updated each frame.
    scene_rt: SceneRt,
    /// The scene as given, for ray-traced GI's instance table (built on first use).
    scene_source: Scene,
    state: FrameState,
    /// Interactive mode: when the last frame began, for the exposure's adaptation.
    interactive_clock: Option<Option<std::time::Instant>>,
}

/// The longest frame time the exposure adapts over in one step (`exposure.frame_seconds`'s
/// limit): after a longer stall the exposure moves as if 8 s had passed.
const MAX_FRAME_SECONDS: f32 = 8.0;

impl Renderer {
    pub fn new(ctx: GpuContext, scene: &Scene) -> Result<Self> {
        let techniques = Techniques::new(&ctx)?;
        let scene_gpu = SceneGpu::upload(&ctx, scene)?;
        let area_lights = AreaLightScene::new(&ctx, scene)?;
        let scene_rt = SceneRt::new(&ctx, scene, &scene_gpu.textures.color)?;
        Ok(Self {
            area_lights,
            scene_rt,
            runtime: GraphRuntime::new(),
            techniques,
            scene: scene_gpu,
            scene_source: scene.clone(),
            state: FrameState::default(),
            interactive_clock: None,
            ctx,
        })
    }

    /// Uses `bake`'s irradiance probes from the next frame on (`None`: none, the sky's SH
    /// lights surfaces unoccluded). Non-finite numbers in the bake become 0.
    pub fn set_probe_bake(&mut self, bake: Option<&hikari_probes::Bake>) {
        self.techniques.irradiance_probes.set_bake(&self.ctx, bake);
    }

    /// Uses `probes` as the relit reflection probes from the next frame on (captured then);
    /// none: the sky's SH and the GI give the indirect specular light.
    pub fn set_reflection_probes(
        &mut self,
        probes: &[hikari_bake::reflection_probes::ReflectionProbeBox],
    ) -> Result<()> {
        self.techniques
            .reflection_probes
            .set_probes(&self.ctx, probes)
    }

    /// The irradiance probes (the uploaded bake's layout, the lookup pass's switch, the
    /// relight's timed dispatches), for `hikari bench probes`.
    pub fn irradiance_probes(&self) -> &crate::techniques::irradiance_probes::IrradianceProbes {
        &self.techniques.irradiance_probes
    }

    pub fn scene(&self) -> &SceneGpu {
        &self.scene
    }

    /// The scene's area lights.
    pub fn area_lights(&self) -> &AreaLightScene {
        &self.area_lights
    }

    /// The frame's scene BVH (its CPU side, `scene_rt.cpu`, is what the GPU traces).
    pub fn scene_rt(&self) -> &SceneRt {
        &self.scene_rt
    }

    /// What the last frame's BVH update cost (`None` before the first frame).
    pub fn scene_rt_stats(&self) -> Option<FrameBvhStats> {
        self.scene_rt.last_stats()
    }

    /// The rasteriser's queue sizes, which grow by themselves; for tests and tuning.
    pub fn raster_queues(&mut self) -> &mut RasterQueues {
        &mut self.state.raster_queues
    }

    /// Drops temporal history next frame (a camera cut).
    pub fn cut_camera(&mut self) {
        self.state.rtgi_reset = true;
    }

    /// Tests only: overwrites these G-buffer texels in every following frame, right after the
    /// G-buffer pass (bad input for the passes that read it); an empty list stops it. A
    /// rectangle outside the image or a texel of the wrong size makes the frame an error.
    pub fn override_gbuffer_texels(&mut self, texels: Vec<crate::frame::GBufferTexel>) {
        self.state.gbuffer_overrides = texels;
    }

    /// Renders one frame; with `read_images`, copies the HDR and LDR results back.
    pub fn render(&mut self, settings: &FrameSettings, read_images: bool) -> Result<RenderedFrame> {
        let mut picked = None;
        let mut result = self.render_reading(settings, |out| {
            picked = Some((out.hdr, out.ldr));
            if read_images {
                vec![out.hdr.into(), out.ldr.into()]
            } else {
                vec![]
            }
        })?;
        let (hdr, ldr) = match (read_images, picked) {
            (true, Some((hdr, ldr))) => (
                // TAA's history is the HDR output; its alpha counts frames, the EXR's is 1.
                result.take_image_of(hdr).map(|mut img| {
                    img.rgba.iter_mut().for_each(|p| p[3] = 1.0);
                    img
                }),
                result.take_image_of(ldr),
            ),
            _ => (None, None),
        };
        Ok(RenderedFrame { result, hdr, ldr })
    }

    /// Offline (the default): a frame whose rasteriser queues overflowed is drawn again with
    /// larger ones before it is shown, so that no triangle is ever lost, and each frame waits
    /// for its queue counts. Interactive: frames do not wait for each other; queues are sized
    /// from the counts of a frame or two before, with headroom, and a frame that overflowed
    /// is shown as it is (missing a few triangles for a frame) while the queues grow.
    /// Interactive frames also adapt the exposure over the wall-clock time since the previous
    /// frame began, unless the settings give `exposure.frame_seconds` themselves.
    pub fn set_interactive(&mut self, interactive: bool) {
        self.runtime.set_wait_for_readbacks(!interactive);
        self.interactive_clock = interactive.then_some(None);
    }

    /// Renders one frame and copies back whatever `pick` names of its resources (G-buffer
    /// textures, shadow maps...); they appear in the result under their graph names (or
    /// by handle, [`FrameResult::take_image_of`]). Temporal state advances once, when the
    /// frame is accepted: a frame drawn again after an overflow does not step it twice.
    pub fn render_reading(
        &mut self,
        settings: &FrameSettings,
        mut pick: impl FnMut(&FrameOutputs) -> Vec<Res>,
    ) -> Result<FrameResult> {
        let timed;
        let settings = match &mut self.interactive_clock {
            Some(last) if settings.settings.exposure.frame_seconds == 0.0 => {
                let now = std::time::Instant::now();
                let seconds = last.map_or(0.0, |t| (now - t).as_secs_f32().min(MAX_FRAME_SECONDS));
                *last = Some(now);
                let mut s = settings.clone();
                s.settings.exposure.frame_seconds = seconds;
                timed = s;
                &timed
            }
            _ => settings,
        };
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
        let invalid =
            |what: &str, e: hikari_scene::SceneError| RenderError::Graph(format!("{what}: {e}"));
        settings
            .camera
            .validate()
            .and_then(|()| {
                settings
                    .camera
                    .validate_projection(settings.width as f32 / settings.height.max(1) as f32)
            })
            .map_err(|e| invalid("camera", e))?;
        if let Some(prev) = &settings.prev_camera {
            prev.validate().map_err(|e| invalid("previous camera", e))?;
        }
        if let Some(sun) = &settings.sun {
            sun.validate().map_err(|e| invalid("sun", e))?;
        }
        if settings.settings.ray_traced_gi.enabled && self.state.rtgi_scene.is_none() {
            let rtgi =
                crate::techniques::ray_traced_gi::RtGiScene::new(&self.ctx, &self.scene_source)?;
            // BLAS refitted before the GI was turned on show a pose its tables do not.
            let cpu = &mut self.scene_rt.cpu;
            for mesh in cpu.animated_meshes().collect::<Vec<_>>() {
                if let Some(t) = cpu.shown_time(mesh)
                    && let Some((positions, _)) = cpu.pose_at(mesh, Some(t))
                {
                    rtgi.update_triangle_normals(&self.ctx, &self.scene_source, mesh, positions);
                }
            }
            self.state.rtgi_scene = Some(std::sync::Arc::new(rtgi));
        }
        // The BVH follows the frame: culled around this camera, deforming meshes at the
        // frame's time (refits throttled), and the raster's vertices at the same time.
        let aspect = settings.width as f32 / settings.height as f32;
        let view_proj = settings.camera.projection(aspect) * settings.camera.view();
        let rt = &settings.settings.scene_rt;
        let stats = self
            .scene_rt
            .update(&self.ctx, settings.camera.position, &view_proj, rt)?;
        // The GI's hit normals follow the refitted BLAS (its tables hold the rest pose).
        if let Some(rtgi) = self.state.rtgi_scene.clone() {
            for mesh in self.scene_rt.refitted().to_vec() {
                if let Some((positions, _)) = self.scene_rt.cpu.pose_at(mesh, rt.time_s) {
                    rtgi.update_triangle_normals(&self.ctx, &self.scene_source, mesh, positions);
                }
            }
        }
        if self
            .scene_rt
            .update_raster(&self.ctx, &self.scene, rt.time_s)
            > 0
        {
            // Cached cascades hold the old pose.
            self.state.shadow_cache = Default::default();
        }
        log::info!("{}", self.scene_rt.last_stats().unwrap_or(stats).summary());
        let binding_limit = self.ctx.limits.max_storage_buffer_binding_size;
        for _ in 0..MAX_QUEUE_RETRIES {
            let mut g = self.runtime.begin_frame(&self.ctx);
            let out = frame::record(
                &mut g,
                &self.techniques,
                &self.scene,
                &self.area_lights,
                &self.scene_rt,
                settings,
                &mut self.state,
            )?;
            for r in pick(&out) {
                g.readback(r);
            }
            let result = g.execute_uncommitted()?;
            let overflowed = !self
                .state
                .raster_queues
                .grow(&result, binding_limit)?
                .is_empty();
            if overflowed {
                // Cascades and cube maps drawn into an overflowing queue lack triangles: draw
                // them all again.
                self.state.shadow_cache = Default::default();
                self.techniques.reflection_probes.invalidate_capture();
            }
            // Interactive frames (the runtime does not wait for their counts) are shown as drawn.
            if !overflowed || !self.runtime.waits_for_readbacks() {
                self.runtime.commit_frame();
                return Ok(result);
            }
            self.runtime.discard_frame();
        }
        Err(RenderError::Graph(format!(
            "the rasteriser's queues still overflowed after {MAX_QUEUE_RETRIES} tries"
        )))
    }
}
