//! `hikari render`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use hikari_render::graph::TimestampMode;
use hikari_render::output;
use hikari_render::techniques::tonemap::{self, cube::CubeLut, lut_strip, lut_strip::StripLayout};

use crate::args::FrameArgs;
use crate::progress::{self, ProgressArgs, Step};
use crate::report;
use crate::scene_source;
use crate::still::{self, ImageFile};

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
    /// Frames of the same view to render; the last is written. Default: enough for the
    /// temporal passes to converge, whole TAA jitter cycles: with ray-traced GI 16 (the GI
    /// denoiser's combiner reaches its steady speed, `gi_denoiser.max_accumulation_speed`
    /// 0.93, at 15 frames of history), else one cycle (`taa.jitter_samples`, 8, after which
    /// TAA's history is the mean of every sub-pixel position); 1 with both off.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub frames: Option<u32>,
    /// Arrive at the view moving: over the frames rendered the camera travels this many
    /// metres a frame along its view direction (negative: backing away) and reaches the
    /// view on the last frame, the one written. Shows what the temporal passes (TAA, the
    /// GI's history) make of a camera in motion. 0: a still camera.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub dolly: f32,
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
    #[command(flatten)]
    pub progress: ProgressArgs,
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    progress::set_quiet(args.progress.quiet);
    anyhow::ensure!(
        args.dolly.is_finite() && args.dolly.abs() <= 100.0,
        "--dolly {} is outside -100 to 100 metres a frame",
        args.dolly
    );
    still::check_image_file("-o", &args.output, ImageFile::Png)?;
    if let Some(exr) = args.exr.as_ref().filter(|_| !args.no_exr) {
        still::check_image_file("--exr", exr, ImageFile::Exr)?;
    }
    let step = Step::start("reading the scene and the settings");
    let resolved = scene_source::resolve(&args.frame)?;
    log::info!("{}", resolved.description.line());
    step.done(resolved.description.line());
    let ctx = still::start_gpu(&resolved)?;
    let resolved = scene_source::fit_to_adapter(resolved, &args.frame, &ctx)?;
    let mut settings = resolved.settings.clone();
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
    let mut renderer = still::renderer_on(ctx, &resolved, args.bake.as_deref())?;
    renderer.runtime.set_dumps(args.dumps.clone());
    // Timing each pass splits merged compute passes and costs the GPU about 10 us a pass.
    renderer.runtime.set_timestamps(if args.timings {
        TimestampMode::Pass
    } else {
        TimestampMode::Frame
    });
    let frames = args
        .frames
        .unwrap_or_else(|| still::default_frames(&settings.settings));
    let view = settings.camera.clone();
    let forward = view.forward();
    let dolly = args.dolly;
    let frame = still::render_frames(&mut renderer, &mut settings, frames, "the view", |f, s| {
        if dolly != 0.0 {
            let back = forward * (dolly * (frames - f) as f32);
            s.prev_camera = (f > 1).then(|| s.camera.clone());
            s.camera.position = view.position - back;
            s.camera.target = view.target - back;
        }
    })?;

    let png = &args.output;
    let step = Step::start(format!("writing {}", png.display()));
    // Printed once the step's line is gone, so that stdout and the bar do not mix.
    let mut wrote = Vec::new();
    let (hdr, ldr) = still::images(&frame)?;
    match &strip_lut {
        Some(lut) => {
            let shot = lut_strip::embed(ldr, lut).context("the LUT strip does not fit")?;
            output::write_png(png, &shot)?;
        }
        None => output::write_png(png, ldr)?,
    }
    wrote.push(png.display().to_string());
    if !args.no_exr {
        let exr = args
            .exr
            .clone()
            .unwrap_or_else(|| png.with_extension("exr"));
        output::write_exr(&exr, hdr)?;
        wrote.push(exr.display().to_string());
    }
    let dump_dir = args
        .dump_dir
        .clone()
        .unwrap_or_else(|| png.parent().map(PathBuf::from).unwrap_or_default());
    // Only what `--dump` asked for: the renderer reads back a few buffers of its own.
    let asked = |name: &str| args.dumps.iter().any(|d| d == name);
    for img in frame.result.images.iter().filter(|i| asked(&i.name)) {
        let p = output::write_dump(&dump_dir, img)?;
        wrote.push(p.display().to_string());
    }
    for (name, bytes) in frame.result.buffers.iter().filter(|(n, _)| asked(n)) {
        let p = dump_dir.join(format!("{name}.bin"));
        output::write_atomically(&p, |tmp| {
            std::fs::write(tmp, bytes).map_err(|e| hikari_render::RenderError::Output {
                path: p.display().to_string(),
                message: e.to_string(),
            })
        })?;
        wrote.push(p.display().to_string());
    }
    step.clear();
    for p in wrote {
        println!("wrote {p}");
    }
    if args.timings {
        report::print_single_frame(&frame.result);
    }
    Ok(())
}
