//! The talk's grading workflow: a screenshot carries a 32x32x32 LUT strip, the artist grades
//! the whole PNG in any photo editor, and the grade is read back from the strip.
//!
//! Layout: a band appended below the image, as wide as the image, holding the 32³ lattice
//! twice. Each copy is 32 tiles of 32x32 pixels, one per blue slice, with red growing
//! rightwards and green downwards; copy 0 holds slice `b` in tile `b`, copy 1 in tile
//! `63 - b`, so each lattice point sits in two distant pixels. Tiles run left to right,
//! `width / 32` (at most 64) to a row, and wrap; the band is `32 · ceil(64 / tiles per row)`
//! pixels high (64 at 1280 wide); what the tiles leave uncovered is black. An image must be
//! at least 32 px wide.
//!
//! The strip holds the LUT the screenshot was graded with (identity if none), so the grade
//! read back is the old grade followed by the artist's. A photo editor applies the same
//! function to equal colours, so the two copies of a lattice point stay equal under any
//! grade; where they differ by more than [`COPY_TOLERANCE`] the strip was damaged (painting,
//! resizing, cropping), and where most differ there is no strip at all.

use std::path::Path;

use super::cube::CubeLut;
use crate::graph::ImageRgba32;

/// The strip's LUT size (the talk's 32x32x32).
pub const STRIP_SIZE: u32 = 32;
/// Largest difference, in 8-bit steps, between the two copies of a lattice point in a graded
/// strip (editors that dither may move a pixel by a step).
pub const COPY_TOLERANCE: u8 = 2;
/// Most pixels [`decode_png`] reads: an 8K screenshot (7680x4320) with its strip fits.
pub const MAX_PIXELS: u64 = 40_000_000;
const TILE: u32 = STRIP_SIZE;
const TILES: u32 = 2 * STRIP_SIZE;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StripError {
    #[error("{file}: {message}")]
    Image { file: String, message: String },
    #[error("{file}: no LUT strip: {message} (write one with `hikari render --lut-screenshot`)")]
    Missing { file: String, message: String },
    #[error("{file}: the LUT strip is damaged: {message}")]
    Damaged { file: String, message: String },
}

/// Where the band lies for an image `width` pixels wide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StripLayout {
    pub tiles_per_row: u32,
    /// Height of the band in pixels.
    pub height: u32,
}

impl StripLayout {
    pub fn for_width(width: u32) -> Option<Self> {
        let tiles_per_row = (width / TILE).min(TILES);
        (tiles_per_row > 0).then(|| Self {
            tiles_per_row,
            height: TILE * TILES.div_ceil(tiles_per_row),
        })
    }

    /// The pixel (within the band) of lattice point `(r, g, b)` in copy 0 or 1.
    pub fn pixel(&self, copy: u32, r: u32, g: u32, b: u32) -> (u32, u32) {
        let tile = if copy == 0 { b } else { TILES - 1 - b };
        let tx = tile % self.tiles_per_row;
        let ty = tile / self.tiles_per_row;
        (tx * TILE + r, ty * TILE + g)
    }
}

/// An 8-bit RGBA image as read from a PNG.
pub struct Rgba8Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[u8; 4]>,
}

/// Reads a PNG (any bit depth, converted to 8-bit RGBA).
pub fn read_png(path: &Path) -> Result<Rgba8Image, StripError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| StripError::Image {
        file: file.clone(),
        message: format!("cannot read: {e}"),
    })?;
    decode_png(&bytes, &file)
}

/// Decodes an image file's bytes (a PNG, or another format `image` recognises), converted to
/// 8-bit RGBA; `file` names it in errors.
pub fn decode_png(bytes: &[u8], file: &str) -> Result<Rgba8Image, StripError> {
    let err = |m: String| StripError::Image {
        file: file.into(),
        message: m,
    };
    check_png_palette(bytes).map_err(err)?;
    // The decoders are outside code: a panic in one (the fuzzing found one in `png`) is a
    // malformed file to the user, not a crash.
    std::panic::catch_unwind(|| decode_checked(bytes, err)).unwrap_or_else(|_| {
        Err(err(
            "the image decoder failed on this file (it is malformed)".to_string(),
        ))
    })
}

/// A PNG's palette chunks as the PNG specification allows them: one at most, of whole RGB
/// entries, 1 to 256 of them. `png` 0.18.1 panics on a palette of 4 bytes after another
/// (found by fuzzing `lut_strip_png`); other files, and what this walk cannot follow, are left
/// to the decoder.
fn check_png_palette(bytes: &[u8]) -> Result<(), String> {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    let Some(mut rest) = bytes.strip_prefix(SIGNATURE) else {
        return Ok(());
    };
    let mut palettes = 0;
    while rest.len() >= 12 {
        let len = u32::from_be_bytes(rest[0..4].try_into().unwrap()) as usize;
        let kind = &rest[4..8];
        if kind == b"PLTE" {
            palettes += 1;
            if palettes > 1 {
                return Err("malformed PNG: more than one PLTE (palette) chunk".into());
            }
            if !len.is_multiple_of(3) || !(3..=768).contains(&len) {
                return Err(format!(
                    "malformed PNG: its PLTE (palette) chunk has {len} bytes, not 1 to 256 \
                     RGB entries"
                ));
            }
        }
        if kind == b"IEND" || rest.len() < 12 + len {
            break;
        }
        rest = &rest[12 + len..];
    }
    Ok(())
}

