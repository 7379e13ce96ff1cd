//! What a window shows of a frame (the viewer's debug views): the final image, or any
//! texture of the frame by its graph name (`gbuffer.normal`, `ray_traced_gi.ao`, ... the
//! names `--dump` knows) through a display mapping that suits what it holds, written into a
//! display-encoded 8-bit target the caller owns. CPU twin: [`reference`].

pub mod reference;

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{FrameGraph, Tex};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

/// The target's format: display-encoded (sRGB) values in a plain 8-bit texture.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// How a texture's values become display values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// The values as they are, clamped to [0, 1] (the final display-encoded image).
    Raw,
    /// Radiance in nits, exposed for `ev100` and compressed (x / (1 + x)) to sRGB.
    Radiance { ev100: f32 },
    /// Octahedral unit vectors in the first two channels, shown as n / 2 + 1/2.
    Normal,
    /// Reverse-Z depth (1 near, 0 at infinity), its fourth root.
    Depth,
    /// One channel (0 to 3) from 0 to `white`, grey.
    Scalar { channel: u32, white: f32 },
    /// Log2 of the luminance on a blue-to-red ramp from 8 stops below the exposure's white
    /// to 4 above.
    Luminance { ev100: f32 },
}

impl Mapping {
    /// The mapping that suits the texture named `name` in a frame exposed at `ev100`.
    pub fn for_name(name: &str, ev100: f32) -> Mapping {
        let n = name.to_ascii_lowercase();
        let has = |s: &str| n.contains(s);
        if has("normal") {
            Mapping::Normal
        } else if has("depth") {
            Mapping::Depth
        } else if has("hit_distance") {
            Mapping::Scalar {
                channel: 0,
                white: 50.0,
            }
        } else if n.ends_with(".ao") || has("visibility") || has("shadow") {
            Mapping::Scalar {
                channel: 0,
                white: 1.0,
            }
        } else if has("illuminance") || has("luminance") {
            Mapping::Luminance { ev100 }
        } else if n == "tonemap.ldr" || has("albedo") || has("material") {
            Mapping::Raw
        } else {
            Mapping::Radiance { ev100 }
        }
    }

    fn code(&self) -> u32 {
        match self {
            Mapping::Raw => 0,
            Mapping::Radiance { .. } => 1,
            Mapping::Normal => 2,
            Mapping::Depth => 3,
            Mapping::Scalar { .. } => 4,
            Mapping::Luminance { .. } => 5,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DisplayParams {
    pub mode: [u32; 4],
    pub sizes: [u32; 4],
    pub values: [f32; 4],
}

impl DisplayParams {
    pub fn new(mapping: &Mapping, source: [u32; 2], target: [u32; 2]) -> Self {
        let (channel, values) = match *mapping {
            Mapping::Radiance { ev100 } => (0, [reference::exposure_scale(ev100), 0.0, 0.0, 0.0]),
            Mapping::Scalar { channel, white } => (channel, [0.0, white, 0.0, 0.0]),
            Mapping::Luminance { ev100 } => {
                let (lo, span) = reference::luminance_ramp(ev100);
                (0, [0.0, 0.0, lo, span])
            }
            _ => (0, [0.0; 4]),
        };
        Self {
            mode: [mapping.code(), channel, 0, 0],
            sizes: [source[0], source[1], target[0], target[1]],
            values,
        }
    }
}

pub struct DebugView {
    display: ComputePipeline,
}

impl DebugView {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            display: ComputePipeline::new(ctx, lib, "debug_view/display.wgsl", "main", &[])?,
        })
    }

    /// Writes `source` through `mapping` into `target` (an imported [`TARGET_FORMAT`] texture),
    /// scaled to its size by the nearest texel.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        source: Tex,
        mapping: &Mapping,
        target: Tex,
    ) -> Result<()> {
        let (src, dst) = (g.texture_desc(source), g.texture_desc(target));
        if dst.format != TARGET_FORMAT {
            return Err(RenderError::Graph(format!(
                "debug_view: the target is {:?}, not {TARGET_FORMAT:?}",
                dst.format
            )));
        }
        if src.dimension != wgpu::TextureDimension::D2 || src.size[2] != 1 {
            return Err(RenderError::Graph(format!(
                "debug_view: `{}` is not a single 2D image; only those can be shown",
                g.texture_name(source)
            )));
        }
        let sample = src.format.sample_type(None, None);
        if !matches!(sample, Some(wgpu::TextureSampleType::Float { .. })) {
            return Err(RenderError::Graph(format!(
                "debug_view: `{}` holds {:?}, which has no display mapping (float formats only)",
                g.texture_name(source),
                src.format
            )));
        }
        let params = DisplayParams::new(
            mapping,
            [src.size[0], src.size[1]],
            [dst.size[0], dst.size[1]],
        );
        g.pass("debug_view.display")
            .constants(&params)
            .read(source)
            .write(target)
            .dispatch_threads(&self.display, [dst.size[0], dst.size[1], 1])
    }
}
