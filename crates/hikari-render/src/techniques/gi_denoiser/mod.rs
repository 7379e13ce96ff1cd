//! The denoisers of the ray-traced GI and AO (Metro Exodus, GDC 2019): two spatial passes over
//! the temporally accumulated GI (luminance L1 SH + CoCg, denoised together), the first
//! without a normal weight and a 6 m base radius, the second with the normal weight and 3 m,
//! and the AO denoiser (adaptive sampling, two pixels a thread). How and why:
//! docs/ray-traced-gi.md. CPU twin: [`reference`].
//!
//! Dumps: `gi_denoiser.hit_mean` (the 5x5 harmonic mean hit distance the radius caps read),
//! `gi_denoiser.pass1_y`, `gi_denoiser.pass1_cocg` (after the first pass),
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
/// The 5x5 harmonic mean hit distance (`gi_denoiser.hit_mean`), in f32 as the twin has it.
pub const HIT_MEAN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

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

/// [`GiDenoiser::recurrent_names`]: the kept GI textures (Y, CoCg) and the kept AO.
pub type RecurrentNames = (Option<[&'static str; 2]>, Option<&'static str>);

pub use crate::techniques::ray_traced_gi::{GiLight, RecurrentHistory};

pub struct GiDenoiser {
    hit_mean: ComputePipeline,
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
            hit_mean: ComputePipeline::new(ctx, lib, "gi_denoiser/hit_mean.wgsl", "main", &[])?,
            // SAFETY: spatial.wgsl indexes its 32-entry workgroup disk with i < flags.x, which
            // `GiDenoiserParams::gi_pass` holds to the 32 points of `gi_disk`, and the uniform
            // disk (32 entries) with local / 2 < 16; its sample loop steps by at least 1
            // (flags.w = MAX_STEP), so it ends; every texel it loads is tested to lie inside the
            // image first; it has no integer division by a variable; the workgroup disk is
            // written before the barrier that precedes every read.
            spatial: unsafe {
                ComputePipeline::new_unchecked(ctx, lib, "gi_denoiser/spatial.wgsl", "main", &[])?
            },
            // SAFETY: ao.wgsl indexes the uniform disk (MAX_DISK_POINTS / 2 entries) with
            // i / 2 for i < flags.x, which `params::common` holds to MAX_DISK_POINTS; its loops
            // count up to fixed or uniform bounds; every texel it loads is tested to lie inside
            // the image first; it has no integer division by a variable and no workgroup memory.
            ao: unsafe {
                ComputePipeline::new_unchecked(ctx, lib, "gi_denoiser/ao.wgsl", "main", &[])?
            },
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

    /// Names of the textures that hold the denoiser's final output across frames when
    /// `recurrent` is on: the last enabled GI pass's (`None` with both off) and the AO
    /// denoiser's (`None` with it off). The temporal accumulation of the next frame blends with
    /// them instead of with its own last output.
    pub fn recurrent_names(settings: &GiDenoiserSettings) -> RecurrentNames {
        if !settings.recurrent {
            return (None, None);
        }
        let gi = if settings.pass2 {
            Some(["gi_denoiser.pass2_y", "gi_denoiser.pass2_cocg"])
        } else if settings.pass1 {
            Some(["gi_denoiser.pass1_y", "gi_denoiser.pass1_cocg"])
        } else {
            None
        };
        (gi, settings.ao.then_some("gi_denoiser.ao"))
    }

    /// The history textures of [`GiDenoiser::recurrent_names`] at `size`: last frame's
    /// denoised GI (Y, CoCg) and AO, for the temporal accumulation to read, and whether each
    /// holds a real last frame.
    pub fn recurrent_history(
        g: &mut FrameGraph<'_>,
        settings: &GiDenoiserSettings,
        [width, height]: [u32; 2],
    ) -> Result<RecurrentHistory> {
        let (gi, ao) = Self::recurrent_names(settings);
        let gi = match gi {
            Some([y, cocg]) => {
                let y = g.history_texture(y, TextureDesc::d2(width, height, GI_Y_FORMAT))?;
                let c = g.history_texture(cocg, TextureDesc::d2(width, height, GI_COCG_FORMAT))?;
                Some(([y.prev, c.prev], y.valid && c.valid))
            }
            None => None,
        };
        let ao = match ao {
            Some(name) => {
                let a = g.history_texture(name, TextureDesc::d2(width, height, AO_FORMAT))?;
                Some((a.prev, a.valid))
            }
            None => None,
        };
        Ok(RecurrentHistory { gi, ao })
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
                "gi_denoiser.pass1_y",
                "gi_denoiser.pass1_cocg",
            ),
            (
                settings.pass2,
                p2,
                "gi_denoiser.pass2",
                "gi_denoiser.pass2_y",
                "gi_denoiser.pass2_cocg",
            ),
        ];
        let (recurrent_gi, recurrent_ao) = Self::recurrent_names(settings);
        // Both denoisers' radius caps read the 5x5 harmonic mean hit distance, made once.
        let hit_mean = g.texture(
            "gi_denoiser.hit_mean",
            TextureDesc::d2(width, height, HIT_MEAN_FORMAT),
        )?;
        g.pass("gi_denoiser.hit_mean")
            .read(input.hit_distance)
            .write(hit_mean)
            .dispatch(&self.hit_mean, [width.div_ceil(16), height.div_ceil(16), 1])?;
        for (enabled, p, label, y_name, cocg_name) in passes {
            if !enabled {
                continue;
            }
            // The last pass's output is kept for the next frame's accumulation when recurrent.
            let kept = recurrent_gi.is_some_and(|[y, _]| y == y_name);
            let out = |g: &mut FrameGraph<'r>, name: &str, format| {
                let desc = TextureDesc::d2(width, height, format);
                if kept {
                    g.history_texture(name, desc).map(|h| h.cur)
                } else {
                    g.texture(name, desc)
                }
            };
            let out_y = out(g, y_name, GI_Y_FORMAT)?;
            let out_cocg = out(g, cocg_name, GI_COCG_FORMAT)?;
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
                .read(hit_mean)
                .dispatch_threads(&self.spatial, [width, height, 1])?;
            y = out_y;
            cocg = out_cocg;
        }
        let mut ao = input.ao;
        if settings.ao {
            let desc = TextureDesc::d2(width, height, AO_FORMAT);
            let out_ao = match recurrent_ao {
                Some(name) => g.history_texture(name, desc)?.cur,
                None => g.texture("gi_denoiser.ao", desc)?,
            };
            g.pass("gi_denoiser.ao")
                .constants(&pao)
                .constants(view)
                .read(geometry.depth)
                .read(geometry.normal)
                .read(input.ao)
                .read(input.history_length)
                .read(hit_mean)
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

/// The GI signal the deferred lighting resolves from the accumulated `rt`: through the
/// denoisers when there is one (`denoiser`, with what it wrote), else as accumulated.
pub fn signal<'r>(
    denoiser: Option<&'r GiDenoiser>,
    g: &mut FrameGraph<'r>,
    s: &GiDenoiserSettings,
    view: &View,
    gbuffer: &crate::techniques::gbuffer::GBuffer,
    rt: &crate::techniques::ray_traced_gi::RtGiFrame,
) -> Result<(GiLight, Option<DenoisedGi>)> {
    let Some(denoiser) = denoiser else {
        return Ok((
            GiLight {
                y: rt.gi_y,
                cocg: rt.gi_cocg,
                ao: rt.ao,
            },
            None,
        ));
    };
    let size = [view.viewport[0] as u32, view.viewport[1] as u32];
    let d = denoiser.record(
        g,
        s,
        view,
        GiDenoiserGeometry::from(gbuffer),
        &GiDenoiserInput {
            gi_y: rt.gi_y,
            gi_cocg: rt.gi_cocg,
            history_length: rt.history_length,
            ao: rt.ao,
            hit_distance: rt.hit_distance,
        },
        size,
    )?;
    let light = GiLight {
        y: d.gi_y,
        cocg: d.gi_cocg,
        ao: d.ao,
    };
    Ok((light, Some(d)))
}
