//! The frame context: the facts of one frame, resolved once before any pass is recorded
//! (ARCHITECTURE.md's step 0) from what the renderer is asked to draw. Every technique reads
//! them from here; none derives them again.
//!
//! * the size, the frame index, TAA's jitter and the jittered view with the previous view;
//! * whether temporal history may be used, and if not why (a cut, a resize, a settings or
//!   scene change): the one flag every temporal pass follows;
//! * the directional light, resolved by its one owner ([`SunSource`]): the sun or moon of
//!   the sky's date, time and place, or a scene's own fixed sun;
//! * the sky's CPU side (the sun and moon as the sky sees them, the weather's knobs, the
//!   sky's own illuminance on the ground);
//! * the illuminance the exposure is metered for, its EV100, and the punctual lights' cut-off;
//! * the sky's clock, which the clouds and particles follow.

use hikari_scene::{Camera, Sun};

use crate::error::{RenderError, Result};
use crate::lights::light_cutoff_lux;
use crate::settings::Settings;
use crate::techniques::sky::FrameSky;
use crate::techniques::taa;
use crate::view::View;

/// Who gives a frame its directional light.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum SunSource {
    /// The sun while it is up, else the moon, from `sky`'s date, time and place (the default).
    /// `sky.sun = false` turns it off.
    #[default]
    Sky,
    /// A fixed light, such as a scene's own sun: the sky is drawn for it and the moon goes.
    /// `sky.sun = false` turns it off too.
    Fixed(Sun),
    /// No directional light at all.
    Off,
}

impl From<Option<Sun>> for SunSource {
    /// `Some`: that fixed sun; `None`: no directional light.
    fn from(sun: Option<Sun>) -> Self {
        sun.map_or(SunSource::Off, SunSource::Fixed)
    }
}

/// What a frame depends on besides the scene: the size, the camera, the directional light's
/// source and the settings. The live renderer API ([`crate::Renderer::set_clock`] and its
/// siblings) keeps one of these; [`crate::Renderer::render`] takes one directly.
#[derive(Clone, Debug)]
pub struct FrameSettings {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    /// The camera of the previous frame, for motion vectors; `None`: it did not move.
    pub prev_camera: Option<Camera>,
    /// Where the directional light comes from.
    pub sun: SunSource,
    pub settings: Settings,
}

impl FrameSettings {
    /// The frame context of these settings as the first frame of a scene without point or
    /// spot lights: for tools and twins that want the frame's light facts (the sun or moon,
    /// the sky, the metered illuminance, the cut-off) without rendering.
    pub fn context(&self) -> Result<FrameContext> {
        FrameContext::new(self, 0, 0, HistoryValidity::VALID)
    }

    /// The directional light these settings give: [`SunSource`] resolved, `sky.sun` applied.
    pub fn directional_light(&self) -> Result<Option<Sun>> {
        if !self.settings.sky.sun {
            return Ok(None);
        }
        match &self.sun {
            SunSource::Sky => crate::techniques::sky::lights::SkyLights::new(&self.settings.sky)
                .map(|l| l.directional())
                .map_err(RenderError::from),
            SunSource::Fixed(sun) => Ok(Some(sun.clone())),
            SunSource::Off => Ok(None),
        }
    }
}

/// Why a frame may not use the temporal history of the frames before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HistoryReset {
    /// No frame came before.
    FirstFrame,
    /// The camera jumped ([`crate::Renderer::cut_camera`], a new camera that claims it did not
    /// move, or [`crate::Renderer::set_camera`] with `cut`).
    CameraCut,
    /// The image's size changed.
    Resize,
    /// A technique was switched on or off.
    SettingsChange,
    /// The light jumped: the clock, place or weather changed the sun or moon by more than
    /// [`LIGHT_JUMP_DEG`] (or switched between them) in one step. Small steps, as a playing
    /// clock makes, keep the history and let it follow the light.
    LightJump,
    /// A new scene was loaded.
    SceneChange,
}

/// The most the directional light may turn between two frames for the history to follow it
/// (a minute or two of clock; the viewer's playing clock turns it 0.025° a frame, its 30-minute
/// steps 7°).
pub const LIGHT_JUMP_DEG: f32 = 1.0;

