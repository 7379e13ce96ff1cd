//! The window's event loop: start-up (the renderer built on a thread while the window shows
//! progress), input, and one frame per redraw: the camera and clock applied through the live
//! renderer API, the frame drawn into the picture, the panel painted over it, presented.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::{Duration, Instant};

use hikari_render::graph::TimestampMode;
use hikari_render::renderer::Display;
use hikari_render::{Preset, Renderer, Settings, SunSource};
use hikari_scene::Camera;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::ViewArgs;
use super::camera::FlyCamera;
use super::keys::{self, Action, Held};
use super::panel::{self, Clock};
use super::present::Presenter;
use super::stats::{FrameTime, RayStats, Stats};
use crate::probe_bake;
use crate::scene_source::{self, ResolvedFrame, SceneSource};
use crate::still;

/// How often a frame is timed per pass (timing waits for the GPU, so not every frame).
const TIMED_EVERY: Duration = Duration::from_millis(250);
/// How often the GI's rays are counted (a read-back of a word a pixel).
const RAYS_EVERY: Duration = Duration::from_secs(1);
/// How long a message stays.
const MESSAGE_FOR: Duration = Duration::from_secs(8);
/// The panel is laid out again at least this often (its numbers move), at once after any
/// input or while egui animates; in between, the last layout is painted again: egui's layout
/// is most of the viewer's own CPU time.
const UI_REFRESH: Duration = Duration::from_millis(100);

/// The last layout of the panel, painted again until something changes.
struct UiCache {
    prims: Vec<egui::ClippedPrimitive>,
    pixels_per_point: f32,
    at: Instant,
    /// What the layout was made for: the window's size, the panel shown, the message.
    key: ([u32; 2], bool, Option<(String, bool)>),
}

enum LoadMsg {
    Stage(String),
    Done(Box<anyhow::Result<Renderer>>),
}

struct Loading {
    rx: Receiver<LoadMsg>,
    stage: String,
    started: Instant,
}

/// The viewer once the renderer is up.
struct Live {
    renderer: Renderer,
    scene_name: String,
    cameras: Vec<Camera>,
    fly: FlyCamera,
    held: Held,
    /// The cursor where the right button was last seen while looking.
    looking: Option<(f64, f64)>,
    moved: bool,
    clock: Clock,
    preset: Option<Preset>,
    view: Option<String>,
    names: Vec<String>,
    stats: Stats,
    last_frame: Instant,
    last_timed: Instant,
    last_rays: Instant,
    screenshot: bool,
    drop: Option<PathBuf>,
    /// The settings before the last change, until a frame has rendered with the new ones: an
    /// out-of-memory frame goes back to them.
    undo: Option<Settings>,
    changes: u64,
}

/// Applies a settings change, keeping what it replaced for [`Live::undo`].
fn change_settings(live: &mut Live, s: Settings) -> hikari_render::Result<()> {
    let before = live.renderer.live_frame().expect("set").settings.clone();
    live.renderer.set_settings(s)?;
    live.undo = Some(before);
    live.changes += 1;
    if super::faults::oom_on_change() == Some(live.changes) {
        live.renderer
            .ctx
            .faults
            .record(hikari_render::faults::Fault::OutOfMemory(
                "pretended by HIKARI_VIEW_FAULT".into(),
            ));
    }
    Ok(())
}

pub struct App {
    args: ViewArgs,
    resolved: Option<ResolvedFrame>,
    scene_name: String,
    window: Option<Arc<Window>>,
    presenter: Option<Presenter>,
    egui: egui::Context,
    egui_state: Option<egui_winit::State>,
    adapter: String,
    loading: Option<Loading>,
    live: Option<Live>,
    show_panel: bool,
    shift: bool,
    message: Option<(String, bool, Instant)>,
    /// The scene's cameras and a speed for its size, kept when the scene goes to the loader.
    cameras: Vec<Camera>,
    speed: f32,
    fatal: Option<anyhow::Error>,
    frames: u64,
    ui_cache: Option<UiCache>,
    /// An input event came since the last layout (or egui asked to be laid out again).
    ui_dirty: bool,
}

