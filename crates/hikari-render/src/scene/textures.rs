//! Scene textures as two mipmapped 2D arrays, so a compute shader can reach any of them
//! without bindless resources: base colour and emissive images in an sRGB array (the sampler
//! decodes before filtering), metallic-roughness, normal and occlusion images in a linear one.
//! Every layer of an array has one size: the largest image's, rounded up to a power of two and
//! capped at [`MAX_LAYER_SIZE`]; smaller or non-square images are resampled to it (UVs are
//! normalised, so only the texel density changes).

use hikari_scene::Scene;
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};

pub const MAX_LAYER_SIZE: u32 = 1024;

/// Where each scene texture went: its layer in the sRGB array and in the linear array.
#[derive(Clone, Debug, Default)]
pub struct LayerMap {
    pub color: Vec<Option<u32>>,
    pub data: Vec<Option<u32>>,
}

impl LayerMap {
    /// Which array each texture is used from, by the material slots that reference it.
    pub fn for_scene(scene: &Scene) -> Self {
        let n = scene.textures.len();
        let (mut color_used, mut data_used) = (vec![false; n], vec![false; n]);
        for m in &scene.materials {
            for t in [m.base_color_texture, m.emissive_texture]
                .into_iter()
                .flatten()
            {
                color_used[t.texture] = true;
            }
            for t in [
                m.metallic_roughness_texture,
                m.normal_texture,
                m.occlusion_texture,
            ]
            .into_iter()
            .flatten()
            {
                data_used[t.texture] = true;
            }
        }
        let number = |used: Vec<bool>| {
            let mut next = 0;
            used.into_iter()
                .map(|u| {
                    u.then(|| {
                        next += 1;
                        next - 1
                    })
                })
                .collect()
        };
        Self {
            color: number(color_used),
            data: number(data_used),
        }
    }
}

pub struct TextureArrays {
    /// `Rgba8UnormSrgb`, at least one (white) layer.
    pub color: wgpu::Texture,
    /// `Rgba8Unorm`, at least one layer.
    pub data: wgpu::Texture,
}

/// Mip chain of a square RGBA8 image, each level averaged 2x2 from the one above, in linear
/// light for sRGB images.
fn mip_chain(base: image::RgbaImage, srgb: bool) -> Vec<image::RgbaImage> {
    let to_linear = |c: u8| {
        let c = c as f32 / 255.0;
        if !srgb {
            c
        } else if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let to_code = |l: f32| {
        let c = if !srgb {
            l
        } else if l <= 0.003_130_8 {
            l * 12.92
        } else {
            1.055 * l.powf(1.0 / 2.4) - 0.055
        };
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    let mut levels = vec![base];
    while levels.last().unwrap().width() > 1 {
        let src = levels.last().unwrap();
        let size = src.width() / 2;
        let next = image::RgbaImage::from_fn(size, size, |x, y| {
            let mut px = [0u8; 4];
            for (c, out) in px.iter_mut().enumerate() {
                let mut sum = 0.0;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let v = src.get_pixel(2 * x + dx, 2 * y + dy)[c];
                    // Alpha is coverage, always linear.
                    sum += if c == 3 {
                        v as f32 / 255.0
                    } else {
                        to_linear(v)
                    };
                }
                *out = if c == 3 {
                    (sum / 4.0 * 255.0).round() as u8
                } else {
                    to_code(sum / 4.0)
                };
            }
            image::Rgba(px)
        });
        levels.push(next);
    }
    levels
}

fn build_array(
    ctx: &GpuContext,
    scene: &Scene,
    layers: &[Option<u32>],
    srgb: bool,
    label: &str,
) -> Result<wgpu::Texture> {
    let used: Vec<usize> = {
        let mut v: Vec<(u32, usize)> = layers
            .iter()
            .enumerate()
            .filter_map(|(i, l)| l.map(|l| (l, i)))
            .collect();
        v.sort();
        v.into_iter().map(|(_, i)| i).collect()
    };
    let size = used
        .iter()
        .map(|&i| scene.textures[i].width.max(scene.textures[i].height))
        .max()
        .unwrap_or(1)
        .next_power_of_two()
        .min(MAX_LAYER_SIZE);
    let layer_count = used.len().max(1) as u32;
    let max_layers = ctx.limits.max_texture_array_layers;
    if layer_count > max_layers {
        return Err(RenderError::Limit {
            what: format!("{label} texture array layers"),
            requested: layer_count as u64,
            limit: max_layers as u64,
        });
    }
    let mips = size.ilog2() + 1;
    // Layer-major, as `create_texture_with_data` wants: every mip of layer 0, then layer 1...
    let mut bytes = Vec::new();
    if used.is_empty() {
        bytes.extend_from_slice(&[255u8; 4]);
    }
    for &i in &used {
        let t = &scene.textures[i];
        let img =
            image::RgbaImage::from_raw(t.width, t.height, t.data.clone()).ok_or_else(|| {
                RenderError::Graph(format!(
                    "texture `{}`: {} bytes for {}x{} RGBA8",
                    t.name,
                    t.data.len(),
                    t.width,
                    t.height
                ))
            })?;
        let base = if img.width() == size && img.height() == size {
            img
        } else {
            image::imageops::resize(&img, size, size, image::imageops::FilterType::Triangle)
        };
        for level in mip_chain(base, srgb) {
            bytes.extend_from_slice(level.as_raw());
        }
    }
    let format = if srgb {
        wgpu::TextureFormat::Rgba8UnormSrgb
    } else {
        wgpu::TextureFormat::Rgba8Unorm
    };
    Ok(ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layer_count,
            },
            mip_level_count: if used.is_empty() { 1 } else { mips },
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &bytes,
    ))
}

impl TextureArrays {
    pub fn upload(ctx: &GpuContext, scene: &Scene) -> Result<(Self, LayerMap)> {
        let map = LayerMap::for_scene(scene);
        Ok((
            Self {
                color: build_array(ctx, scene, &map.color, true, "scene sRGB textures")?,
                data: build_array(ctx, scene, &map.data, false, "scene linear textures")?,
            },
            map,
        ))
    }
}
