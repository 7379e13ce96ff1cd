//! What the commands that render frames of a view share (`render`, `compare`, `timelapse`):
//! the GPU, a renderer with the scene's probe bake attached, how many frames a still view
//! needs, a frame's images and exposure read back, and the checks on where the
//! images go, made before anything is rendered.

use std::path::Path;

use anyhow::Context;

use hikari_render::graph::ImageRgba32;
use hikari_render::{ContextOptions, GpuContext, RenderedFrame, Renderer, output};

use crate::probe_bake;
use crate::scene_source::ResolvedFrame;

/// The GPU the environment picks (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`).
pub fn gpu() -> anyhow::Result<GpuContext> {
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    log::info!("adapter: {}", ctx.describe());
    Ok(ctx)
}

/// A renderer of `frame`'s scene on a new GPU context, with the scene's probe bake attached
/// when its settings use the probes (`bake`: `--bake`, else the cache, baked on a miss).
pub fn renderer(frame: &ResolvedFrame, bake: Option<&Path>) -> anyhow::Result<Renderer> {
    let mut renderer = Renderer::new(gpu()?, &frame.scene)?;
    probe_bake::attach(
        &mut renderer,
        &frame.scene,
        &frame.description.source,
        &frame.settings,
        bake,
    )?;
    Ok(renderer)
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
    }
}
