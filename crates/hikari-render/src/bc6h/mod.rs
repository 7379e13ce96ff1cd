//! BC6H_UF16 compression of HDR images, as Ghost of Tsushima compresses its relit reflection
//! probes: Narkowicz's real-time method (the single-subset mode, endpoints from the block's
//! box), on the GPU (`gpu`, `encode.wgsl`) with its CPU twin (`reference`), the DDS file
//! `hikari bc6h` writes (`dds`) and the error against the input (`error`). docs/bc6h.md.

pub mod dds;
pub mod gpu;
pub mod reference;

pub use gpu::{Bc6hEncoder, BlockLayout};
pub use reference::Quality;

/// How far decoded texels are from the input, over the channels of every texel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bc6hError {
    /// Root mean square of log2(decoded + 1e-3) - log2(input + 1e-3): relative error where
    /// values are bright, absolute near black.
    pub rms_log2: f64,
    /// Mean of |decoded - input| / max(input, 1e-3).
    pub mean_relative: f64,
    /// The largest |decoded - input|.
    pub max_abs: f64,
}

/// The image `blocks` decode to (this encoder's blocks), RGB floats, row by row.
pub fn decode_image(blocks: &[u8], width: u32, height: u32) -> Option<Vec<[f32; 3]>> {
    let bx = width.div_ceil(4);
    let mut out = vec![[0.0f32; 3]; (width * height) as usize];
    for (k, chunk) in blocks.chunks_exact(reference::BLOCK_BYTES).enumerate() {
        let (cx, cy) = (k as u32 % bx, k as u32 / bx);
        if cy >= height.div_ceil(4) {
            break;
        }
        let texels = reference::decode(chunk.try_into().ok()?)?;
        for (t, h) in texels.iter().enumerate() {
            let (x, y) = (cx * 4 + t as u32 % 4, cy * 4 + t as u32 / 4);
            if x < width && y < height {
                out[(y * width + x) as usize] = h.map(|b| half::f16::from_bits(b as u16).to_f32());
            }
        }
    }
    Some(out)
}

/// The error of `decoded` against `input` (the input clamped to what BC6H_UF16 holds).
pub fn error(input: &[[f32; 3]], decoded: &[[f32; 3]]) -> Bc6hError {
    let (mut sq, mut rel, mut max, mut n) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for (a, b) in input.iter().zip(decoded) {
        for c in 0..3 {
            let x = f64::from(if a[c] > 0.0 { a[c].min(65504.0) } else { 0.0 });
            let y = f64::from(b[c]);
            let d = (y + 1e-3).log2() - (x + 1e-3).log2();
            sq += d * d;
            rel += (y - x).abs() / x.max(1e-3);
            max = max.max((y - x).abs());
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    Bc6hError {
        rms_log2: (sq / n).sqrt(),
        mean_relative: rel / n,
        max_abs: max,
    }
}
