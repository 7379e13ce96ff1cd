//! `hikari render`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use hikari_render::graph::TimestampMode;
use hikari_render::techniques::tonemap::{self, cube::CubeLut, lut_strip, lut_strip::StripLayout};
use hikari_render::{ContextOptions, GpuContext, Renderer, output};

use crate::args::FrameArgs;
use crate::probe_bake;
use crate::report;
use crate::scene_source::{self, ResolvedFrame};

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
    /// Frames of the same view to render; the last is written. Default: one jitter cycle of
    /// TAA (`taa.jitter_samples`, 8), after which the history is the exact mean of every
    /// sub-pixel position; 1 with TAA off.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub frames: Option<u32>,
    /// Print a per-pass GPU timing table.
    #[arg(long)]
    pub timings: bool,
    /// Also write these intermediate resources as EXR (e.g. `gbuffer.normal`); repeatable.
    #[arg(long = "dump", value_name = "NAME")]
    pub dumps: Vec<String>,
    /// Folder for `--dump` files; defaults to the PNG's folder.
    #[arg(long)]
    pub dump_dir: Option<PathBuf>,
    /// Irradiance-probe bake file [default: the cache under $XDG_CACHE_HOME/hikari, baked
    /// on a miss].
    #[arg(long)]
    pub bake: Option<PathBuf>,
    /// Append a 32x32x32 LUT strip below the PNG (the current grade, identity if none) to
    /// grade in a photo editor; `hikari lut extract` reads the grade back (docs/tonemapping.md).
    #[arg(long)]
    pub lut_screenshot: bool,
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let ResolvedFrame {
        scene,
        settings,
        description,
    } = scene_source::resolve(&args.frame)?;
    log::info!("{}", description.line());
    let strip_lut = if args.lut_screenshot {
        if StripLayout::for_width(settings.width).is_none() {
            anyhow::bail!(
                "--lut-screenshot needs an image at least 32 px wide for its LUT strip; --width is {}",
                settings.width
            );
        }
        Some(match tonemap::graded_by(&settings.settings.tonemap) {
            Some(p) => {
                CubeLut::read(p).map_err(|e| anyhow::anyhow!("settings `tonemap.lut`: {e}"))?
            }
            None => CubeLut::identity(lut_strip::STRIP_SIZE as usize),
        })
    } else {
        None
    };
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    log::info!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::new(ctx, &scene)?;
    probe_bake::attach(
        &mut renderer,
        &scene,
        &description.source,
        &settings,
        args.bake.as_deref(),
    )?;
    renderer.runtime.set_dumps(args.dumps.clone());
    // Timing each pass splits merged compute passes and costs the GPU about 10 us a pass.
    renderer.runtime.set_timestamps(if args.timings {
        TimestampMode::Pass
    } else {
        TimestampMode::Frame
    });
    let frames = args.frames.unwrap_or(if settings.settings.taa.enabled {
        settings.settings.taa.jitter_samples
    } else {
        1
    });
    for _ in 1..frames {
        renderer.render(&settings, false)?;
    }
    let frame = renderer.render(&settings, true)?;

    let png = &args.output;
    let ldr = frame.ldr.as_ref().context("no LDR image")?;
    match &strip_lut {
        Some(lut) => {
            let shot = lut_strip::embed(ldr, lut).context("the LUT strip does not fit")?;
            output::write_png(png, &shot)?;
        }
        None => output::write_png(png, ldr)?,
    }
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
        report::print_single_frame(&frame.result);
    }
    Ok(())
}
