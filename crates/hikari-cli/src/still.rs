//! What the commands that render frames of a view share (`render`, `compare`, `timelapse`):
//! the GPU, a renderer with the scene's probe bake attached, how many frames a still view
//! needs, a frame's images and exposure read back, and the checks on where the
//! images go, made before anything is rendered.

use std::path::Path;

use anyhow::Context;

use hikari_render::graph::ImageRgba32;
use hikari_render::{ContextOptions, FrameSettings, GpuContext, RenderedFrame, Renderer, output};

use crate::probe_bake;
use crate::progress::{Counter, Step};
use crate::scene_source::ResolvedFrame;

/// The GPU the environment picks (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`), checked for what
/// hikari needs ([`crate::gpu_check`]).
pub fn gpu() -> anyhow::Result<GpuContext> {
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    log::info!("adapter: {}", ctx.describe());
    crate::gpu_check::ensure_can_run(&ctx)?;
    Ok(ctx)
}

/// A renderer of `frame`'s scene on a new GPU context, with the scene's probe bake attached
/// when its settings use the probes (`bake`: `--bake`, else the cache, baked on a miss);
/// each step shown as progress.
pub fn renderer(frame: &ResolvedFrame, bake: Option<&Path>) -> anyhow::Result<Renderer> {
    renderer_on(start_gpu(frame)?, frame, bake)
}

/// A new GPU context for `frame`, shown as a step; an image larger than the GPU's limit is
/// refused now, not after the renderer's set-up and the bake.
pub fn start_gpu(frame: &ResolvedFrame) -> anyhow::Result<GpuContext> {
    let step = Step::start("starting the GPU");
    let ctx = gpu()?;
    step.done(format!("GPU: {}", ctx.info.name));
    let max = ctx.limits.max_texture_dimension_2d;
    for (what, v) in [
        ("width", frame.settings.width),
        ("height", frame.settings.height),
    ] {
        if v > max {
            anyhow::bail!("image {what} of {v} exceeds this GPU's limit of {max}");
        }
    }
    Ok(ctx)
}

/// [`renderer`] on a GPU context already started ([`start_gpu`]).
pub fn renderer_on(
    ctx: GpuContext,
    frame: &ResolvedFrame,
    bake: Option<&Path>,
) -> anyhow::Result<Renderer> {
    let step = Step::start("preparing the renderer");
    let mut renderer = Renderer::new(ctx, &frame.scene)?;
    step.done("renderer ready");
    probe_bake::attach(
        &mut renderer,
        &frame.scene,
        &frame.description.source,
        &frame.settings,
        bake,
    )?;
    Ok(renderer)
}

/// Renders `frames` frames of `settings` on `renderer` with a progress bar ("rendering
/// {what}"), `before` called ahead of each with the frame's number from 1 (to move the
/// camera); the last is read back and returned.
pub fn render_frames(
    renderer: &mut Renderer,
    settings: &mut FrameSettings,
    frames: u32,
    what: &str,
    mut before: impl FnMut(u32, &mut FrameSettings),
) -> anyhow::Result<RenderedFrame> {
    let label = format!("rendering {what}");
    // The first frame compiles the shaders: on the CPU driver most of a short render.
    let bar = Counter::start(
        format!("{label} (the first frame compiles the shaders)"),
        u64::from(frames),
        "frames",
    );
    for f in 1..frames {
        before(f, settings);
        renderer.render(settings, false)?;
        bar.inc();
        if f == 1 {
            bar.set_message(label.clone());
            bar.reset_eta();
        }
    }
    before(frames, settings);
    let frame = renderer.render(settings, true)?;
    bar.inc();
    bar.done(format!("rendered {what}"));
    Ok(frame)
}

