//! The denoisers of the ray-traced GI and AO (Metro Exodus, GDC 2019): two spatial passes over
//! the temporally accumulated GI (luminance L1 SH + CoCg, denoised together), the first
//! without a normal weight and a 6 m base radius, the second with the normal weight and 3 m,
//! and the AO denoiser (adaptive sampling, two pixels a thread). How and why:
//! docs/ray-traced-gi.md. CPU twin: [`reference`].
//!
//! Dumps: `gi_denoiser.pass1_y`, `gi_denoiser.pass1_cocg` (after the first pass),
//! `gi_denoiser.pass2_y`, `gi_denoiser.pass2_cocg` (after the second), `gi_denoiser.ao`. A pass
//! that is switched off writes nothing: its input goes on, and its dump names do not exist.

pub mod params;
pub mod reference;
pub mod settings;

use glam::Vec2;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::techniques::gbuffer::GBuffer;
use crate::view::View;

pub use params::{GiDenoiserParams, GiPass};
pub use settings::GiDenoiserSettings;

pub const GI_Y_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const GI_COCG_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;
pub const AO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// The accumulated GI signal the denoiser reads: the shape of `ray_traced_gi::RtGiFrame`
/// (all full resolution), kept local so that this technique does not depend on the tracer.
#[derive(Clone, Copy, Debug)]
pub struct GiDenoiserInput {
    /// Rgba16Float: luminance as L1 SH (c0, y, z, x), normalised as `ShL1YCoCg`.
    pub gi_y: Tex,
    /// Rg16Float: mean (Co, Cg).
    pub gi_cocg: Tex,
    /// R16Float: frames in this pixel's history (1 = fresh).
    pub history_length: Tex,
    /// R16Float: ambient occlusion in [0, 1] (1 = open), accumulated like the GI.
    pub ao: Tex,
    /// R16Float: this frame's hit distance in metres (0 = no hit). The AO denoiser caps its
    /// radius with it (`ao_hit_distance_scale`).
    pub hit_distance: Tex,
}

/// The G-buffer textures the denoiser reads.
#[derive(Clone, Copy, Debug)]
pub struct GiDenoiserGeometry {
    /// R32Float reverse-Z depth, 0 for the sky.
    pub depth: Tex,
    /// Rgba16Float, xy: octahedral world-space normal.
    pub normal: Tex,
}

impl From<&GBuffer> for GiDenoiserGeometry {
    fn from(gb: &GBuffer) -> Self {
        Self {
            depth: gb.depth,
            normal: gb.normal,
        }
    }
}

/// The denoised GI, in the input's encoding and formats.
#[derive(Clone, Copy, Debug)]
pub struct DenoisedGi {
    pub gi_y: Tex,
    pub gi_cocg: Tex,
    pub ao: Tex,
}

pub struct GiDenoiser {
    spatial: ComputePipeline,
    ao: ComputePipeline,
    gi_disk: Vec<Vec2>,
    ao_disk: Vec<Vec2>,
}

impl GiDenoiser {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        // The outputs keep the tracer's formats; wgpu stores to r16float and rg16float only
        // with this feature (Vulkan, Metal and DX12 adapters grant it).
        if !ctx.has(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES) {
            return Err(RenderError::Device(
                "gi_denoiser writes r16float and rg16float storage textures, which need the \
                 adapter-specific format feature this adapter does not grant"
                    .into(),
            ));
        }
        Ok(Self {
            spatial: ComputePipeline::new(ctx, lib, "gi_denoiser/spatial.wgsl", "main", &[])?,
            ao: ComputePipeline::new(ctx, lib, "gi_denoiser/ao.wgsl", "main", &[])?,
            gi_disk: params::poisson_points(params::GI_DISK_POINTS, 0x6d65_7472_6f31)?,
            ao_disk: params::poisson_points(params::MAX_DISK_POINTS, 0x6d65_7472_6f32)?,
        })
    }

    /// The constants of the first GI pass, the second, and the AO denoiser for `frame_index`
    /// (what [`GiDenoiser::record`] uses; the tests hand them to the CPU twin).
    pub fn pass_params(
        &self,
        settings: &GiDenoiserSettings,
        view: &View,
        frame_index: u64,
    ) -> [GiDenoiserParams; 3] {
        [
            GiDenoiserParams::gi_pass(settings, view, frame_index, GiPass::First, &self.gi_disk),
            GiDenoiserParams::gi_pass(settings, view, frame_index, GiPass::Second, &self.gi_disk),
            GiDenoiserParams::ao(settings, view, frame_index, &self.ao_disk),
        ]
    }

    /// Adds the enabled passes to the frame (step 10, after the temporal accumulation).
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        settings: &GiDenoiserSettings,
        view: &View,
        geometry: GiDenoiserGeometry,
        input: &GiDenoiserInput,
        [width, height]: [u32; 2],
    ) -> Result<DenoisedGi> {
        let [p1, p2, pao] = self.pass_params(settings, view, g.frame_index());
        let mut y = input.gi_y;
        let mut cocg = input.gi_cocg;
        let passes = [
            (
                settings.pass1,
                p1,
                "gi_denoiser.pass1",
                "pass1_y",
                "pass1_cocg",
            ),
            (
                settings.pass2,
                p2,
                "gi_denoiser.pass2",
                "pass2_y",
                "pass2_cocg",
            ),
        ];
        for (enabled, p, label, y_name, cocg_name) in passes {
            if !enabled {
                continue;
            }
            let out_y = g.texture(
                &format!("gi_denoiser.{y_name}"),
                TextureDesc::d2(width, height, GI_Y_FORMAT),
            )?;
            let out_cocg = g.texture(
                &format!("gi_denoiser.{cocg_name}"),
                TextureDesc::d2(width, height, GI_COCG_FORMAT),
            )?;
            g.pass(label)
                .constants(&p)
                .constants(view)
                .read(geometry.depth)
                .read(geometry.normal)
                .read(y)
                .read(cocg)
                .read(input.history_length)
                .read(input.ao)
                .write(out_y)
                .write(out_cocg)
                .dispatch_threads(&self.spatial, [width, height, 1])?;
            y = out_y;
            cocg = out_cocg;
        }
        let mut ao = input.ao;
        if settings.ao {
            let out_ao = g.texture("gi_denoiser.ao", TextureDesc::d2(width, height, AO_FORMAT))?;
            g.pass("gi_denoiser.ao")
                .constants(&pao)
                .constants(view)
                .read(geometry.depth)
                .read(geometry.normal)
                .read(input.ao)
                .read(input.history_length)
                .read(input.hit_distance)
                .write(out_ao)
                .dispatch_threads(&self.ao, [width.div_ceil(2), height, 1])?;
            ao = out_ao;
        }
        Ok(DenoisedGi {
            gi_y: y,
            gi_cocg: cocg,
            ao,
        })
    }
}