impl App {
    pub fn new(args: ViewArgs, resolved: ResolvedFrame) -> Self {
        Self {
            scene_name: resolved.description.source.name(),
            args,
            resolved: Some(resolved),
            window: None,
            presenter: None,
            egui: egui::Context::default(),
            egui_state: None,
            adapter: String::new(),
            loading: None,
            live: None,
            show_panel: true,
            shift: false,
            message: None,
            cameras: Vec::new(),
            speed: 1.0,
            fatal: None,
            frames: 0,
            ui_cache: None,
            ui_dirty: true,
        }
    }

    /// After the event loop: the error that ended it, if any, and the viewer's cost printed.
    pub fn finish(self) -> anyhow::Result<()> {
        if let Some(e) = self.fatal {
            return Err(e);
        }
        if let Some(live) = &self.live
            && let (Some(us), Some((mean, n))) =
                (live.stats.ui_cpu_us(), live.stats.ui_cpu_mean_us())
        {
            log::info!(
                "{} frames; the viewer's own CPU time a frame (egui layout, tessellation, paint \
                 recording): median {:.3} ms over the last second, mean {:.3} ms over {n} frames",
                self.frames,
                us / 1000.0,
                mean / 1000.0
            );
        }
        Ok(())
    }

    fn say(&mut self, text: impl Into<String>, error: bool) {
        let text = text.into();
        if error {
            log::warn!("{text}");
        } else {
            log::info!("{text}");
        }
        self.message = Some((text, error, Instant::now()));
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.fatal = Some(e);
        event_loop.exit();
    }

