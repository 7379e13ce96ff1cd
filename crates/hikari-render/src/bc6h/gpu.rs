//! BC6H on the GPU: `encode.wgsl`, a thread a block, for every layer of a texture's first mip.

use bytemuck::{Pod, Zeroable};

use super::reference::{BLOCK_BYTES, Quality};
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, GraphRuntime, Tex};
use crate::pipeline::ComputePipeline;
use crate::{GpuContext, shader};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Bc6hParams {
    pub blocks_x: u32,
    pub blocks_y: u32,
    pub layer: u32,
    pub quality: u32,
    pub width: u32,
    pub height: u32,
    pub first_block: u32,
    pub level: u32,
    pub row_stride: u32,
    pub layer_stride: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// Where [`Bc6hEncoder::record`] puts the blocks: from `first_block`, rows `row_stride`
/// blocks apart, layers `layer_stride` blocks apart.
#[derive(Clone, Copy, Debug)]
pub struct BlockLayout {
    pub first_block: u32,
    pub row_stride: u32,
    pub layer_stride: u32,
}

impl BlockLayout {
    /// Rows and layers packed tight, for a `size` texel image.
    pub fn tight(size: [u32; 2]) -> Self {
        let (bx, by) = (size[0].div_ceil(4), size[1].div_ceil(4));
        Self {
            first_block: 0,
            row_stride: bx,
            layer_stride: bx * by,
        }
    }

    /// Rows padded to whole 256-byte copy rows, as `copy_buffer_to_texture` wants them.
    pub fn for_copy(size: [u32; 2]) -> Self {
        let (bx, by) = (size[0].div_ceil(4), size[1].div_ceil(4));
        let per_row = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT / BLOCK_BYTES as u32;
        let row_stride = bx.next_multiple_of(per_row);
        Self {
            first_block: 0,
            row_stride,
            layer_stride: row_stride * by,
        }
    }
}

/// The compiled encoder.
pub struct Bc6hEncoder {
    pipeline: ComputePipeline,
}

impl Bc6hEncoder {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let mut lib = shader::library(shader::capabilities_for(ctx.features))?;
        Self::with_library(ctx, &mut lib)
    }

    /// The encoder compiled from a library the caller already has (the frame's).
    pub fn with_library(ctx: &GpuContext, lib: &mut shader::ShaderLibrary) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(ctx, lib, "bc6h/encode.wgsl", "main", &[])?,
        })
    }

    /// Every layer of mip 0 of `texture` (a float format the shader can load) as BC6H_UF16
    /// blocks, layer after layer, each row by row.
    pub fn encode_texture(
        &self,
        ctx: &GpuContext,
        texture: &wgpu::Texture,
        quality: Quality,
    ) -> Result<Vec<u8>> {
        let (w, h, layers) = (
            texture.width(),
            texture.height(),
            texture.depth_or_array_layers(),
        );
        let (bx, by) = (w.div_ceil(4), h.div_ceil(4));
        let per_layer = u64::from(bx) * u64::from(by);
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(ctx);
        let source = g.import_texture("bc6h.source", texture);
        let blocks = g.buffer(
            "bc6h.blocks",
            per_layer * u64::from(layers) * BLOCK_BYTES as u64,
        )?;
        self.record(
            &mut g,
            "bc6h.encode",
            source,
            blocks,
            [w, h],
            (0, layers, 0),
            BlockLayout::tight([w, h]),
            quality,
        )?;
        g.readback(blocks);
        let result = g.execute()?;
        ctx.faults.check("BC6H encoding")?;
        result
            .buffer("bc6h.blocks")
            .map(<[u8]>::to_vec)
            .ok_or_else(|| RenderError::Graph("bc6h.blocks was not read back".into()))
    }

    /// Records pass `name`: layers `layer..layer + layers` of mip `level` (`size` texels) of
    /// `source` encoded into `blocks`, laid out as `out` says.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        name: &str,
        source: Tex,
        blocks: Buf,
        size: [u32; 2],
        (layer, layers, level): (u32, u32, u32),
        out: BlockLayout,
        quality: Quality,
    ) -> Result<()> {
        let (bx, by) = (size[0].div_ceil(4), size[1].div_ceil(4));
        g.pass(name)
            .constants(&Bc6hParams {
                blocks_x: bx,
                blocks_y: by,
                layer,
                quality: u32::from(quality == Quality::High),
                width: size[0],
                height: size[1],
                first_block: out.first_block,
                level,
                row_stride: out.row_stride,
                layer_stride: out.layer_stride,
                _pad0: 0,
                _pad1: 0,
            })
            .read(source)
            .write(blocks)
            .dispatch_threads(&self.pipeline, [bx, by, layers])
    }

    /// An RGB image as BC6H_UF16 blocks. The texels go to the GPU as halves (what BC6H holds),
    /// so the CPU twin given the same halves encodes the same blocks.
    pub fn encode_rgb(
        &self,
        ctx: &GpuContext,
        rgb: &[[f32; 3]],
        width: u32,
        height: u32,
        quality: Quality,
    ) -> Result<Vec<u8>> {
        let limit = ctx.limits.max_texture_dimension_2d;
        for (what, v) in [("width", width), ("height", height)] {
            if v == 0 || v > limit {
                return Err(RenderError::Limit {
                    what: format!("image {what} to encode"),
                    requested: u64::from(v),
                    limit: u64::from(limit),
                });
            }
        }
        let texels: Vec<half::f16> = rgb
            .iter()
            .flat_map(|p| [p[0], p[1], p[2], 1.0].map(half::f16::from_f32))
            .collect();
        use wgpu::util::DeviceExt;
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("bc6h.source"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&texels),
        );
        self.encode_texture(ctx, &texture, quality)
    }
}
