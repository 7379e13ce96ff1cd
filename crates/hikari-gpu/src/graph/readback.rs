//! Copies of textures and buffers back to the CPU: frame outputs and `--dump` requests.

use half::f16;

use super::resources::TextureDesc;
use crate::error::{RenderError, Result};

/// A texture read back to the CPU as linear RGBA f32. 3D textures and arrays are stacked
/// vertically: slice `z` occupies rows `z * height .. (z + 1) * height`.
#[derive(Clone, Debug)]
pub struct ImageRgba32 {
    pub name: String,
    /// The texture of its frame it was read from.
    pub texture: Option<super::Tex>,
    pub width: u32,
    pub height: u32,
    pub format: wgpu::TextureFormat,
    pub rgba: Vec<[f32; 4]>,
}

impl ImageRgba32 {
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.rgba[(y * self.width + x) as usize]
    }
}

/// Bytes of one texel of formats that can be read back, or `None`.
pub(crate) fn texel_bytes(format: wgpu::TextureFormat) -> Option<u32> {
    use wgpu::TextureFormat as F;
    Some(match format {
        F::R8Unorm | F::R8Uint => 1,
        F::Rg8Unorm | F::R16Float | F::R16Uint => 2,
        F::Rgba8Unorm
        | F::Rgba8UnormSrgb
        | F::Rgba8Snorm
        | F::Bgra8Unorm
        | F::Bgra8UnormSrgb
        | F::R32Float
        | F::R32Uint
        | F::Rg16Float
        | F::Rg16Snorm
        | F::Rg16Unorm
        | F::Rgb10a2Unorm
        | F::Rg11b10Ufloat
        | F::Depth32Float => 4,
        F::Rgba16Float | F::Rg32Float | F::Rg32Uint => 8,
        F::Rgba32Float | F::Rgba32Uint => 16,
        _ => return None,
    })
}

