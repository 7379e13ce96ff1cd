//! Turning the scene flags into what the renderer needs: the scene (built-in by name or a glTF
//! file), the camera, the sun and the frame settings, plus a description of exactly what was
//! chosen so that reports name what really ran.

use std::path::PathBuf;

use anyhow::{Context, bail};
use serde_json::json;

use hikari_render::{FrameSettings, SunSource};
use hikari_scene::{Camera, Scene};

use crate::args::FrameArgs;

/// The scene used when neither a flag nor the config file names one.
pub const DEFAULT_SCENE: &str = "village";
/// Image size used when neither a flag nor the config file gives one, in pixels.
pub const DEFAULT_SIZE: (u32, u32) = (1280, 720);

/// Where a scene comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SceneSource {
    /// One of `hikari_scene::builtin::NAMES`.
    Builtin(String),
    /// A `.gltf` or `.glb` file.
    Gltf(PathBuf),
}

impl SceneSource {
    /// A built-in scene name, or a path ending in `.gltf` / `.glb` (any case). Anything else
    /// is an error that says what it is (a folder, a file of another kind) or, for a name,
    /// the nearest built-in one.
    pub fn parse(name: &str) -> anyhow::Result<Self> {
        let builtin = hikari_scene::builtin::NAMES;
        if builtin.contains(&name) {
            return Ok(Self::Builtin(name.to_string()));
        }
        let path = std::path::Path::new(name);
        if path.is_dir() {
            bail!(
                "--scene {name}: is a folder; give a .gltf or .glb file in it, or a built-in \
                 scene ({})",
                builtin.join(", ")
            );
        }
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".gltf") || lower.ends_with(".glb") {
            return Ok(Self::Gltf(PathBuf::from(name)));
        }
        if path.is_file() {
            bail!(
                "--scene {name}: hikari reads glTF 2.0 scenes, files ending in .gltf or .glb; \
                 or give a built-in scene ({})",
                builtin.join(", ")
            );
        }
        bail!(
            "unknown scene `{name}`{}; built-in scenes: {}, or a path to a .gltf or .glb file",
            nearest(name, builtin).map_or(String::new(), |n| format!(" (did you mean `{n}`?)")),
            builtin.join(", ")
        )
    }

    pub fn load(&self) -> anyhow::Result<Scene> {
        match self {
            Self::Builtin(name) => hikari_scene::builtin::by_name(name)
                .with_context(|| format!("built-in scene `{name}` is listed but not built")),
            // The loader logs its warnings (ignored extensions, skipped primitives) itself.
            Self::Gltf(path) => Ok(hikari_scene::gltf::load(path)?.scene),
        }
    }

    /// The name as the user gave it: the built-in name or the file path.
    pub fn name(&self) -> String {
        match self {
            Self::Builtin(name) => name.clone(),
            Self::Gltf(path) => path.display().to_string(),
        }
    }

    /// `"built-in"` or `"glTF"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Builtin(_) => "built-in",
            Self::Gltf(_) => "glTF",
        }
    }
}

/// The name of `names` nearest to `name` when it is a likely misspelling: at most a third
/// of its letters edited (at least one), case aside.
pub fn nearest<'a>(name: &str, names: &[&'a str]) -> Option<&'a str> {
    let name = name.to_lowercase();
    let limit = (name.chars().count() / 3).max(1);
    names
        .iter()
        .map(|n| (strsim::levenshtein(&name, &n.to_lowercase()), *n))
        .filter(|(d, _)| *d <= limit)
        .min()
        .map(|(_, n)| n)
}

/// A built-in scene by name, or a `.gltf` / `.glb` file by path.
pub fn load_scene(name: &str) -> anyhow::Result<Scene> {
    SceneSource::parse(name)?.load()
}

/// Where the camera's name came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraOrigin {
    Flag,
    ConfigFile,
    /// Nobody named one: the scene's first camera.
    SceneFirst,
    /// The scene has no camera: one framing its bounds.
    Framing,
    /// The scene has neither a camera nor geometry: one looking at the horizon.
    Horizon,
}

impl CameraOrigin {
    fn describe(self) -> &'static str {
        match self {
            Self::Flag => "--camera",
            Self::ConfigFile => "config file",
            Self::SceneFirst => "the scene's first",
            Self::Framing => "framing the scene's bounds",
            Self::Horizon => "looking at the horizon: nothing to frame",
        }
    }
}

