//! `hikari render`.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;

use hikari_render::graph::TimestampMode;
use hikari_render::{ContextOptions, FrameSettings, GpuContext, Renderer, output};

/// What to render and how: shared by `render` and `bench frame`.
#[derive(Args, Debug, Clone, Default)]
pub struct FrameArgs {
    /// Built-in scene (village, cornell, terrain, boxes) or a .gltf/.glb file [default: village].
    #[arg(long)]
    pub scene: Option<String>,
    /// Camera name in the scene; the scene's first camera if omitted.
    #[arg(long)]
    pub camera: Option<String>,
    /// Time of day, HH:MM: sets the sun (or moon) by a simple model until the atmosphere
    /// issue [default: the scene's own sun].
    #[arg(long)]
    pub time: Option<String>,
    /// Image width in pixels [default: 1280].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels [default: 720].
    #[arg(long)]
    pub height: Option<u32>,
    /// TOML settings file (docs/config.example.toml); flags win over it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Placeholder exposure: EV at ISO 100 (sunny day about 15, overcast 12, interior 7)
    /// [default: metered from the sun].
    #[arg(long, allow_negative_numbers = true)]
    pub ev100: Option<f32>,
}

impl FrameArgs {
    /// The scene and the frame settings, from the flags, then the config file, then defaults.
    pub fn resolve(&self) -> anyhow::Result<(hikari_scene::Scene, FrameSettings)> {
        let file = match &self.config {
            Some(p) => crate::config::load(p)?,
            None => crate::config::ConfigFile::default(),
        };
        let scene_name = self
            .scene
            .clone()
            .or(file.scene.clone())
            .unwrap_or_else(|| "village".into());
        let scene = load_scene(&scene_name)?;
        let camera = self.camera.as_deref().or(file.camera.as_deref());
        let camera = match camera {
            Some(name) => scene.camera(name)?.clone(),
            None => scene
                .cameras
                .first()
                .context("the scene has no camera")?
                .clone(),
        };
        let sun = match self.time.as_deref().or(file.time.as_deref()) {
            Some(t) => Some(hikari_scene::time_of_day::sun_at(
                hikari_scene::time_of_day::parse_time(t).context("--time")?,
            )),
            None => scene.sun.clone(),
        };
        let mut settings = file.settings();
        if let Some(ev) = self.ev100 {
            if !ev.is_finite() || !(-10.0..=30.0).contains(&ev) {
                bail!("--ev100 {ev} is outside the range -10 to 30");
            }
            settings.exposure.ev100 = Some(ev);
        }
        settings.validate().context("settings")?;
        Ok((
            scene,
            FrameSettings {
                width: self.width.or(file.width).unwrap_or(1280),
                height: self.height.or(file.height).unwrap_or(720),
                camera,
                prev_camera: None,
                sun,
                settings,
            },
        ))
    }
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// PNG output (display-encoded sRGB).
    #[arg(short, long, default_value = "hikari.png")]
    pub output: PathBuf,
    /// EXR output (linear radiance in nits); defaults to the PNG path with `.exr`.
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Do not write the EXR.
    #[arg(long)]
    pub no_exr: bool,
    /// Print a per-pass GPU timing table.
    #[arg(long)]
    pub timings: bool,
    /// Also write these intermediate resources as EXR (e.g. `gbuffer.normal`); repeatable.
    #[arg(long = "dump", value_name = "NAME")]
    pub dumps: Vec<String>,
    /// Folder for `--dump` files; defaults to the PNG's folder.
    #[arg(long)]
    pub dump_dir: Option<PathBuf>,
}

/// A built-in scene by name, or a `.gltf` / `.glb` file by path.
pub fn load_scene(name: &str) -> anyhow::Result<hikari_scene::Scene> {
    if let Some(s) = hikari_scene::builtin::by_name(name) {
        return Ok(s);
    }
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        // The loader logs its warnings (ignored extensions, skipped primitives) itself.
        return Ok(hikari_scene::gltf::load(name)?.scene);
    }
    bail!(
        "unknown scene `{name}`; built-in scenes: {}, or a path to a .gltf or .glb file",
        hikari_scene::builtin::NAMES.join(", ")
    )
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let (scene, settings) = args.frame.resolve()?;
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    log::info!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::new(ctx, &scene)?;
    renderer.runtime.set_dumps(args.dumps.clone());
    // Timing each pass splits merged compute passes and costs the GPU about 10 us a pass.
    renderer.runtime.set_timestamps(if args.timings {
        TimestampMode::Pass
    } else {
        TimestampMode::Frame
    });
    let frame = renderer.render(&settings, true)?;

    let png = &args.output;
    output::write_png(png, frame.ldr.as_ref().context("no LDR image")?)?;
    println!("wrote {}", png.display());
    if !args.no_exr {
        let exr = args
            .exr
            .clone()
            .unwrap_or_else(|| png.with_extension("exr"));
        output::write_exr(&exr, frame.hdr.as_ref().context("no HDR image")?)?;
        println!("wrote {}", exr.display());
    }
    let dump_dir = args
        .dump_dir
        .clone()
        .unwrap_or_else(|| png.parent().map(PathBuf::from).unwrap_or_default());
    // Only what `--dump` asked for: the renderer reads back a few buffers of its own.
    let asked = |name: &str| args.dumps.iter().any(|d| d == name);
    for img in frame.result.images.iter().filter(|i| asked(&i.name)) {
        let p = output::write_dump(&dump_dir, img)?;
        println!("wrote {}", p.display());
    }
    for (name, bytes) in frame.result.buffers.iter().filter(|(n, _)| asked(n)) {
        let p = dump_dir.join(format!("{name}.bin"));
        output::write_atomically(&p, |tmp| {
            std::fs::write(tmp, bytes).map_err(|e| hikari_render::RenderError::Output {
                path: p.display().to_string(),
                message: e.to_string(),
            })
        })?;
        println!("wrote {}", p.display());
    }
    if args.timings {
        crate::bench::print_single_frame(&frame.result);
    }
    Ok(())
}