pub(crate) fn padded_row_bytes(desc: &TextureDesc) -> Option<u32> {
    let row = texel_bytes(desc.format)? * desc.size[0];
    Some(row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

fn unorm8(v: u8) -> f32 {
    v as f32 / 255.0
}

fn f11(bits: u32) -> f32 {
    // 6-bit mantissa, 5-bit exponent, bias 15, no sign.
    let (e, m) = ((bits >> 6) & 0x1f, bits & 0x3f);
    match e {
        0 => (m as f32 / 64.0) * 2f32.powi(-14),
        31 => {
            if m == 0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        _ => (1.0 + m as f32 / 64.0) * 2f32.powi(e as i32 - 15),
    }
}

fn f10(bits: u32) -> f32 {
    let (e, m) = ((bits >> 5) & 0x1f, bits & 0x1f);
    match e {
        0 => (m as f32 / 32.0) * 2f32.powi(-14),
        31 => {
            if m == 0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        _ => (1.0 + m as f32 / 32.0) * 2f32.powi(e as i32 - 15),
    }
}

/// Decodes one texel to RGBA f32 (missing channels: 0, alpha 1).
fn decode(format: wgpu::TextureFormat, t: &[u8]) -> [f32; 4] {
    use wgpu::TextureFormat as F;
    let u32_at = |i: usize| u32::from_le_bytes([t[i], t[i + 1], t[i + 2], t[i + 3]]);
    let f32_at = |i: usize| f32::from_bits(u32_at(i));
    let h = |i: usize| f16::from_bits(u16::from_le_bytes([t[i], t[i + 1]])).to_f32();
    let u16_at = |i: usize| u16::from_le_bytes([t[i], t[i + 1]]);
    match format {
        F::R8Unorm => [unorm8(t[0]), 0.0, 0.0, 1.0],
        F::R8Uint => [t[0] as f32, 0.0, 0.0, 1.0],
        F::Rg8Unorm => [unorm8(t[0]), unorm8(t[1]), 0.0, 1.0],
        F::Rgba8Unorm | F::Rgba8UnormSrgb => {
            [unorm8(t[0]), unorm8(t[1]), unorm8(t[2]), unorm8(t[3])]
        }
        F::Bgra8Unorm | F::Bgra8UnormSrgb => {
            [unorm8(t[2]), unorm8(t[1]), unorm8(t[0]), unorm8(t[3])]
        }
        F::Rgba8Snorm => {
            let s = |i: usize| (t[i] as i8 as f32 / 127.0).max(-1.0);
            [s(0), s(1), s(2), s(3)]
        }
        F::R16Float => [h(0), 0.0, 0.0, 1.0],
        F::R16Uint => [u16_at(0) as f32, 0.0, 0.0, 1.0],
        F::Rg16Float => [h(0), h(2), 0.0, 1.0],
        F::Rg16Unorm => [
            u16_at(0) as f32 / 65535.0,
            u16_at(2) as f32 / 65535.0,
            0.0,
            1.0,
        ],
        F::Rg16Snorm => {
            let s = |i| (i16::from_le_bytes([t[i], t[i + 1]]) as f32 / 32767.0).max(-1.0);
            [s(0), s(2), 0.0, 1.0]
        }
        F::Rgba16Float => [h(0), h(2), h(4), h(6)],
        F::R32Float | F::Depth32Float => [f32_at(0), 0.0, 0.0, 1.0],
        F::R32Uint => [u32_at(0) as f32, 0.0, 0.0, 1.0],
        F::Rg32Float => [f32_at(0), f32_at(4), 0.0, 1.0],
        F::Rg32Uint => [u32_at(0) as f32, u32_at(4) as f32, 0.0, 1.0],
        F::Rgba32Float => [f32_at(0), f32_at(4), f32_at(8), f32_at(12)],
        F::Rgba32Uint => [
            u32_at(0) as f32,
            u32_at(4) as f32,
            u32_at(8) as f32,
            u32_at(12) as f32,
        ],
        F::Rgb10a2Unorm => {
            let v = u32_at(0);
            [
                (v & 0x3ff) as f32 / 1023.0,
                ((v >> 10) & 0x3ff) as f32 / 1023.0,
                ((v >> 20) & 0x3ff) as f32 / 1023.0,
                (v >> 30) as f32 / 3.0,
            ]
        }
        F::Rg11b10Ufloat => {
            let v = u32_at(0);
            [f11(v & 0x7ff), f11((v >> 11) & 0x7ff), f10(v >> 22), 1.0]
        }
        _ => unreachable!("texel_bytes filters formats"),
    }
}

/// Turns the padded rows of a texture copy into an image.
pub(crate) fn decode_image(name: &str, desc: &TextureDesc, data: &[u8]) -> Result<ImageRgba32> {
    let tb = texel_bytes(desc.format).ok_or_else(|| {
        RenderError::Graph(format!(
            "cannot read back `{name}`: format {:?}",
            desc.format
        ))
    })? as usize;
    let row = padded_row_bytes(desc).unwrap() as usize;
    let [w, h, d] = desc.size;
    let mut rgba = Vec::with_capacity((w * h * d) as usize);
    for y in 0..(h * d) as usize {
        let r = &data[y * row..];
        for x in 0..w as usize {
            rgba.push(decode(desc.format, &r[x * tb..(x + 1) * tb]));
        }
    }
    Ok(ImageRgba32 {
        name: name.into(),
        texture: None,
        width: w,
        height: h * d,
        format: desc.format,
        rgba,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_floats_decode_to_their_ieee_like_values() {
        // 1.0 in the 11-bit float: exponent 15, mantissa 0.
        assert_eq!(f11(15 << 6), 1.0);
        assert_eq!(f10(15 << 5), 1.0);
        // Largest finite 11-bit value is 65024 (OpenGL spec, section 2.3.4.3).
        assert_eq!(f11((30 << 6) | 63), 65024.0);
        assert_eq!(f10((30 << 5) | 31), 64512.0);
        assert!(f11(31 << 6).is_infinite());
    }
}
