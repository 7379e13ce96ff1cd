//! `hikari render`.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;

use hikari_render::graph::TimestampMode;
use hikari_render::{ContextOptions, FrameSettings, GpuContext, Renderer, output};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Built-in scene (boxes, cornell, terrain) or a .gltf/.glb file.
    #[arg(long, default_value = "boxes")]
    pub scene: String,
    /// Camera name in the scene; the scene's first camera if omitted.
    #[arg(long)]
    pub camera: Option<String>,
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// PNG output (display-encoded sRGB).
    #[arg(short, long, default_value = "hikari.png")]
    pub output: PathBuf,
    /// EXR output (linear radiance in nits); defaults to the PNG path with `.exr`.
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Do not write the EXR.
    #[arg(long)]
    pub no_exr: bool,
    /// Placeholder exposure: EV at ISO 100 (sunny day about 15, overcast 12, interior 7).
    #[arg(long, default_value_t = 14.0, allow_negative_numbers = true)]
    pub ev100: f32,
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

pub fn settings(
    scene: &hikari_scene::Scene,
    camera: Option<&str>,
    width: u32,
    height: u32,
    ev100: f32,
) -> anyhow::Result<FrameSettings> {
    let camera = match camera {
        Some(name) => scene.camera(name)?.clone(),
        None => scene
            .cameras
            .first()
            .context("the scene has no camera")?
            .clone(),
    };
    if !ev100.is_finite() || !(-10.0..=30.0).contains(&ev100) {
        bail!("--ev100 {ev100} is outside the range -10 to 30");
    }
    Ok(FrameSettings {
        width,
        height,
        camera,
        ev100,
    })
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let scene = load_scene(&args.scene)?;
    let settings = settings(
        &scene,
        args.camera.as_deref(),
        args.width,
        args.height,
        args.ev100,
    )?;
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
    for img in &frame.result.images {
        let p = output::write_dump(&dump_dir, img)?;
        println!("wrote {}", p.display());
    }
    for (name, bytes) in &frame.result.buffers {
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