/// The named camera, or else the scene's first one; an error if there is neither.
pub fn choose_camera(
    scene: &Scene,
    flag: Option<&str>,
    config: Option<&str>,
) -> anyhow::Result<(Camera, CameraOrigin)> {
    if let Some(name) = flag {
        return Ok((scene.camera(name)?.clone(), CameraOrigin::Flag));
    }
    if let Some(name) = config {
        return Ok((scene.camera(name)?.clone(), CameraOrigin::ConfigFile));
    }
    let first = scene.cameras.first().context("the scene has no camera")?;
    Ok((first.clone(), CameraOrigin::SceneFirst))
}

/// The scene's first camera, or one framing its bounds when it has none, or one looking at
/// the horizon ([`Camera::horizon`], with a warning) when it has no geometry either.
pub fn first_or_framing_camera(
    scene: &Scene,
    name: &str,
) -> anyhow::Result<(Camera, CameraOrigin)> {
    match (scene.cameras.first(), scene.bounds()) {
        (Some(c), _) => Ok((c.clone(), CameraOrigin::SceneFirst)),
        (None, Some((lo, hi))) => Ok((Camera::framing(name, lo, hi), CameraOrigin::Framing)),
        (None, None) => {
            log::warn!("the scene has neither a camera nor geometry: looking at the horizon");
            Ok((Camera::horizon(name), CameraOrigin::Horizon))
        }
    }
}

/// What a frame was made of, as resolved from flags, config file and defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameDescription {
    pub source: SceneSource,
    pub camera: String,
    pub camera_origin: CameraOrigin,
    /// Local time of the sun and sky (`HH:MM`, or `HH:MM:SS`); `None` when the scene's own
    /// sun (or none) lights it.
    pub time: Option<String>,
    /// Local date of the sun and sky, `YYYY-MM-DD`, with `time`.
    pub date: Option<String>,
    /// Pixels.
    pub width: u32,
    pub height: u32,
}

impl FrameDescription {
    /// E.g. "scene village (built-in), camera `courtyard` (--camera), time 07:30, 64x64".
    pub fn line(&self) -> String {
        let time = match &self.time {
            Some(t) => format!("date {}, time {t}", self.date.as_deref().unwrap_or("?")),
            None => "the scene's own sun".to_string(),
        };
        format!(
            "scene {} ({}), camera `{}` ({}), {time}, {}x{}",
            self.source.name(),
            self.source.kind(),
            self.camera,
            self.camera_origin.describe(),
            self.width,
            self.height
        )
    }

    pub fn json(&self) -> serde_json::Value {
        json!({
            "name": self.source.name(),
            "source": self.source.kind(),
            "camera": self.camera,
            "camera_from": self.camera_origin.describe(),
            "time": self.time,
            "date": self.date,
            "width": self.width,
            "height": self.height,
        })
    }
}

/// A scene ready to render, its frame settings and what they were made of.
pub struct ResolvedFrame {
    pub scene: Scene,
    pub settings: FrameSettings,
    pub description: FrameDescription,
    /// Whether `--preset` or the config file chose the preset (else the default did).
    pub preset_given: bool,
}

/// Which light a scene gets, and the time it shows (`None`: the scene's own sun).
///
/// * A date or time given (flags, the file's `time` or `[sky]` date/time other than the
///   defaults): the sun or moon of that instant, whatever the scene.
/// * Else a scene that brings its own sun (a glTF directional light, or a built-in scene
///   other than the village) keeps it; the sky follows that sun's direction.
/// * Else a scene with no sun at all (the Cornell box) gets no sun and no sky light.
/// * Else (the village, a glTF without lights) the sun or moon of the default instant.
///
/// `--no-sun` (`sky.sun = false`) always removes the directional light.
fn is_default_sun(s: &hikari_scene::Sun) -> bool {
    let d = hikari_scene::Sun::default();
    s.direction == d.direction && s.illuminance_lux == d.illuminance_lux && s.color == d.color
}