/// Frames `render` draws of a still view when `--frames` is not given: the larger of what TAA
/// and the ray-traced GI need, in whole jitter cycles of TAA.
///
/// * TAA: one jitter cycle (`taa.jitter_samples`), after which its history is the mean of every
///   sub-pixel position.
/// * GI: the denoiser's combiner keeps `0.5 x speed` of the accumulated signal, where speed =
///   min(1 - 1 / history, `gi_denoiser.max_accumulation_speed`); the frames until speed reaches
///   that cap (history >= 1 / (1 - cap): 15 for the talk's 0.93), at most the accumulation's
///   `max_history`. Before then the image is mostly the spatially denoised single frames.
pub fn default_frames(s: &hikari_render::Settings) -> u32 {
    let cycle = if s.taa.enabled {
        s.taa.jitter_samples.max(1)
    } else {
        1
    };
    let gi = &s.ray_traced_gi;
    let gi_frames = if gi.enabled && gi.accumulate {
        let cap = s.gi_denoiser.max_accumulation_speed as f64;
        // Less a hair, so that a cap such as 0.8 (0.800000012 in f32) settles at 5, not 6.
        let history = if cap < 1.0 {
            (1.0 / (1.0 - cap) - 1e-4).ceil() as u32
        } else {
            u32::MAX
        };
        history.min(gi.max_history.max(1))
    } else {
        1
    };
    gi_frames.max(cycle).div_ceil(cycle) * cycle
}

/// The exposure's buffer, `vec4<f32>(scale, ev100, metered lux, highlight)`: a renderer
/// whose runtime dumps it ([`read_exposure`]) reads it back every frame.
const EXPOSURE_VALUE: &str = "exposure.value";

/// Has `renderer` read back each frame's exposure, for [`ev100`].
pub fn read_exposure(renderer: &mut Renderer) {
    renderer.runtime.set_dumps(vec![EXPOSURE_VALUE.into()]);
}

/// The EV100 `frame` was shown at (metered, or fixed by `exposure.ev100`), from a renderer
/// set up with [`read_exposure`].
pub fn ev100(frame: &RenderedFrame) -> anyhow::Result<f32> {
    frame
        .result
        .buffer(EXPOSURE_VALUE)
        .filter(|b| b.len() >= 8)
        .map(|b| f32::from_le_bytes([b[4], b[5], b[6], b[7]]))
        .context("the frame's exposure was not read back")
}

/// The linear (nits) and the display images of a frame rendered with its images read back.
pub fn images(frame: &RenderedFrame) -> anyhow::Result<(&ImageRgba32, &ImageRgba32)> {
    Ok((
        frame.hdr.as_ref().context("no HDR image")?,
        frame.ldr.as_ref().context("no LDR image")?,
    ))
}

/// Checks, before anything is rendered, that `file` (named by `flag`) can be written: its
/// folder exists and it is not itself a folder.
pub fn check_output_file(flag: &str, file: &Path) -> anyhow::Result<()> {
    let dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        anyhow::bail!(
            "{flag} {}: the folder {} does not exist",
            file.display(),
            dir.display()
        );
    }
    if file.is_dir() {
        anyhow::bail!("{flag} {}: is a folder, not a file", file.display());
    }
    Ok(())
}

/// The image files hikari writes, each by the extension its name must end in: hikari writes
/// no other format, and never one format under another's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFile {
    /// 8-bit sRGB, display-encoded.
    Png,
    /// OpenEXR, linear radiance in nits.
    Exr,
}

impl ImageFile {
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Exr => "exr",
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Self::Png => "PNG (8-bit sRGB)",
            Self::Exr => "OpenEXR (linear radiance in nits)",
        }
    }
}

/// [`check_output_file`], and that `file`'s name ends in `kind`'s extension (any case): an
/// error naming the flag, the format written and the extension otherwise.
pub fn check_image_file(flag: &str, file: &Path, kind: ImageFile) -> anyhow::Result<()> {
    let ext = kind.extension();
    if !file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    {
        anyhow::bail!(
            "{flag} {}: this writes {}; give a file name ending in .{ext}",
            file.display(),
            kind.describe()
        );
    }
    check_output_file(flag, file)
}