/// Whether going from the frame `old` to `new` makes the light jump (see
/// [`HistoryReset::LightJump`]): another weather, a sun or moon that appears, goes, or turns
/// more than [`LIGHT_JUMP_DEG`], or whose illuminance changes by more than a factor of two.
pub fn light_jumps(old: &FrameSettings, new: &FrameSettings) -> bool {
    if old.settings.sky.weather != new.settings.sky.weather {
        return true;
    }
    let (Ok(a), Ok(b)) = (old.directional_light(), new.directional_light()) else {
        return true;
    };
    match (a, b) {
        (None, None) => false,
        (Some(a), Some(b)) => {
            let (u, v) = (a.direction.normalize(), b.direction.normalize());
            let turned = u.cross(v).length().atan2(u.dot(v)).to_degrees();
            let ratio = a.illuminance_lux.max(1e-9) / b.illuminance_lux.max(1e-9);
            turned > LIGHT_JUMP_DEG || !(0.5..=2.0).contains(&ratio)
        }
        _ => true,
    }
}

/// Whether this frame may use the temporal history, and if not why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistoryValidity {
    pub reset: Option<HistoryReset>,
}

impl HistoryValidity {
    pub const VALID: Self = Self { reset: None };

    pub fn valid(&self) -> bool {
        self.reset.is_none()
    }

    /// The view itself changed (a cut or a new scene): what was cached for the old view
    /// (the reflection probes' relight order) starts over.
    pub fn view_changed(&self) -> bool {
        matches!(
            self.reset,
            Some(HistoryReset::CameraCut | HistoryReset::SceneChange)
        )
    }
}

/// One frame's facts; see the module's documentation.
#[derive(Clone, Debug)]
pub struct FrameContext {
    /// The size every pass before TAA renders at: the output's at `taa.render_scale`.
    pub size: [u32; 2],
    /// The output's size (`FrameSettings::width`, `height`): TAA's output and what follows.
    pub output_size: [u32; 2],
    pub aspect: f32,
    /// The graph's frame index: frames committed before this one.
    pub frame_index: u64,
    /// TAA's sub-pixel offset of this frame (zero with TAA off).
    pub jitter: [f32; 2],
    /// The jittered view with the previous frame's view.
    pub view: View,
    pub history: HistoryValidity,
    /// The directional light (sun or moon), `None` when there is none or it is switched off.
    pub sun: Option<Sun>,
    /// The sky's CPU side; `None` with the sky off.
    pub sky: Option<FrameSky>,
    /// The sky's own illuminance on a horizontal plane at the ground, lux (0 without a sky).
    pub sky_lux: f32,
    /// The illuminance the exposure is set for: the configured EV100's, else the larger of the
    /// sun's and the sky's, at least a thousandth of a lux.
    pub metered_lux: f32,
    /// The CPU meter's EV100 for `metered_lux` (or the configured one).
    pub ev100: f32,
    /// Lux below which a point or spot light is cut off in every pass that lights with them.
    pub light_cutoff_lux: f32,
    /// Seconds since local midnight of the sky's clock (0 when the clock is invalid).
    pub clock_s: f64,
    /// Point and spot lights the frame lights with (0 with `direct_lighting.punctual` off).
    pub punctual_lights: u32,
}