fn choose_light(
    source: &SceneSource,
    scene: &Scene,
    settings: &mut hikari_render::Settings,
    args: &FrameArgs,
    file: &crate::config::ConfigFile,
) -> anyhow::Result<(SunSource, Option<String>)> {
    let defaults = hikari_render::settings::SkySettings::default();
    let sky = &settings.sky;
    let time_given = args.sky.sets_time()
        || file.time.is_some()
        || sky.date != defaults.date
        || sky.time != defaults.time;
    let own_sun = match (source, &scene.sun) {
        (_, None) => None,
        // The loader gives a lightless glTF the default sun: that one is not the scene's own.
        (SceneSource::Gltf(_), Some(s)) if is_default_sun(s) => None,
        (SceneSource::Builtin(name), Some(_)) if name == "village" => None,
        (_, Some(s)) => Some(s.clone()),
    };
    let when = sky.date_time()?;
    let (h, m, sec) = when.time();
    let now = Some(if sec == 0 {
        format!("{h:02}:{m:02}")
    } else {
        format!("{h:02}:{m:02}:{sec:02}")
    });
    if time_given {
        return Ok((SunSource::Sky, now));
    }
    if scene.sun.is_none() {
        settings.sky.sun = false;
        settings.sky.sky = false;
        return Ok((SunSource::Off, None));
    }
    Ok(match own_sun {
        Some(s) => (SunSource::Fixed(s), None),
        None => (SunSource::Sky, now),
    })
}

/// An image is at least a pixel each way: checked here, before the GPU starts (its upper
/// limit is the GPU's, checked when the renderer sizes its textures).
fn check_size(args: &FrameArgs, width: u32, height: u32) -> anyhow::Result<()> {
    for (what, flag, given, v) in [
        ("width", "--width", args.size.width.is_some(), width),
        ("height", "--height", args.size.height.is_some(), height),
    ] {
        if v == 0 {
            let from = if given {
                format!("{flag} 0")
            } else {
                format!("the config file's `{what} = 0`")
            };
            bail!("{from}: the image {what} must be at least 1 pixel");
        }
    }
    Ok(())
}

/// The scene and the frame settings: from the flags, then the config file, then defaults.
pub fn resolve(args: &FrameArgs) -> anyhow::Result<ResolvedFrame> {
    resolve_loaded(args, None)
}

/// What a CPU adapter gets by default: a frame resolved without a preset from the flags or
/// the file is resolved again at `low` (a quarter of the pixels, rendered at scale 0.5 and
/// upsampled), so that the first picture on a machine without a GPU takes about a minute;
/// said on stderr. Any other frame is returned as it is.
pub fn fit_to_adapter(
    frame: ResolvedFrame,
    args: &FrameArgs,
    ctx: &hikari_render::GpuContext,
) -> anyhow::Result<ResolvedFrame> {
    if frame.preset_given || ctx.info.device_type != hikari_render::wgpu::DeviceType::Cpu {
        return Ok(frame);
    }
    let mut low = args.clone();
    low.config.preset = Some(hikari_render::Preset::Low);
    let frame = resolve_loaded(&low, Some(frame.scene))?;
    crate::progress::note(&format!(
        "CPU adapter ({}): preset low, render scale {} (--preset high for the full frame)",
        ctx.info.name, frame.settings.settings.taa.render_scale
    ));
    Ok(frame)
}

