//! Test hooks of the G-buffer: texels overwritten after the G-buffer pass in every frame
//! ([`crate::Renderer::override_gbuffer_texels`]), so that tests can put bad values (NaN,
//! infinity) where the frame's later passes read them. Kept out of `frame.rs`, whose walk
//! calls [`override_gbuffer`] once.

use crate::error::Result;
use crate::graph::FrameGraph;
use crate::techniques::gbuffer::GBuffer;

/// Which G-buffer texture a [`GBufferTexel`] overwrites.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GBufferTarget {
    /// `gbuffer.depth` (R32Float, reverse-Z).
    Depth,
    /// `gbuffer.normal` (Rgba16Float, octahedral).
    Normal,
    /// `gbuffer.albedo` (Rgba8Unorm: it cannot hold NaN or infinity).
    Albedo,
    /// `gbuffer.motion` (Rgba16Float).
    Motion,
    /// `gbuffer.emissive` (Rgba16Float, nits).
    Emissive,
}

/// A rectangle of G-buffer texels to overwrite with one value, so that tests can put bad
/// values (NaN, infinity) where the frame's later passes read them.
#[derive(Clone, Debug, PartialEq)]
pub struct GBufferTexel {
    pub target: GBufferTarget,
    /// The rectangle's top-left texel.
    pub pixel: [u32; 2],
    /// The rectangle's width and height in texels ([1, 1]: one texel).
    pub size: [u32; 2],
    /// One texel's bytes in the target's format (4 for depth and albedo, 8 for the others),
    /// written to every texel of the rectangle.
    pub bytes: Vec<u8>,
}

/// Records the copies of `texels` into the G-buffer; a rectangle outside the image or a texel
/// of the wrong size is an error naming it.
pub(crate) fn override_gbuffer<'r>(
    g: &mut FrameGraph<'r>,
    gbuffer: &GBuffer,
    size: [u32; 2],
    texels: &[GBufferTexel],
) -> Result<()> {
    use crate::techniques::gbuffer as gb;
    use wgpu::util::DeviceExt;
    for (i, t) in texels.iter().enumerate() {
        let (tex, format) = match t.target {
            GBufferTarget::Depth => (gbuffer.depth, gb::DEPTH_FORMAT),
            GBufferTarget::Normal => (gbuffer.normal, gb::NORMAL_FORMAT),
            GBufferTarget::Albedo => (gbuffer.albedo, gb::ALBEDO_FORMAT),
            GBufferTarget::Motion => (gbuffer.motion, gb::MOTION_FORMAT),
            GBufferTarget::Emissive => (gbuffer.emissive, gb::EMISSIVE_FORMAT),
        };
        let texel_bytes = format.block_copy_size(None).unwrap_or(0) as usize;
        let inside = |k: usize| {
            t.size[k] > 0
                && t.pixel[k]
                    .checked_add(t.size[k])
                    .is_some_and(|e| e <= size[k])
        };
        if t.bytes.len() != texel_bytes || !inside(0) || !inside(1) {
            return Err(crate::error::RenderError::Graph(format!(
                "G-buffer override {i} ({:?}, {:?} at {:?}): {} bytes for a {texel_bytes}-byte \
                 texel of a {}x{} image",
                t.target,
                t.size,
                t.pixel,
                t.bytes.len(),
                size[0],
                size[1]
            )));
        }
        // Rows padded to the copy's alignment.
        let row = (texel_bytes * t.size[0] as usize)
            .next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize);
        let mut contents = vec![0u8; row * t.size[1] as usize];
        for r in contents.chunks_exact_mut(row) {
            for c in r.chunks_exact_mut(texel_bytes).take(t.size[0] as usize) {
                c.copy_from_slice(&t.bytes);
            }
        }
        let data = g
            .ctx()
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("gbuffer.override"),
                contents: &contents,
                usage: wgpu::BufferUsages::COPY_SRC,
            });
        let origin = wgpu::Origin3d {
            x: t.pixel[0],
            y: t.pixel[1],
            z: 0,
        };
        let extent = wgpu::Extent3d {
            width: t.size[0],
            height: t.size[1],
            depth_or_array_layers: 1,
        };
        g.pass("gbuffer.override")
            .uses(tex, true)
            .encode(move |enc, res| {
                enc.copy_buffer_to_texture(
                    wgpu::TexelCopyBufferInfo {
                        buffer: &data,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(row as u32),
                            rows_per_image: None,
                        },
                    },
                    wgpu::TexelCopyTextureInfo {
                        texture: res.texture(tex),
                        mip_level: 0,
                        origin,
                        aspect: wgpu::TextureAspect::All,
                    },
                    extent,
                );
            })?;
    }
    Ok(())
}