/// Creates the output folder `dir` (named by `flag`) with its parents if it is missing; an
/// error naming the flag if something that is not a folder is there.
pub fn output_folder(flag: &str, dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!(
            "{flag} {}: exists and is not a folder; give a folder for the frames",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{flag} {}: cannot create the folder", dir.display()))
}

/// Writes the display image as a PNG and, unless `exr` is `None`, the linear image as an
/// EXR, each atomically (hikari-render's `output`).
pub fn write_images(png: &Path, exr: Option<&Path>, frame: &RenderedFrame) -> anyhow::Result<()> {
    let (hdr, ldr) = images(frame)?;
    output::write_png(png, ldr)?;
    if let Some(exr) = exr {
        output::write_exr(exr, hdr)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The history length at which the combiner's speed, min(1 - 1/h, cap), first equals
    /// the cap: stepped frame by frame as the accumulation counts.
    fn combiner_settles(cap: f32, max_history: u32) -> u32 {
        (1..=max_history)
            .find(|&h| (1.0 - 1.0 / h as f32).min(cap) >= cap)
            .unwrap_or(max_history)
    }

    #[test]
    fn default_frames_cover_taa_cycles_and_the_gi_combiners_settling() {
        let mut s = hikari_render::Settings::default();
        let settle = combiner_settles(
            s.gi_denoiser.max_accumulation_speed,
            s.ray_traced_gi.max_history,
        );
        assert_eq!(
            settle, 15,
            "the talk's 0.93 settles at 15 frames of history"
        );
        // 15 frames, rounded up to whole 8-frame jitter cycles.
        assert_eq!(default_frames(&s), 16);
        s.taa.enabled = false;
        assert_eq!(default_frames(&s), settle);
        s.ray_traced_gi.enabled = false;
        assert_eq!(default_frames(&s), 1);
        s.taa.enabled = true;
        assert_eq!(default_frames(&s), s.taa.jitter_samples);
        s.ray_traced_gi.enabled = true;
        s.ray_traced_gi.accumulate = false;
        assert_eq!(default_frames(&s), s.taa.jitter_samples);
        s.ray_traced_gi.accumulate = true;
        for cap in [0.0, 0.5, 0.8, 0.9, 0.95, 0.99, 1.0] {
            s.gi_denoiser.max_accumulation_speed = cap;
            s.taa.enabled = false;
            let want = combiner_settles(cap, s.ray_traced_gi.max_history);
            assert_eq!(default_frames(&s), want, "cap {cap}");
            s.taa.enabled = true;
            assert_eq!(default_frames(&s), want.max(8).div_ceil(8) * 8, "cap {cap}");
        }
    }

    #[test]
    fn output_checks_name_the_flag_and_what_is_wrong() {
        let dir = std::env::temp_dir().join(format!("hikari-still-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("taken");
        std::fs::write(&file, "x").unwrap();
        let e = output_folder("-o", &file).unwrap_err().to_string();
        assert!(e.contains("-o") && e.contains("not a folder"), "{e}");
        let nested = dir.join("a/b");
        output_folder("-o", &nested).unwrap();
        assert!(nested.is_dir());
        let e = check_output_file("--exr-a", &dir.join("no/x.exr"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--exr-a") && e.contains("does not exist"), "{e}");
        assert!(check_output_file("-o", &dir).is_err());
        check_output_file("-o", &file).unwrap();

        let png = dir.join("a.PNG");
        check_image_file("-o", &png, ImageFile::Png).unwrap();
        check_image_file("--exr", &dir.join("a.exr"), ImageFile::Exr).unwrap();
        for (name, kind) in [
            ("x.jpg", ImageFile::Png),
            ("x", ImageFile::Png),
            ("x.exr", ImageFile::Png),
            ("x.png", ImageFile::Exr),
        ] {
            let e = check_image_file("-o", &dir.join(name), kind)
                .unwrap_err()
                .to_string();
            let want = format!("ending in .{}", kind.extension());
            assert!(e.contains(name) && e.contains(&want), "{e}");
        }
    }
}
