//! A renderer: a GPU context, the techniques, an uploaded scene, and the frame graph's state.

use hikari_scene::{Camera, Scene};

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::frame::{self, FrameOutputs, FrameState, Techniques};
use crate::frame_context::{FrameContext, FrameSettings, HistoryReset, HistoryValidity, SunSource};
use crate::graph::{FrameResult, GraphRuntime, ImageRgba32, Res};
use crate::scene::raster::RasterQueues;
use crate::scene::rt::{FrameBvhStats, SceneRt};
use crate::scene::upload::SceneGpu;
use crate::techniques::area_lights::AreaLightScene;

/// A rendered frame: timings, and the images if they were asked for.
pub struct RenderedFrame {
    pub result: FrameResult,
    pub hdr: Option<ImageRgba32>,
    pub ldr: Option<ImageRgba32>,
}

/// What [`Renderer::frame_into`] writes into the caller's texture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Display {
    /// A texture of the frame by its graph name (`gbuffer.normal`: the names `--dump` knows);
    /// `None`: the final image.
    pub source: Option<String>,
    /// How its values are shown; `None`: the mapping that suits its name
    /// ([`crate::techniques::debug_view::Mapping::for_name`]) at the frame's exposure.
    pub mapping: Option<crate::techniques::debug_view::Mapping>,
}

/// A frame written into a caller's texture.
pub struct DisplayedFrame {
    pub result: FrameResult,
    /// The names of the frame's textures that [`Display::source`] can show.
    pub names: Vec<String>,
}

/// Frames drawn again at most after their rasteriser queues overflowed; each try grows the
/// queues to 1.5 times what the last one asked for, so one is nearly always enough.
const MAX_QUEUE_RETRIES: usize = 4;

pub struct Renderer {
    pub ctx: GpuContext,
    pub runtime: GraphRuntime,
    /// The pipelines, compiled once per device and shared by its renderers.
    techniques: std::sync::Arc<Techniques>,
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
    /// The live frame that [`Renderer::frame`] draws, changed by the setters between frames.
    live: Option<FrameSettings>,
    /// The camera pose, size and render scale (bits) of the last frame rendered, to tell a
    /// cut or a resize.
    last_pose: Option<([f32; 6], [u32; 3])>,
    /// A reason to drop temporal history that the next frame takes up.
    pending_reset: Option<HistoryReset>,
    /// The context of the last frame rendered.
    last_context: Option<FrameContext>,
}

/// The longest frame time the exposure adapts over in one step (`exposure.frame_seconds`'s
/// limit): after a longer stall the exposure moves as if 8 s had passed.
const MAX_FRAME_SECONDS: f32 = 8.0;

