//! Image files: linear EXR and 8-bit sRGB PNG, each written to a temporary file beside the
//! target and renamed over it, so a reader never sees half a file.

use std::path::{Path, PathBuf};

use crate::error::{RenderError, Result};
use crate::graph::ImageRgba32;

fn err(path: &Path, message: impl ToString) -> RenderError {
    RenderError::Output {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

/// Runs `write` on a temporary path in the target's folder, then renames it to `path`.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(err(
            path,
            format!("folder {} does not exist", dir.display()),
        ));
    }
    let file = path
        .file_name()
        .ok_or_else(|| err(path, "not a file path"))?;
    // Keep the extension last: image encoders pick the format from it.
    let tmp: PathBuf = dir.join(format!(
        ".{}.{}.tmp.{}",
        file.to_string_lossy(),
        std::process::id(),
        path.extension().and_then(|e| e.to_str()).unwrap_or("tmp")
    ));
    let result = write(&tmp).and_then(|_| std::fs::rename(&tmp, path).map_err(|e| err(path, e)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Linear RGBA as 32-bit float EXR.
pub fn write_exr(path: &Path, img: &ImageRgba32) -> Result<()> {
    write_atomically(path, |tmp| {
        exr::prelude::write_rgba_file(tmp, img.width as usize, img.height as usize, |x, y| {
            let p = img.rgba[y * img.width as usize + x];
            (p[0], p[1], p[2], p[3])
        })
        .map_err(|e| err(path, e))
    })
}

/// 8-bit RGBA PNG from values already display-encoded in [0, 1].
pub fn write_png(path: &Path, img: &ImageRgba32) -> Result<()> {
    let bytes: Vec<u8> = img
        .rgba
        .iter()
        .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect();
    write_atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &bytes,
            img.width,
            img.height,
            image::ColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|e| err(path, e))
    })
}

/// Writes a `--dump` image: EXR for everything (it keeps negative and HDR values).
pub fn write_dump(dir: &Path, img: &ImageRgba32) -> Result<PathBuf> {
    let path = dir.join(format!("{}.exr", img.name));
    write_exr(&path, img)?;
    Ok(path)
}

/// The first RGBA layer of an OpenEXR file as RGB floats, row by row (alpha dropped):
/// (width, height, pixels).
pub fn read_exr_rgb(path: &Path) -> Result<(u32, u32, Vec<[f32; 3]>)> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| {
            (
                size.width(),
                vec![[0.0f32; 3]; size.width() * size.height()],
            )
        },
        |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .map_err(|e| RenderError::Input {
        path: path.display().to_string(),
        message: format!("not a readable OpenEXR image: {e}"),
    })?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, pixels))
}
