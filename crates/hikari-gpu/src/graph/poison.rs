//! NaN and infinity on purpose: the debug switch that proves a temporal pass survives them.
//! Before a chosen pass runs, one texture it reads (an input of the frame or a history) is
//! overwritten with NaN, +Inf and -Inf in turn, texel by texel; the frame must stay finite and
//! recover. The graph also lists what each pass reads ([`PassReads`]), so a test or
//! `hikari bench soak --poison` can walk every temporal pass's inputs.

use super::{Binding, TexSource, VirtualTexture};
use crate::context::GpuContext;
use crate::pipeline::{BindingKind, PipelineInfo};

/// Which texture to overwrite, read by which pass, in the next frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Poison {
    pub pass: String,
    /// The texture's graph name as the pass sees it (a history is `name.prev`).
    pub texture: String,
}

/// The textures one pass reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PassReads {
    pub pass: String,
    pub textures: Vec<ReadTexture>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadTexture {
    pub name: String,
    /// Last frame's result of a history (`name.prev`).
    pub history: bool,
    /// Kept from frame to frame and rebuilt only when what it caches changes (the sky's
    /// tables, cached shadow cascades): not a history, and not what a pass blends over time.
    pub cached: bool,
    /// Of a float format a copy can overwrite, so that [`Poison`] can reach it.
    pub poisonable: bool,
}

impl PassReads {
    /// Whether the pass blends over frames (reads a history): the passes the poison sweep
    /// visits.
    pub fn is_temporal(&self) -> bool {
        self.textures.iter().any(|t| t.history)
    }
}

/// The element bytes of a float format, or `None` for one that cannot hold NaN.
fn float_element(format: wgpu::TextureFormat) -> Option<(u32, u32)> {
    use wgpu::TextureFormat as F;
    // (bytes a component, components)
    match format {
        F::R16Float => Some((2, 1)),
        F::Rg16Float => Some((2, 2)),
        F::Rgba16Float => Some((2, 4)),
        F::R32Float => Some((4, 1)),
        F::Rg32Float => Some((4, 2)),
        F::Rgba32Float => Some((4, 4)),
        _ => None,
    }
}

/// What pass `pipeline` reads among `bindings`: sampled textures and storage textures it
/// may read.
pub(crate) fn reads_of(
    pass: &str,
    info: &PipelineInfo,
    bindings: &[Binding],
    set_bindings: &[Vec<Binding>],
    textures: &[VirtualTexture],
) -> PassReads {
    let mut out = Vec::new();
    for (slot, b) in super::bound_slots(info, bindings, set_bindings) {
        let Binding::Texture(t, _) = b else { continue };
        let reads = match slot.kind {
            BindingKind::SampledTexture { .. } => true,
            BindingKind::StorageTexture { access, .. } => {
                access != wgpu::StorageTextureAccess::WriteOnly
            }
            _ => false,
        };
        let v = &textures[t.0 as usize];
        if !reads || out.iter().any(|r: &ReadTexture| r.name == v.name) {
            continue;
        }
        out.push(ReadTexture {
            name: v.name.clone(),
            history: matches!(v.source, TexSource::HistoryPrev),
            cached: matches!(v.source, TexSource::Persistent),
            poisonable: float_element(v.desc.format).is_some()
                && !matches!(v.source, TexSource::Imported),
        });
    }
    PassReads {
        pass: pass.to_string(),
        textures: out,
    }
}

/// Overwrites mip 0 of `v` (every layer) with NaN, +Inf and -Inf in turn. Returns whether
/// it could.
pub(crate) fn poison(
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    v: &VirtualTexture,
) -> bool {
    use wgpu::util::DeviceExt;
    let (Some((bytes, components)), Some(p)) = (float_element(v.desc.format), v.physical.as_ref())
    else {
        return false;
    };
    if matches!(v.source, TexSource::Imported) {
        return false;
    }
    let [w, h, layers] = v.desc.size;
    let row = (w * bytes * components).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let words = (row * h * layers / bytes) as usize;
    let data: Vec<u8> = if bytes == 2 {
        // f16: NaN, +Inf, -Inf.
        (0..words)
            .flat_map(|i| [0x7e00u16, 0x7c00, 0xfc00][i % 3].to_le_bytes())
            .collect()
    } else {
        (0..words)
            .flat_map(|i| [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][i % 3].to_le_bytes())
            .collect()
    };
    let src = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("graph.poison"),
            contents: &data,
            usage: wgpu::BufferUsages::COPY_SRC,
        });
    encoder.copy_buffer_to_texture(
        wgpu::TexelCopyBufferInfo {
            buffer: &src,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::TexelCopyTextureInfo {
            texture: &p.texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        },
    );
    true
}