fn decode_checked(
    bytes: &[u8],
    err: impl Fn(String) -> StripError,
) -> Result<Rgba8Image, StripError> {
    let decoder = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| err(format!("cannot read: {e}")))?
        .into_decoder()
        .map_err(|e| err(format!("not a readable image: {e}")))?;
    // The header's size is checked before anything is allocated: a few hundred bytes of PNG
    // may claim gigapixels, and the 8-bit RGBA copy is up to 4x the decoded image.
    let (w, h) = image::ImageDecoder::dimensions(&decoder);
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(err(format!(
            "the header gives {w}x{h} pixels; at most {MAX_PIXELS} are read"
        )));
    }
    let img = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| err(format!("not a readable image: {e}")))?
        .to_rgba8();
    let (width, height) = img.dimensions();
    let pixels = img.pixels().map(|p| p.0).collect();
    Ok(Rgba8Image {
        width,
        height,
        pixels,
    })
}

/// `img` (display values in [0, 1]) with the strip of `lut` appended below it.
pub fn embed(img: &ImageRgba32, lut: &CubeLut) -> Option<ImageRgba32> {
    let layout = StripLayout::for_width(img.width)?;
    let w = img.width as usize;
    let mut rgba = img.rgba.clone();
    rgba.resize(
        w * (img.height + layout.height) as usize,
        [0.0, 0.0, 0.0, 1.0],
    );
    let step = 1.0 / (STRIP_SIZE - 1) as f32;
    for b in 0..STRIP_SIZE {
        for g in 0..STRIP_SIZE {
            for r in 0..STRIP_SIZE {
                let c = lut.sample([r as f32 * step, g as f32 * step, b as f32 * step]);
                for copy in 0..2 {
                    let (x, y) = layout.pixel(copy, r, g, b);
                    rgba[(img.height + y) as usize * w + x as usize] = [c[0], c[1], c[2], 1.0];
                }
            }
        }
    }
    Some(ImageRgba32 {
        name: img.name.clone(),
        texture: None,
        width: img.width,
        height: img.height + layout.height,
        format: img.format,
        rgba,
    })
}