    fn start(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let resolved = self.resolved.take().expect("started once");
        self.cameras = if resolved.scene.cameras.is_empty() {
            vec![resolved.settings.camera.clone()]
        } else {
            resolved.scene.cameras.clone()
        };
        self.speed = FlyCamera::speed_for(resolved.scene.bounds());
        let attrs = Window::default_attributes()
            .with_title(format!("hikari view — {}", self.scene_name))
            .with_inner_size(winit::dpi::PhysicalSize::new(
                resolved.settings.width,
                resolved.settings.height,
            ));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| anyhow::anyhow!("cannot open a window: {e}"))?,
        );
        let ctx = still::gpu()?;
        // A CPU adapter gets the low preset unless one was asked for, as `render` does.
        let resolved = scene_source::fit_to_adapter(resolved, &self.args.frame, &ctx)?;
        self.adapter = format!("{} ({:?})", ctx.info.name, ctx.info.backend);
        let presenter = Presenter::new(
            &ctx.instance,
            &ctx.adapter,
            &ctx.device,
            &ctx.queue,
            window.clone(),
        )?;
        self.egui_state = Some(egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            event_loop,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.limits.max_texture_dimension_2d as usize),
        ));
        let (tx, rx) = std::sync::mpsc::channel();
        let bake = self.args.bake.clone();
        let name = self.scene_name.clone();
        std::thread::Builder::new()
            .name("hikari-view-load".into())
            .spawn(move || {
                let build = || -> anyhow::Result<Renderer> {
                    let _ = tx.send(LoadMsg::Stage(format!(
                        "uploading {name} and building its BVH"
                    )));
                    let mut r = Renderer::new(ctx, &resolved.scene)?;
                    let _ = tx.send(LoadMsg::Stage(
                        "irradiance probes: read from the cache, or baked on a miss (minutes on a \
                         CPU driver); reflection probes"
                            .into(),
                    ));
                    probe_bake::attach(
                        &mut r,
                        &resolved.scene,
                        &resolved.description.source,
                        &resolved.settings,
                        bake.as_deref(),
                    )?;
                    r.set_frame(resolved.settings.clone())?;
                    let _ = tx.send(LoadMsg::Stage("compiling the first frame".into()));
                    Ok(r)
                };
                let _ = tx.send(LoadMsg::Done(Box::new(build())));
            })?;
        self.loading = Some(Loading {
            rx,
            stage: "starting".into(),
            started: Instant::now(),
        });
        self.presenter = Some(presenter);
        window.request_redraw();
        self.window = Some(window);
        Ok(())
    }

    /// The renderer arrived: the live state around it.
    fn go_live(&mut self, mut renderer: Renderer) {
        renderer.set_interactive(true);
        renderer.runtime.set_timestamps(TimestampMode::Off);
        let frame = renderer.live_frame().expect("set by the loader").clone();
        let cameras = std::mem::take(&mut self.cameras);
        let now = Instant::now();
        let speed = self.speed;
        self.live = Some(Live {
            fly: FlyCamera::new(&frame.camera, speed),
            scene_name: self.scene_name.clone(),
            cameras,
            held: Held::default(),
            looking: None,
            moved: false,
            clock: Clock::of(&frame.settings),
            preset: preset_of(&frame.settings),
            view: None,
            names: Vec::new(),
            stats: Stats::default(),
            last_frame: now,
            last_timed: now - TIMED_EVERY,
            last_rays: now - RAYS_EVERY,
            screenshot: false,
            drop: None,
            undo: None,
            changes: 0,
            renderer,
        });
    }

    fn on_key(&mut self, event_loop: &ActiveEventLoop, code: KeyCode, pressed: bool, repeat: bool) {
        if let Some(live) = &mut self.live
            && let Some(m) = keys::movement(code)
        {
            live.held.set(m, pressed);
            return;
        }
        if !pressed || repeat {
            return;
        }
        let Some(action) = keys::action(code, self.shift) else {
            return;
        };
        match action {
            Action::Exit => event_loop.exit(),
            Action::TogglePanel => self.show_panel = !self.show_panel,
            _ => {
                let Some(live) = &mut self.live else { return };
                match action {
                    Action::Screenshot => live.screenshot = true,
                    Action::TimeBack => live.clock.step(-panel::TIME_STEP_S),
                    Action::TimeForward => live.clock.step(panel::TIME_STEP_S),
                    Action::PlayClock => live.clock.playing = !live.clock.playing,
                    Action::ToggleGi => {
                        let mut s = live.renderer.live_frame().unwrap().settings.clone();
                        s.ray_traced_gi.enabled = !s.ray_traced_gi.enabled;
                        let on = s.ray_traced_gi.enabled;
                        let r = change_settings(live, s);
                        live.stats.clear_passes();
                        match r {
                            Ok(()) => self.say(
                                format!("ray-traced GI {}", if on { "on" } else { "off" }),
                                false,
                            ),
                            Err(e) => self.say(format!("ray-traced GI: {e}"), true),
                        }
                    }
                    Action::NextView => {
                        live.view = panel::next_view(&live.names, live.view.as_deref())
                    }
                    Action::FinalView => live.view = None,
                    Action::Camera(i) => jump(live, i),
                    Action::Exit | Action::TogglePanel => {}
                }
            }
        }
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let Some(window) = self.window.clone() else {
            return;
        };
        if let Some(loading) = &mut self.loading {
            let mut done = None;
            loop {
                match loading.rx.try_recv() {
                    Ok(LoadMsg::Stage(s)) => {
                        log::info!("start-up: {s}");
                        loading.stage = s;
                    }
                    Ok(LoadMsg::Done(r)) => {
                        done = Some(*r);
                        break;
                    }
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => {
                        done = Some(Err(anyhow::anyhow!(
                            "the renderer's start-up thread stopped"
                        )));
                        break;
                    }
                }
            }
            match done {
                Some(Ok(r)) => {
                    log::info!("ready in {:.1} s", loading.started.elapsed().as_secs_f64());
                    self.loading = None;
                    self.go_live(r);
                }
                Some(Err(e)) => return self.fail(event_loop, e.context("starting the renderer")),
                None => {
                    let (stage, secs) = (
                        loading.stage.clone(),
                        loading.started.elapsed().as_secs_f64(),
                    );
                    let name = self.scene_name.clone();
                    self.paint_ui(&window, false, |ui, _| {
                        super::ui::loading(ui, &name, &stage, secs)
                    });
                    return;
                }
            }
        }
        if let Err(e) = self.frame(&window) {
            self.say(format!("{e:#}"), true);
        }
        self.frames += 1;
        if self.args.print_frames {
            println!("frame {} shown", self.frames);
        }
        if self
            .args
            .exit_after_frames
            .is_some_and(|n| self.frames >= n)
        {
            event_loop.exit();
        }
    }

    /// Runs egui for one pass with `build` and paints it; with `time`, the paint's GPU time
    /// comes back. Returns (GPU ms, the CPU µs egui and its paint recording took).
    fn paint_ui(
        &mut self,
        window: &Window,
        time: bool,
        mut build: impl FnMut(&mut egui::Ui, &egui::Context),
    ) -> (Option<f64>, f64) {
        let t0 = super::stats::thread_cpu_us();
        let Some(state) = self.egui_state.as_mut() else {
            return (None, 0.0);
        };
        let input = state.take_egui_input(window);
        let ctx = self.egui.clone();
        let mut out = self.egui.run_ui(input, |ui| build(ui, &ctx));
        state.handle_platform_output(window, out.platform_output);
        let prims = self.egui.tessellate(out.shapes, out.pixels_per_point);
        let cpu_us = super::stats::thread_cpu_us() - t0;
        let Some(presenter) = self.presenter.as_mut() else {
            return (None, cpu_us);
        };
        match presenter.paint(&mut out.textures_delta, &prims, out.pixels_per_point, time) {
            Ok((gpu, encode_us)) => (gpu, cpu_us + encode_us),
            Err(e) => {
                log::warn!("painting the window: {e:#}");
                (None, cpu_us)
            }
        }
    }

    /// One frame of the live viewer.
    fn frame(&mut self, window: &Window) -> anyhow::Result<()> {
        let now = Instant::now();
        let size = self.presenter.as_ref().map_or([1, 1], |p| p.size());
        let mut messages: Vec<(String, bool)> = Vec::new();
        let live = self.live.as_mut().expect("live");
        let dt = now.duration_since(live.last_frame).as_secs_f64();
        live.last_frame = now;
        if let Some(path) = live.drop.take() {
            match load_dropped(live, &path) {
                Ok(()) => {
                    self.scene_name = live.scene_name.clone();
                    window.set_title(&format!("hikari view — {}", self.scene_name));
                    messages.push((format!("loaded {}", path.display()), false));
                }
                Err(e) => messages.push((
                    format!("{}: {e:#} (the scene is unchanged)", path.display()),
                    true,
                )),
            }
        }
        // The camera: moving is not a cut.
        let moved =
            live.fly.step(&live.held, self.shift, dt as f32) | std::mem::take(&mut live.moved);
        if moved && let Err(e) = live.renderer.set_camera(live.fly.camera(), false) {
            messages.push((format!("camera: {e}"), true));
        }
        live.clock.advance(dt);
        apply_clock(live, &mut messages);
        let f = live.renderer.live_frame().expect("set").clone();
        if [f.width, f.height] != size && size[0] > 0 && size[1] > 0 {
            live.renderer.resize(size[0], size[1])?;
        }
        // A frame timed per pass now and then (timing waits for the GPU).
        let timed = now.duration_since(live.last_timed) >= TIMED_EVERY;
        let rays = timed
            && f.settings.ray_traced_gi.enabled
            && now.duration_since(live.last_rays) >= RAYS_EVERY;
        if timed {
            live.last_timed = now;
        }
        if rays {
            live.last_rays = now;
        } else if !f.settings.ray_traced_gi.enabled {
            live.stats.rays = None;
        }
        live.renderer.runtime.set_timestamps(if timed {
            TimestampMode::Pass
        } else {
            TimestampMode::Off
        });
        live.renderer.runtime.set_dumps(if rays {
            vec![GI_HITS.into(), GI_QUEUE.into()]
        } else {
            Vec::new()
        });
        if std::mem::take(&mut live.screenshot) {
            messages.push(match screenshot(&mut live.renderer) {
                Ok(p) => (format!("wrote {} and .exr", p.display()), false),
                Err(e) => (format!("screenshot: {e:#}"), true),
            });
        }
        let presenter = self.presenter.as_mut().expect("presenter");
        let picture = presenter.picture(size);
        let (picture_tex, picture_id) = (picture.texture.clone(), picture.id);
        let display = Display {
            source: live.view.clone(),
            mapping: None,
        };
        let t0 = Instant::now();
        let shown = match live.renderer.frame_into(&picture_tex, &display) {
            Err(e) if live.view.is_some() => {
                messages.push((format!("debug view: {e}; back to the final image"), true));
                live.view = None;
                live.renderer.frame_into(&picture_tex, &Display::default())
            }
            r => r,
        };
        let render_cpu_ms = t0.elapsed().as_secs_f64() * 1e3;
        let mut gpu_span = None;
        match shown {
            Ok(shown) => {
                live.undo = None;
                live.names = shown.names;
                let r = &shown.result;
                gpu_span = r.gpu_span_ms.filter(|_| timed);
                if timed {
                    live.stats.add_passes(
                        now,
                        r.timings
                            .iter()
                            .filter_map(|t| t.gpu_ms.map(|g| (t.name.as_str(), g))),
                    );
                }
                if rays {
                    live.stats.rays = ray_stats(r, f.width as u64 * f.height as u64);
                }
            }
            Err(e @ hikari_render::RenderError::OutOfMemory { .. }) if live.undo.is_some() => {
                let back = live.renderer.set_settings(live.undo.take().unwrap());
                messages.push((
                    match back {
                        Ok(()) => format!("{e}; went back to the settings before the last change"),
                        Err(b) => format!("{e}; going back to the settings before failed: {b}"),
                    },
                    true,
                ));
            }
            Err(e) => messages.push((format!("frame: {e}"), true)),
        }
        live.renderer.runtime.set_dumps(Vec::new());

        // The panel, on copies of the renderer's state.
        let live_settings = live.renderer.live_frame().unwrap().settings.clone();
        let sun = match &live.renderer.live_frame().unwrap().sun {
            SunSource::Sky => "the sun or moon of the clock",
            SunSource::Fixed(_) => "the scene's own sun (the clock sets the sky's)",
            SunSource::Off => "none (the scene is lit by its lamps)",
        };
        let show_panel = self.show_panel;
        let message = self
            .message
            .as_ref()
            .filter(|(_, _, at)| at.elapsed() < MESSAGE_FOR)
            .map(|(t, e, _)| (t.clone(), *e));
        let adapter = self.adapter.clone();
        let mut model = super::ui::Model {
            picture: Some((picture_id, size)),
            show_panel,
            scene: &live.scene_name,
            adapter: &adapter,
            cameras: live.cameras.iter().map(|c| c.name.clone()).collect(),
            jump: None,
            speed: live.fly.speed,
            sun,
            clock: live.clock.clone(),
            settings: live_settings.clone(),
            preset: live.preset,
            view: live.view.clone(),
            names: &live.names,
            stats: &mut live.stats,
            now,
            message: message.as_ref().map(|(t, e)| (t.as_str(), *e)),
            screenshot: false,
        };
        let t_ui = super::stats::thread_cpu_us();
        let Some(state) = self.egui_state.as_mut() else {
            return Ok(());
        };
        let key = (size, show_panel, message.clone());
        let fresh = !self.ui_dirty
            && self
                .ui_cache
                .as_ref()
                .is_some_and(|c| c.key == key && now.duration_since(c.at) < UI_REFRESH);
        let mut textures = egui::TexturesDelta::default();
        if !fresh {
            let input = state.take_egui_input(window);
            let out = self
                .egui
                .run_ui(input, |ui| super::ui::draw(ui, &mut model));
            state.handle_platform_output(window, out.platform_output);
            // egui animating (a header opening) wants the next frame laid out too.
            self.ui_dirty = out
                .viewport_output
                .values()
                .any(|v| v.repaint_delay.is_zero());
            textures = out.textures_delta;
            self.ui_cache = Some(UiCache {
                prims: self.egui.tessellate(out.shapes, out.pixels_per_point),
                pixels_per_point: out.pixels_per_point,
                at: now,
                key,
            });
        }
        let cache = self.ui_cache.as_ref().expect("laid out");
        let ui_layout_us = super::stats::thread_cpu_us() - t_ui;
        let (ui_gpu, encode_us) =
            presenter.paint(&mut textures, &cache.prims, cache.pixels_per_point, timed)?;
        let ui_cpu_us = ui_layout_us + encode_us;

        // What the panel changed.
        let super::ui::Model {
            jump: jumped,
            speed,
            clock,
            settings,
            preset,
            view,
            screenshot,
            ..
        } = model;
        live.fly.speed = speed;
        live.clock = clock;
        live.view = view;
        live.screenshot |= screenshot;
        if preset != live.preset {
            live.preset = preset;
        }
        if settings != live_settings {
            let switched = settings.switches() != live_settings.switches();
            match change_settings(live, settings.clone()) {
                Ok(()) => {
                    if switched {
                        live.stats.clear_passes();
                    }
                    live.preset = preset_of(&settings).or(live.preset.filter(|_| false));
                }
                Err(e) => messages.push((format!("{e}"), true)),
            }
        }
        if let Some(i) = jumped {
            jump(live, i);
        }
        if live.clock
            != Clock::of_synced(&live.clock, &live.renderer.live_frame().unwrap().settings)
        {
            apply_clock(live, &mut messages);
        }
        live.stats.add_ui_cpu(now, ui_cpu_us);
        if let Some(g) = ui_gpu {
            live.stats.add_passes(now, [("ui.egui", g)]);
        }
        live.stats.add_frame(
            now,
            FrameTime {
                frame_ms: dt * 1e3,
                cpu_ms: render_cpu_ms + ui_cpu_us / 1e3,
                gpu_ms: gpu_span.map(|g| g + ui_gpu.unwrap_or(0.0)),
            },
        );
        for (text, error) in messages {
            self.say(text, error);
        }
        Ok(())
    }
}