/// [`resolve`], with the scene already loaded when `loaded` has it.
fn resolve_loaded(args: &FrameArgs, loaded: Option<Scene>) -> anyhow::Result<ResolvedFrame> {
    let file = match &args.config.config {
        Some(p) => crate::config::load(p)?,
        None => crate::config::ConfigFile::default(),
    };
    let scene_name = args
        .scene
        .scene
        .clone()
        .or(file.scene.clone())
        .unwrap_or_else(|| DEFAULT_SCENE.into());
    let source = SceneSource::parse(&scene_name)?;
    let width = args.size.width.or(file.width).unwrap_or(DEFAULT_SIZE.0);
    let height = args.size.height.or(file.height).unwrap_or(DEFAULT_SIZE.1);
    check_size(args, width, height)?;
    let scene = match loaded {
        Some(scene) => scene,
        None => source.load()?,
    };
    let (camera, camera_origin) = choose_camera(
        &scene,
        args.camera.camera.as_deref(),
        file.camera.as_deref(),
    )?;
    let overrides: Vec<(String, String)> = args
        .config
        .all_overrides()
        .into_iter()
        .chain(args.tonemap.overrides()?)
        .collect();
    let mut settings = file
        .settings_with(args.config.preset, &overrides)
        .context("settings")?;
    // A bad grade fails here, before the GPU starts and before anything is written.
    if let Some(p) = hikari_render::techniques::tonemap::graded_by(&settings.tonemap) {
        hikari_render::techniques::tonemap::cube::CubeLut::read(p)
            .map_err(|e| anyhow::anyhow!("settings `tonemap.lut`: {e}"))?;
    }
    if let Some(t) = &file.time {
        settings.sky.time = t.clone();
        hikari_render::settings::TechniqueSettings::validate(&settings.sky, "sky")
            .map_err(|e| anyhow::anyhow!("{e}"))
            .context("the config file's `time`")?;
    }
    args.sky.apply(&mut settings.sky)?;
    args.lights.apply(&mut settings.sky);
    if let Some(ev) = args.exposure.ev100 {
        if !ev.is_finite() || !(-10.0..=30.0).contains(&ev) {
            bail!("--ev100 {ev} is outside the range -10 to 30");
        }
        settings.exposure.ev100 = Some(ev);
    }
    settings.validate().context("settings")?;
    let (sun, time) = choose_light(&source, &scene, &mut settings, args, &file)?;
    let description = FrameDescription {
        source,
        camera: camera.name.clone(),
        camera_origin,
        date: time.as_ref().map(|_| settings.sky.date.clone()),
        time,
        width,
        height,
    };
    Ok(ResolvedFrame {
        scene,
        settings: FrameSettings {
            width,
            height,
            camera,
            prev_camera: None,
            sun,
            settings,
        },
        description,
        preset_given: args.config.preset.is_some() || file.has_preset(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_names_are_built_in_or_gltf_paths_and_anything_else_is_named_in_the_error() {
        assert_eq!(
            SceneSource::parse("cornell").unwrap(),
            SceneSource::Builtin("cornell".into())
        );
        assert_eq!(
            SceneSource::parse("dir/Model.GLB").unwrap(),
            SceneSource::Gltf("dir/Model.GLB".into())
        );
        let e = SceneSource::parse("atlantis").unwrap_err().to_string();
        assert!(e.contains("`atlantis`") && e.contains("village"), "{e}");
        assert!(!e.contains("did you mean"), "{e}");
    }

    #[test]
    fn a_misspelled_scene_gets_the_nearest_built_in_name() {
        for (typo, want) in [
            ("vilage", "village"),
            ("Village", "village"),
            ("cornel", "cornell"),
            ("cutuot", "cutout"),
        ] {
            assert_eq!(
                nearest(typo, hikari_scene::builtin::NAMES),
                Some(want),
                "{typo}"
            );
            let e = SceneSource::parse(typo).unwrap_err().to_string();
            assert!(e.contains(&format!("did you mean `{want}`?")), "{e}");
        }
        assert_eq!(nearest("atlantis", hikari_scene::builtin::NAMES), None);
    }

    #[test]
    fn the_description_names_the_config_files_scene_and_camera_not_the_default() {
        let dir = std::env::temp_dir().join(format!("hikari-scene-source-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let config = dir.join("c.toml");
        std::fs::write(
            &config,
            "scene = \"cornell\"\nwidth = 32\ntime = \"7:30\"\n",
        )
        .unwrap();
        let mut args = FrameArgs::default();
        args.config.config = Some(config);
        args.size.height = Some(16);
        let r = resolve(&args).unwrap();
        let d = &r.description;
        assert_eq!(d.source, SceneSource::Builtin("cornell".into()));
        assert_eq!((d.width, d.height), (32, 16));
        assert_eq!(d.time.as_deref(), Some("07:30"));
        assert_eq!(d.camera_origin, CameraOrigin::SceneFirst);
        assert_eq!(d.camera, r.scene.cameras[0].name);
        assert_eq!(r.settings.camera.name, d.camera);
        let line = d.line();
        assert!(
            line.contains("scene cornell (built-in)") && line.contains("time 07:30"),
            "{line}"
        );
    }
}