/// The 32³ LUT read back from the strip at the bottom of `img`; `file` names it in errors.
pub fn extract(img: &Rgba8Image, file: &str) -> Result<CubeLut, StripError> {
    let missing = |m: String| StripError::Missing {
        file: file.into(),
        message: m,
    };
    let layout = StripLayout::for_width(img.width).ok_or_else(|| {
        missing(format!(
            "the image is {} px wide; a strip needs at least {TILE}",
            img.width
        ))
    })?;
    if img.height <= layout.height {
        return Err(missing(format!(
            "the image is {} px high; a {} px wide one with a strip is taller than {}",
            img.height, img.width, layout.height
        )));
    }
    let top = img.height - layout.height;
    let w = img.width as usize;
    let mut data = Vec::with_capacity((STRIP_SIZE * STRIP_SIZE * STRIP_SIZE) as usize);
    let mut damaged = 0usize;
    let mut first_damage = None;
    for b in 0..STRIP_SIZE {
        for g in 0..STRIP_SIZE {
            for r in 0..STRIP_SIZE {
                let mut sum = [0u32; 3];
                let mut lo = [255u8; 3];
                let mut hi = [0u8; 3];
                for copy in 0..2 {
                    let (x, y) = layout.pixel(copy, r, g, b);
                    let p = img.pixels[(top + y) as usize * w + x as usize];
                    for k in 0..3 {
                        sum[k] += p[k] as u32;
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                if (0..3).any(|k| hi[k] - lo[k] > COPY_TOLERANCE) {
                    damaged += 1;
                    let (x, y) = layout.pixel(0, r, g, b);
                    first_damage.get_or_insert((x, top + y));
                }
                data.push(sum.map(|s| s as f32 / (2.0 * 255.0)));
            }
        }
    }
    if damaged * 2 > data.len() {
        return Err(missing(format!(
            "the two copies of the lattice in the bottom {} px disagree at {damaged} of {} points",
            layout.height,
            data.len()
        )));
    }
    if let Some((x, y)) = first_damage {
        return Err(StripError::Damaged {
            file: file.into(),
            message: format!(
                "the two copies of {damaged} of {} lattice points differ, the first at pixel \
                 ({x}, {y}); grade colours only, without resizing, cropping or painting over the \
                 band",
                data.len()
            ),
        });
    }
    let first = data[0];
    if data.iter().all(|c| c == &first) {
        return Err(missing(format!(
            "the bottom {} px are one colour",
            layout.height
        )));
    }
    let mut lut = CubeLut::identity(STRIP_SIZE as usize);
    lut.data = data;
    lut.title = Some(format!("read from {file}"));
    Ok(lut)
}

/// Applies `lut` to an 8-bit image (trilinear, as colour tools do), as display values.
pub fn apply(img: &Rgba8Image, lut: &CubeLut) -> ImageRgba32 {
    let rgba = img
        .pixels
        .iter()
        .map(|p| {
            let c = lut.sample([p[0], p[1], p[2]].map(|v| v as f32 / 255.0));
            [c[0], c[1], c[2], p[3] as f32 / 255.0]
        })
        .collect();
    ImageRgba32 {
        name: "graded".into(),
        texture: None,
        width: img.width,
        height: img.height,
        format: wgpu::TextureFormat::Rgba8Unorm,
        rgba,
    }
}

/// Quantises display values to 8 bits as `output::write_png` does.
pub fn to_rgba8(img: &ImageRgba32) -> Rgba8Image {
    Rgba8Image {
        width: img.width,
        height: img.height,
        pixels: img
            .rgba
            .iter()
            .map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32) -> ImageRgba32 {
        ImageRgba32 {
            name: "t".into(),
            texture: None,
            width: w,
            height: h,
            format: wgpu::TextureFormat::Rgba8Unorm,
            rgba: (0..w * h)
                .map(|i| {
                    let v = (i % 97) as f32 / 96.0;
                    [v, 1.0 - v, 0.5 * v, 1.0]
                })
                .collect(),
        }
    }

    /// A grade no one would confuse with the identity: a curve per channel and a channel mix.
    fn grade(c: [f32; 3]) -> [f32; 3] {
        [
            (0.8 * c[0] + 0.2 * c[1]).powf(0.8),
            c[1] * c[1],
            0.1 + 0.8 * c[2],
        ]
    }

    #[test]
    fn the_lut_read_back_from_a_graded_screenshot_is_the_grade() {
        for width in [32u32, 200, 2100] {
            let shot = embed(&image(width, 20), &CubeLut::identity(32)).unwrap();
            let mut px = to_rgba8(&shot);
            // The artist grades the whole 8-bit PNG.
            for p in px.pixels.iter_mut() {
                let c = grade([p[0], p[1], p[2]].map(|v| v as f32 / 255.0));
                for k in 0..3 {
                    p[k] = (c[k] * 255.0).round() as u8;
                }
            }
            let lut = extract(&px, "graded.png").unwrap();
            let step = 1.0 / 31.0;
            let mut worst = 0f32;
            for b in 0..32 {
                for g in 0..32 {
                    for r in 0..32 {
                        let want = grade([r as f32 * step, g as f32 * step, b as f32 * step]);
                        let got = lut.at(r, g, b);
                        for k in 0..3 {
                            worst = worst.max((got[k] - want[k]).abs());
                        }
                    }
                }
            }
            // The strip's 8-bit input is off by at most half a step, which the grade's slope
            // (at most 2, of x^2 at 1) doubles, plus half a step of the graded output:
            // 1.5 steps; the x^0.8 near 0 is steeper but its lattice points are exact there.
            assert!(worst <= 1.5 / 255.0 + 1e-5, "width {width}: {worst}");
        }
    }

    #[test]
    fn a_missing_or_damaged_strip_is_an_error() {
        let plain = to_rgba8(&image(200, 800));
        let e = extract(&plain, "plain.png").unwrap_err().to_string();
        assert!(e.contains("plain.png") && e.contains("no LUT strip"), "{e}");
        let narrow = to_rgba8(&image(20, 300));
        let e = extract(&narrow, "narrow.png").unwrap_err().to_string();
        assert!(
            e.contains("no LUT strip") && e.contains("20 px wide"),
            "{e}"
        );
        let black = Rgba8Image {
            width: 200,
            height: 800,
            pixels: vec![[0, 0, 0, 255]; 200 * 800],
        };
        let e = extract(&black, "black.png").unwrap_err().to_string();
        assert!(e.contains("one colour"), "{e}");
        let shot = embed(&image(200, 20), &CubeLut::identity(32)).unwrap();
        let mut px = to_rgba8(&shot);
        let i = (shot.height as usize - 10) * 200 + 33;
        px.pixels[i] = [255, 0, 255, 255];
        let e = extract(&px, "painted.png").unwrap_err().to_string();
        assert!(e.contains("damaged") && e.contains("1 of 32768"), "{e}");
        // A smooth gradient (which a test of neighbouring pixels would take for a strip).
        let gradient = Rgba8Image {
            width: 200,
            height: 800,
            pixels: (0..200 * 800)
                .map(|i| [(i % 200) as u8, (i / 200 % 256) as u8, 7, 255])
                .collect(),
        };
        let e = extract(&gradient, "gradient.png").unwrap_err().to_string();
        assert!(e.contains("no LUT strip"), "{e}");
    }
}