const GI_HITS: &str = "ray_traced_gi.hits";
const GI_QUEUE: &str = "ray_traced_gi.queue";

/// The GI's rays a pixel and the pre-trace's share, from a frame that read its ray buffers.
fn ray_stats(r: &hikari_render::graph::FrameResult, pixels: u64) -> Option<RayStats> {
    let words = |name: &str| -> Option<Vec<u32>> {
        Some(
            r.buffer(name)?
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        )
    };
    let hits = words(GI_HITS)?;
    let queued = *words(GI_QUEUE)?.first()? as f64;
    let traced = hits
        .iter()
        .filter(|&&w| w != hikari_render::techniques::ray_traced_gi::reference::HIT_NOT_TRACED)
        .count() as f64;
    Some(RayStats {
        rays_per_pixel: traced / pixels.max(1) as f64,
        pretrace_share: if traced > 0.0 {
            ((traced - queued) / traced).clamp(0.0, 1.0)
        } else {
            0.0
        },
    })
}

/// The preset whose values the settings are (the sky aside), if any.
fn preset_of(s: &Settings) -> Option<Preset> {
    Preset::ALL
        .into_iter()
        .find(|&p| panel::with_preset(s, p) == *s)
}

/// Jumps to the scene's camera `i`: a camera cut.
fn jump(live: &mut Live, i: usize) {
    let Some(cam) = live.cameras.get(i).cloned() else {
        return;
    };
    live.fly = FlyCamera::new(&cam, live.fly.speed);
    if let Err(e) = live.renderer.set_camera(cam, true) {
        log::warn!("camera: {e}");
    }
}