impl FrameContext {
    /// Resolves `s` for the frame `frame_index` of a scene with `scene_lights` point and spot
    /// lights; `history` says whether the frames before may be used.
    pub fn new(
        s: &FrameSettings,
        frame_index: u64,
        scene_lights: u32,
        history: HistoryValidity,
    ) -> Result<Self> {
        let settings = &s.settings;
        let output_size = [s.width, s.height];
        let scale = settings.taa.render_scale;
        let size = taa::render_size(output_size, scale);
        let aspect = s.width as f32 / s.height.max(1) as f32;
        let jitter = if settings.taa.enabled {
            let cycle = taa::jitter_cycle(settings.taa.jitter_samples, scale);
            taa::reference::jitter(frame_index, cycle)
        } else {
            [0.0; 2]
        };
        let view = View::with_previous(
            &s.camera,
            s.prev_camera.as_ref().unwrap_or(&s.camera),
            s.width,
            s.height,
        )
        .with_viewport(size[0], size[1])
        .jittered(jitter);
        let sun = s.directional_light()?;
        let fixed = match &s.sun {
            SunSource::Fixed(f) => Some(f),
            _ => None,
        };
        let sky = if settings.sky.enabled {
            Some(FrameSky::new(&settings.sky, fixed)?)
        } else {
            None
        };
        let sky_lux = sky.as_ref().map_or(0.0, |k| k.sky_lux);
        let metered_lux = metered_lux(settings, sun.as_ref(), sky_lux);
        let ev100 = settings
            .exposure
            .ev100
            .unwrap_or_else(|| (metered_lux * 100.0 / 250.0).log2());
        let clock_s = settings
            .sky
            .date_time()
            .map_or(0.0, |t| f64::from(t.seconds_of_day()));
        Ok(Self {
            size,
            output_size,
            aspect,
            frame_index,
            jitter,
            view,
            history,
            sun,
            sky,
            sky_lux,
            metered_lux,
            ev100,
            light_cutoff_lux: light_cutoff_lux(metered_lux),
            clock_s,
            punctual_lights: if settings.direct_lighting.punctual {
                scene_lights
            } else {
                0
            },
        })
    }

    /// The context of a bare `view` at `frame_index` with valid history, for passes recorded
    /// outside a renderer's frame (tests, tools): no sun, no sky, a 1000 lux meter.
    pub fn for_view(view: View, frame_index: u64) -> Self {
        let size = [view.viewport[0] as u32, view.viewport[1] as u32];
        let metered_lux = 1000.0;
        Self {
            size,
            output_size: size,
            aspect: view.viewport[0] / view.viewport[1].max(1.0),
            frame_index,
            jitter: [view.jitter[0], view.jitter[1]],
            view,
            history: HistoryValidity::VALID,
            sun: None,
            sky: None,
            sky_lux: 0.0,
            metered_lux,
            ev100: (metered_lux * 100.0 / 250.0).log2(),
            light_cutoff_lux: light_cutoff_lux(metered_lux),
            clock_s: 0.0,
            punctual_lights: 0,
        }
    }

    /// The directional light where `direct_lighting.sun` lets it light surfaces (the haze,
    /// the particles).
    pub fn lit_sun<'a>(&'a self, settings: &Settings) -> Option<&'a Sun> {
        self.sun.as_ref().filter(|_| settings.direct_lighting.sun)
    }

    /// The directional light's elevation in degrees (NaN without one).
    pub fn sun_elevation_deg(&self) -> f32 {
        self.sun.as_ref().map_or(f32::NAN, |sun| {
            sun.direction
                .normalize_or_zero()
                .y
                .clamp(-1.0, 1.0)
                .asin()
                .to_degrees()
        })
    }
}

/// The illuminance the exposure is set for, with the sky's own light (`sky_lux` on a
/// horizontal plane): the configured EV100's, else the larger of the sun's and the sky's (at
/// least a thousandth of a lux, so that a scene without either stays finite). At dawn and dusk
/// the sky outshines the low sun; the punctual lights' cut-off follows it.
pub fn metered_lux(settings: &Settings, sun: Option<&Sun>, sky_lux: f32) -> f32 {
    match settings.exposure.ev100 {
        Some(ev) => 2f32.powf(ev) * 250.0 / 100.0,
        None => sun
            .map_or(0.0, |s| s.illuminance_lux)
            .max(sky_lux)
            .max(1e-3),
    }
}

/// Last frame's adapted exposure, for passes that run before this frame's.
#[derive(Clone, Copy, Debug)]
pub struct PreviousExposure {
    /// `exposure.state` as the last frame left it: Rgba32Float 1x1, x the EV100 (scale =
    /// 1 / (1.2 · 2^x)), y 1 once written (zeros in a new history).
    pub state: crate::graph::Tex,
    /// Whether a frame has written it (false on a graph runtime's first frame).
    pub valid: bool,
}