impl Renderer {
    pub fn new(ctx: GpuContext, scene: &Scene) -> Result<Self> {
        let techniques = ctx.shared(|| Techniques::new(&ctx))?;
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
            live: None,
            last_pose: None,
            pending_reset: None,
            last_context: None,
            ctx,
        })
    }

    /// Replaces the scene: its geometry, materials, lights and BVH are uploaded anew, the
    /// probe bake and reflection probes are dropped (attach the new scene's with
    /// [`Renderer::set_probe_bake`] and [`Renderer::set_reflection_probes`]) and the next frame
    /// starts without temporal history. On an error the old scene stays.
    pub fn reload_scene(&mut self, scene: &Scene) -> Result<()> {
        let scene_gpu = SceneGpu::upload(&self.ctx, scene)?;
        let area_lights = AreaLightScene::new(&self.ctx, scene)?;
        let scene_rt = SceneRt::new(&self.ctx, scene, &scene_gpu.textures.color)?;
        self.scene = scene_gpu;
        self.area_lights = area_lights;
        self.scene_rt = scene_rt;
        self.scene_source = scene.clone();
        let queues = std::mem::take(&mut self.state.raster_queues);
        self.state = FrameState {
            raster_queues: queues,
            ..FrameState::default()
        };
        self.pending_reset = Some(HistoryReset::SceneChange);
        Ok(())
    }

    // ---- The live renderer API: set what the next frame shows, then call `frame`. ----

    /// Sets the whole live frame (size, camera, sun source, settings) that [`Renderer::frame`]
    /// draws; the setters below change parts of it. Validates it first.
    pub fn set_frame(&mut self, frame: FrameSettings) -> Result<()> {
        self.validate(&frame)?;
        if let Some(old) = &self.live {
            if old.settings.switches() != frame.settings.switches() {
                self.pending_reset
                    .get_or_insert(HistoryReset::SettingsChange);
            } else if crate::frame_context::light_jumps(old, &frame) {
                self.pending_reset.get_or_insert(HistoryReset::LightJump);
            }
        }
        self.live = Some(frame);
        Ok(())
    }

    /// The live frame, once [`Renderer::set_frame`] has given one.
    pub fn live_frame(&self) -> Option<&FrameSettings> {
        self.live.as_ref()
    }

    fn live_mut(&mut self) -> Result<&mut FrameSettings> {
        self.live.as_mut().ok_or_else(|| {
            RenderError::Graph("the live frame is not set: call Renderer::set_frame first".into())
        })
    }

    /// Changes the live frame with `change`, keeping the old one if the result is not valid.
    fn change_live(&mut self, change: impl FnOnce(&mut FrameSettings)) -> Result<()> {
        let mut next = self.live_mut()?.clone();
        change(&mut next);
        self.set_frame(next)
    }

    /// Sets every settings field at once. A technique switched on or off drops the temporal
    /// history; any other change keeps it, so that the image follows the change smoothly.
    pub fn set_settings(&mut self, settings: crate::Settings) -> Result<()> {
        self.change_live(|f| f.settings = settings)
    }

    /// Sets the sky's clock: local date `YYYY-MM-DD` and time `HH:MM[:SS]`. The sun or moon,
    /// sky, clouds, probes and haze follow from the next frame on; the temporal history is
    /// kept for a small step and dropped when the light jumps
    /// ([`crate::HistoryReset::LightJump`]).
    pub fn set_clock(&mut self, date: &str, time: &str) -> Result<()> {
        self.change_live(|f| {
            f.settings.sky.date = date.into();
            f.settings.sky.time = time.into();
        })
    }

    /// Sets the local time of day in seconds after midnight (wrapped into one day, to the
    /// nearest second), keeping the date.
    pub fn set_time_of_day(&mut self, seconds: f64) -> Result<()> {
        if !seconds.is_finite() {
            return Err(crate::settings::SettingError {
                field: "sky.time".into(),
                value: seconds.to_string(),
                allowed: "a finite number of seconds".into(),
            }
            .into());
        }
        let s = (seconds.rem_euclid(86_400.0).round() as u32) % 86_400;
        let time = format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
        self.change_live(|f| f.settings.sky.time = time)
    }

    /// Sets the place: latitude and longitude in degrees, the local time's UTC offset in hours.
    pub fn set_place(
        &mut self,
        latitude_deg: f64,
        longitude_deg: f64,
        utc_offset_h: f64,
    ) -> Result<()> {
        self.change_live(|f| {
            let sky = &mut f.settings.sky;
            sky.latitude_deg = latitude_deg;
            sky.longitude_deg = longitude_deg;
            sky.utc_offset_h = utc_offset_h;
        })
    }

    /// Sets the weather preset (`clear`, `hazy`, `overcast`); the atmosphere's tables are
    /// rebuilt once for it.
    pub fn set_weather(&mut self, weather: &str) -> Result<()> {
        self.change_live(|f| f.settings.sky.weather = weather.into())
    }

    /// Sets where the directional light comes from.
    pub fn set_sun_source(&mut self, sun: SunSource) -> Result<()> {
        self.change_live(|f| f.sun = sun)
    }

    /// Moves the camera. Moving (`cut` false) keeps the temporal history, reprojected by the
    /// motion from the last frame's camera; a cut (a jump to another view) drops it.
    pub fn set_camera(&mut self, camera: Camera, cut: bool) -> Result<()> {
        let f = self.live_mut()?;
        let old = std::mem::replace(&mut f.camera, camera);
        if cut {
            f.prev_camera = None;
        } else if f.prev_camera.is_none() {
            f.prev_camera = Some(old);
        }
        let next = f.clone();
        if let Err(e) = self.validate(&next) {
            let f = self.live_mut()?;
            f.camera = f.prev_camera.take().unwrap_or_else(|| f.camera.clone());
            return Err(e);
        }
        if cut {
            self.pending_reset.get_or_insert(HistoryReset::CameraCut);
        }
        Ok(())
    }

    /// Sets the output size; the frame's textures are reallocated and history restarts.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        self.change_live(|f| {
            f.width = width;
            f.height = height;
        })
    }

    /// Renders the live frame ([`Renderer::set_frame`] and the setters), reading the images
    /// back with `read_images`.
    pub fn frame(&mut self, read_images: bool) -> Result<RenderedFrame> {
        let f = self.live_mut()?.clone();
        let out = self.render(&f, read_images)?;
        // The camera shown becomes the one the next frame's motion starts from.
        self.live_mut()?.prev_camera = None;
        Ok(out)
    }

    /// The frame context of the last frame rendered: its sun or moon, metered light, history
    /// validity and why, for viewers and tests.
    pub fn last_context(&self) -> Option<&FrameContext> {
        self.last_context.as_ref()
    }

    /// Checks a frame's settings, size and cameras before anything is recorded; the error
    /// names the field, the limit or the camera.
    pub fn validate(&self, settings: &FrameSettings) -> Result<()> {
        settings.settings.validate()?;
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
        let invalid = |what: &str, source: hikari_scene::SceneError| RenderError::Scene {
            what: what.into(),
            source: Box::new(source),
        };
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
        if let SunSource::Fixed(sun) = &settings.sun {
            sun.validate().map_err(|e| invalid("sun", e))?;
        }
        Ok(())
    }

    /// Why the next frame of `settings` may not use the history, if it may not: a reason
    /// given by a setter, the first frame, a new size, or a camera that moved while claiming
    /// it did not (a cut).
    fn history_for(&mut self, settings: &FrameSettings) -> HistoryValidity {
        // The output's size and the size rendered at: a new render scale is a new size.
        let size = [
            settings.width,
            settings.height,
            settings.settings.taa.render_scale.to_bits(),
        ];
        let pose = camera_pose(&settings.camera);
        let reset = self.pending_reset.take().or(match self.last_pose {
            None => Some(HistoryReset::FirstFrame),
            Some((_, s)) if s != size => Some(HistoryReset::Resize),
            Some((p, _)) if settings.prev_camera.is_none() && p != pose => {
                Some(HistoryReset::CameraCut)
            }
            _ => None,
        });
        self.last_pose = Some((pose, size));
        HistoryValidity { reset }
    }

    /// Uses `bake`'s irradiance probes from the next frame on (`None`: none, the sky's SH
    /// lights surfaces unoccluded). Non-finite numbers in the bake become 0; a bake past the
    /// device's buffer limits is an error naming the buffer.
    pub fn set_probe_bake(&mut self, bake: Option<&hikari_probes::Bake>) -> Result<()> {
        self.state
            .techniques
            .irradiance_probes
            .set_bake(&self.ctx, bake)
    }

    /// Uses `probes` as the relit reflection probes from the next frame on (captured then);
    /// none: the sky's SH and the GI give the indirect specular light.
    pub fn set_reflection_probes(
        &mut self,
        probes: &[hikari_bake::reflection_probes::ReflectionProbeBox],
    ) -> Result<()> {
        self.state
            .techniques
            .reflection_probes
            .set_probes(&self.ctx, probes)
    }

    /// The irradiance probes' passes (the relight's timed dispatches), for `hikari bench probes`.
    pub fn irradiance_probes(&self) -> &crate::techniques::irradiance_probes::IrradianceProbes {
        &self.techniques.irradiance_probes
    }

    /// The irradiance probes' state (the uploaded bake's layout, the lookup pass's switch).
    pub fn irradiance_probes_state(
        &mut self,
    ) -> &mut crate::techniques::irradiance_probes::IrradianceProbesState {
        &mut self.state.techniques.irradiance_probes
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

    /// Drops temporal history next frame (a camera cut), in every temporal pass.
    pub fn cut_camera(&mut self) {
        self.pending_reset.get_or_insert(HistoryReset::CameraCut);
    }

    /// Tests only: overwrites these G-buffer texels in every following frame, right after the
    /// G-buffer pass (bad input for the passes that read it); an empty list stops it. A
    /// rectangle outside the image or a texel of the wrong size makes the frame an error.
    pub fn override_gbuffer_texels(
        &mut self,
        texels: Vec<crate::techniques::gbuffer::overrides::GBufferTexel>,
    ) {
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
        pick: impl FnMut(&FrameOutputs) -> Vec<Res>,
    ) -> Result<FrameResult> {
        self.render_with(settings, pick, |_, _, _, _| Ok(()))
    }

    /// Renders the live frame ([`Renderer::set_frame`]) and writes what `display` names into
    /// `target`, a texture of [`crate::techniques::debug_view::TARGET_FORMAT`] with
    /// `STORAGE_BINDING` usage that the caller owns (a window's picture), at its size. Nothing
    /// is read back: with [`Renderer::set_interactive`] no frame waits for the GPU.
    pub fn frame_into(
        &mut self,
        target: &wgpu::Texture,
        display: &Display,
    ) -> Result<DisplayedFrame> {
        let f = self.live_mut()?.clone();
        let mut names = Vec::new();
        let result = self.render_with(
            &f,
            |_| vec![],
            |g, t, cx, out| {
                let to = g.import_texture("debug_view.target", target);
                let (source, mapping) = match &display.source {
                    None => (out.ldr, crate::techniques::debug_view::Mapping::Raw),
                    Some(name) => {
                        let tex = g.find_written_texture(name).ok_or_else(|| {
                            RenderError::Graph(format!(
                                "display: no texture `{name}` in this frame; there are: {}",
                                g.written_texture_names().join(", ")
                            ))
                        })?;
                        let mapping = display.mapping.unwrap_or_else(|| {
                            crate::techniques::debug_view::Mapping::for_name(name, cx.ev100)
                        });
                        (tex, mapping)
                    }
                };
                t.debug_view.record(g, source, &mapping, to)?;
                names = g.written_texture_names();
                Ok(())
            },
        )?;
        self.live_mut()?.prev_camera = None;
        Ok(DisplayedFrame { result, names })
    }

    /// [`Renderer::render_reading`], with `finish` recording passes after the frame's own
    /// (the window's picture) from its outputs.
    fn render_with(
        &mut self,
        settings: &FrameSettings,
        mut pick: impl FnMut(&FrameOutputs) -> Vec<Res>,
        mut finish: impl for<'r> FnMut(
            &mut crate::graph::FrameGraph<'r>,
            &'r Techniques,
            &FrameContext,
            &FrameOutputs,
        ) -> Result<()>,
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
        self.validate(settings)?;
        if let Some(why) = self.ctx.faults.lost() {
            return Err(RenderError::DeviceLost {
                during: "starting a frame".into(),
                reason: why,
            });
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
        // 0. The frame context: this frame's facts, resolved once.
        let history = self.history_for(settings);
        let cx = FrameContext::new(
            settings,
            self.runtime.frame_index(),
            self.scene.light_count,
            history,
        )?;
        for _ in 0..MAX_QUEUE_RETRIES {
            // The techniques' states advance with a shown frame only.
            let before = self.state.techniques.clone();
            let mut g = self.runtime.begin_frame(&self.ctx);
            let out = frame::record(
                &mut g,
                &self.techniques,
                &self.scene,
                &self.area_lights,
                &self.scene_rt,
                &cx,
                settings,
                &mut self.state,
            )?;
            finish(&mut g, &self.techniques, &cx, &out)?;
            for r in pick(&out) {
                g.readback(r);
            }
            let result = g.execute_uncommitted()?;
            // Errors the device raised while recording or running the frame (out of memory,
            // a lost device): the frame is dropped and the states stay as they were, so the
            // caller can change back what asked too much and go on.
            if let Err(e) = self.ctx.faults.check(&format!("frame {}", cx.frame_index)) {
                self.runtime.discard_frame();
                self.state.techniques = before;
                return Err(e);
            }
            let overflowed = !self
                .state
                .raster_queues
                .grow(&result, binding_limit)?
                .is_empty();
            // Interactive frames (the runtime does not wait for their counts) are shown as drawn.
            let shown = !overflowed || !self.runtime.waits_for_readbacks();
            if !shown {
                // Drawn again: the techniques start from their states before this try.
                self.runtime.discard_frame();
                self.state.techniques = before;
            }
            if overflowed {
                // Cascades and cube maps drawn into an overflowing queue lack triangles: draw
                // them all again (after the restore above, which would undo it).
                self.state.shadow_cache = Default::default();
                self.state.techniques.reflection_probes.invalidate_capture();
            }
            if shown {
                self.runtime.commit_frame();
                self.last_context = Some(cx);
                return Ok(result);
            }
        }
        Err(RenderError::Graph(format!(
            "the rasteriser's queues still overflowed after {MAX_QUEUE_RETRIES} tries"
        )))
    }
}

/// The camera's position and forward direction, which together tell a cut.
fn camera_pose(c: &Camera) -> [f32; 6] {
    let f = c.forward();
    [c.position.x, c.position.y, c.position.z, f.x, f.y, f.z]
}