impl Clock {
    /// `self` with the renderer's clock and place (the play state and rate kept), for
    /// telling what the panel changed.
    fn of_synced(&self, s: &Settings) -> Clock {
        let mut c = Clock::of(s);
        c.playing = self.playing;
        c.rate_h_per_10s = self.rate_h_per_10s;
        if (c.seconds - self.seconds).abs() < 1.0 {
            c.seconds = self.seconds;
        }
        c
    }
}

/// Gives the renderer the panel's clock and place where they differ from its own; what it
/// refuses is reported and the panel goes back to the renderer's values.
fn apply_clock(live: &mut Live, messages: &mut Vec<(String, bool)>) {
    let s = live.renderer.live_frame().unwrap().settings.clone();
    let have = live.clock.of_synced(&s);
    let want = live.clock.clone();
    if want == have {
        return;
    }
    let r = &mut live.renderer;
    let mut result = Ok(());
    if want.seconds != have.seconds || want.date != have.date {
        // Turning the clock means the sky's sun, even in a scene with its own.
        if matches!(r.live_frame().unwrap().sun, SunSource::Fixed(_)) {
            result = result.and(r.set_sun_source(SunSource::Sky));
        }
        if want.date != have.date {
            result = result.and(r.set_clock(&want.date, &s.sky.time));
        }
        result = result.and(r.set_time_of_day(want.seconds));
    }
    if (want.latitude_deg, want.longitude_deg, want.utc_offset_h)
        != (have.latitude_deg, have.longitude_deg, have.utc_offset_h)
    {
        result = result.and(r.set_place(want.latitude_deg, want.longitude_deg, want.utc_offset_h));
    }
    if want.weather != have.weather {
        result = result.and(r.set_weather(&want.weather));
    }
    if let Err(e) = result {
        messages.push((format!("{e}"), true));
        live.clock = live.clock.of_synced(&r.live_frame().unwrap().settings);
    }
}

/// F12: the live frame rendered with its images read back, written as `render` writes them.
fn screenshot(renderer: &mut Renderer) -> anyhow::Result<PathBuf> {
    let png = super::shot::png_path(std::path::Path::new("."), &super::shot::local_stamp());
    let frame = renderer.frame(true)?;
    still::write_images(&png, Some(&png.with_extension("exr")), &frame)?;
    Ok(png)
}

/// Loads a dropped .gltf or .glb in place of the scene; on an error the scene stays.
fn load_dropped(live: &mut Live, path: &std::path::Path) -> anyhow::Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("gltf" | "glb")) {
        anyhow::bail!("only .gltf and .glb files can be dropped here");
    }
    let source = SceneSource::Gltf(path.to_path_buf());
    let scene = source.load()?;
    scene.validate()?;
    let (camera, _) = scene_source::first_or_framing_camera(&scene, "view")?;
    live.renderer.reload_scene(&scene)?;
    let frame = live.renderer.live_frame().unwrap().clone();
    probe_bake::attach(&mut live.renderer, &scene, &source, &frame, None)?;
    live.fly = FlyCamera::new(&camera, FlyCamera::speed_for(scene.bounds()));
    live.renderer.set_camera(camera.clone(), true)?;
    live.cameras = if scene.cameras.is_empty() {
        vec![camera]
    } else {
        scene.cameras.clone()
    };
    live.scene_name = source.name();
    live.view = None;
    live.stats.clear_passes();
    Ok(())
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() || self.fatal.is_some() {
            return;
        }
        if let Err(e) = self.start(event_loop) {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(window) = self.window.clone() else {
            return;
        };
        if let Some(state) = self.egui_state.as_mut() {
            let _ = state.on_window_event(&window, &event);
        }
        if !matches!(event, WindowEvent::RedrawRequested) {
            self.ui_dirty = true;
        }
        let egui_keys = self.egui.egui_wants_keyboard_input();
        let over_egui = self.egui.is_pointer_over_egui();
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(s) => {
                if let Some(p) = self.presenter.as_mut() {
                    p.resize(s.width, s.height);
                }
                window.request_redraw();
            }
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    let pressed = event.state == ElementState::Pressed;
                    // A text field keeps its keys; Esc and the F keys always work.
                    let always = matches!(code, KeyCode::Escape | KeyCode::F1 | KeyCode::F12);
                    if !egui_keys || always || !pressed {
                        self.on_key(event_loop, code, pressed, event.repeat);
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Right,
                ..
            } => {
                if let Some(live) = &mut self.live {
                    live.looking = (state == ElementState::Pressed && !over_egui)
                        .then_some((f64::NAN, f64::NAN));
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some(live) = &mut self.live
                    && let Some((x, y)) = live.looking
                {
                    if x.is_finite() {
                        live.moved |= live
                            .fly
                            .look((position.x - x) as f32, (position.y - y) as f32);
                    }
                    live.looking = Some((position.x, position.y));
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !over_egui => {
                if let Some(live) = &mut self.live {
                    let notches = match delta {
                        MouseScrollDelta::LineDelta(_, y) => y,
                        MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                    };
                    live.fly.wheel(notches);
                }
            }
            WindowEvent::Focused(false) => {
                if let Some(live) = &mut self.live {
                    live.held.clear();
                    live.looking = None;
                }
            }
            WindowEvent::DroppedFile(path) => {
                if let Some(live) = &mut self.live {
                    self.message = Some((
                        format!("loading {} ...", path.display()),
                        false,
                        Instant::now(),
                    ));
                    live.drop = Some(path);
                }
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            if self.loading.is_some() {
                event_loop.set_control_flow(ControlFlow::WaitUntil(
                    Instant::now() + Duration::from_millis(100),
                ));
            } else {
                event_loop.set_control_flow(ControlFlow::Poll);
            }
            w.request_redraw();
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        let (Some(path), Some(p)) = (self.args.screenshot.clone(), self.presenter.as_ref()) else {
            return;
        };
        if self.live.is_none() {
            return;
        }
        let r = p
            .read_picture()
            .and_then(|img| Ok(hikari_render::output::write_png(&path, &img)?));
        match r {
            Ok(()) => println!("wrote {}", path.display()),
            Err(e) if self.fatal.is_none() => self.fatal = Some(e.context("--screenshot")),
            Err(e) => log::warn!("--screenshot: {e:#}"),
        }
    }
}
