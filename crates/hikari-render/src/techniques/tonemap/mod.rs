//! The final image (issue 19, after Ghost of Tsushima's "Tonemapping"): one full-resolution
//! pass, `tonemap.apply`, from HDR radiance in nits to the 8-bit sRGB display image:
//!
//! 1. Purkinje shift at absolute scene luminance, before exposure (the talk's three-line
//!    shader with the matrices of [`hikari_math::color::purkinje`], times a strength, faded
//!    out as the rods saturate);
//! 2. times the exposure's scale (`exposure.value`) and `exp2` of the local tonemap's gain,
//!    evaluated here from its blurred grid and wide Gaussian (no full-resolution gain image);
//! 3. one matrix to the tonemapping space (ACEScg with red x 0.75), the white balance (von
//!    Kries in Bradford LMS to the artist's white) folded in;
//! 4. Uchimura's curve per channel (toe, linear section, shoulder), back to Rec.709;
//! 5. the sRGB transfer function, the `.cube` LUT grade (trilinear), a triangular dither.
//!
//! CPU twin: [`reference`]. The `.cube` format: [`cube`]. The screenshot with an embedded
//! identity LUT: [`lut_strip`]. docs/tonemapping.md explains each step.

pub mod cube;
pub mod lut_strip;
pub mod reference;
pub mod settings;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use hikari_math::color::adaptation::white_balance_rec709;
use hikari_math::color::primaries::{REC709, TONEMAP, rgb_to_rgb};
use hikari_math::color::purkinje::PurkinjeMatrices;
use hikari_math::color::{Mat3Rows, inv3, mul3};

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::techniques::local_tonemap::{GAIN_FORMAT, LocalTonemapFrame, LocalTonemapParams};
use cube::CubeLut;
use settings::TonemapSettings;

pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Switch bits of [`TonemapParams::switches`]`[0]`.
pub const SWITCH_PURKINJE: u32 = 1;
pub const SWITCH_LOCAL_GAIN: u32 = 2;
pub const SWITCH_CURVE: u32 = 4;
pub const SWITCH_LUT: u32 = 8;
pub const SWITCH_DITHER: u32 = 16;
/// The local gain is evaluated from the local tonemap's grid ([`LocalGain::Grid`]).
pub const SWITCH_LOCAL_GRID: u32 = 32;

/// The uniforms of `tonemap/apply.wgsl` (see it for each field). Matrices are rows.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct TonemapParams {
    pub lmsr_from_rgb: [[f32; 4]; 4],
    pub rgb_from_lms_gain: [[f32; 4]; 3],
    pub purkinje_fade: [f32; 4],
    pub tonemap_from_rec709: [[f32; 4]; 3],
    pub rec709_from_tonemap: [[f32; 4]; 3],
    pub curve: [f32; 4],
    pub curve_shoulder: [f32; 4],
    pub lut_domain_min: [f32; 4],
    pub lut_domain_max: [f32; 4],
    pub switches: [u32; 4],
    /// The local tonemap's uniforms (zero unless [`SWITCH_LOCAL_GRID`] is set).
    pub local: LocalTonemapParams,
}

fn rows4(m: &Mat3Rows, scale: f64) -> [[f32; 4]; 3] {
    m.map(|r| {
        [
            (r[0] * scale) as f32,
            (r[1] * scale) as f32,
            (r[2] * scale) as f32,
            0.0,
        ]
    })
}

/// Rec.709 → tonemapping space with the white balance to `white` folded in:
/// `T · W`, where `W · (1, 1, 1) = white` (identity for white (1, 1, 1)).
pub fn tonemap_from_rec709(white: Option<[f32; 3]>) -> Result<Mat3Rows> {
    let to_tm = rgb_to_rgb(&REC709, &TONEMAP);
    match white {
        None => Ok(to_tm),
        Some(w) => {
            let wb = white_balance_rec709(w.map(f64::from)).map_err(|e| RenderError::Setting {
                field: "tonemap.white".into(),
                message: e.to_string(),
            })?;
            Ok(mul3(&to_tm, &wb))
        }
    }
}

/// The three numbers of Uchimura's curve the settings do not hold, for the shader:
/// `(S0, S1, CP)`: where the shoulder starts, its value there, and its exponential rate.
pub fn curve_constants(s: &TonemapSettings) -> [f32; 3] {
    let (p, a, m, l) = (
        s.curve_max,
        s.curve_contrast,
        s.curve_linear_start,
        s.curve_linear_length,
    );
    let l0 = (p - m) * l / a;
    let s0 = m + l0;
    let s1 = m + a * l0;
    let c2 = a * p / (p - s1);
    [s0, s1, -c2 / p]
}

impl TonemapParams {
    /// The uniforms for `s`; `lut` is the grade's size and domain if one is applied,
    /// `local_gain` whether a local tonemap gain texture is bound, `dither_seed` picks the
    /// dither pattern.
    pub fn new(
        s: &TonemapSettings,
        lut: Option<&CubeLut>,
        local_gain: bool,
        dither_seed: u32,
    ) -> Result<Self> {
        let pk = PurkinjeMatrices::new();
        let mut lmsr = [[0f32; 4]; 4];
        for (dst, src) in lmsr.iter_mut().zip(pk.lmsr_from_rgb) {
            *dst = [src[0] as f32, src[1] as f32, src[2] as f32, 0.0];
        }
        let to_tm = tonemap_from_rec709(s.white_balance.then_some(s.white))?;
        let from_tm = inv3(&rgb_to_rgb(&REC709, &TONEMAP))
            .ok_or_else(|| RenderError::Graph("tonemapping space is singular".into()))?;
        let [s0, s1, cp] = curve_constants(s);
        let mut switches = 0;
        for (on, bit) in [
            (s.purkinje, SWITCH_PURKINJE),
            (local_gain, SWITCH_LOCAL_GAIN),
            (s.curve, SWITCH_CURVE),
            (lut.is_some(), SWITCH_LUT),
            (s.dither, SWITCH_DITHER),
        ] {
            if on {
                switches |= bit;
            }
        }
        let (dmin, dmax, n) = lut.map_or(([0.0; 3], [1.0; 3], 2.0), |l| {
            (l.domain_min, l.domain_max, l.size as f32)
        });
        Ok(Self {
            lmsr_from_rgb: lmsr,
            rgb_from_lms_gain: rows4(&pk.rgb_from_lms_gain, s.purkinje_strength as f64),
            purkinje_fade: [s.purkinje_rod_saturation, 0.0, 0.0, 0.0],
            tonemap_from_rec709: rows4(&to_tm, 1.0),
            rec709_from_tonemap: rows4(&from_tm, 1.0),
            curve: [
                s.curve_max,
                s.curve_contrast,
                s.curve_linear_start,
                s.curve_toe,
            ],
            curve_shoulder: [s.curve_black, s0, s1, cp],
            lut_domain_min: [dmin[0], dmin[1], dmin[2], n],
            lut_domain_max: [dmax[0], dmax[1], dmax[2], 0.0],
            switches: [switches, dither_seed, 0, 0],
            local: LocalTonemapParams::zeroed(),
        })
    }

    /// The same uniforms with the local gain evaluated from the local tonemap's grid with
    /// `local` (instead of read from a gain image).
    pub fn with_local_grid(mut self, local: LocalTonemapParams) -> Self {
        self.switches[0] = (self.switches[0] & !SWITCH_LOCAL_GAIN) | SWITCH_LOCAL_GRID;
        self.local = local;
        self
    }
}

/// `exposure.value` as the exposure technique lays it out: `(scale, ev100, metered lux,
/// highlight)`, scale = 1 / (1.2 · 2^ev100), no highlight metered.
pub fn exposure_value_from_ev100(ev100: f32, metered_lux: f32) -> [f32; 4] {
    [
        crate::techniques::exposure::reference::scale_from_ev100(ev100),
        ev100,
        metered_lux,
        crate::techniques::exposure::NO_HIGHLIGHT,
    ]
}

/// What `tonemap.apply` reads besides its settings.
#[derive(Clone, Copy, Debug)]
pub struct TonemapInputs {
    /// Linear Rec.709 radiance in nits (Rgba16Float).
    pub hdr: Tex,
    /// `exposure.value`, 16 bytes: `(scale, ev100, metered lux, highlight)`.
    pub exposure: Buf,
    /// The local tonemap's gain, if it ran.
    pub local: Option<LocalGain>,
}

/// Where `tonemap.apply` takes the local tonemap's log2 gain from.
#[derive(Clone, Copy, Debug)]
pub enum LocalGain {
    /// Evaluated per pixel from the blurred grid (`local_tonemap.grid_blurred`) and the wide
    /// Gaussian (`local_tonemap.wide`) with these uniforms: what the frame does.
    Grid {
        grid: Tex,
        wide: Tex,
        params: LocalTonemapParams,
    },
    /// Read from a full-resolution R16Float image (`local_tonemap.log2_gain`; tests, tools).
    Image(Tex),
}

impl LocalGain {
    /// The grid lookup of a frame's local tonemap, `None` when it was off.
    pub fn of(frame: &LocalTonemapFrame) -> Option<Self> {
        frame
            .lookup()
            .map(|(grid, wide, params)| LocalGain::Grid { grid, wide, params })
    }
}

struct LoadedLut {
    path: PathBuf,
    stamp: Option<(std::time::SystemTime, u64)>,
    lut: CubeLut,
    texture: wgpu::Texture,
}

fn file_stamp(path: &Path) -> Option<(std::time::SystemTime, u64)> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok()?, m.len()))
}

/// The LUT as an Rgba16Float 3D texture (filterable everywhere, and ample for 8-bit output).
pub fn upload_lut(ctx: &GpuContext, lut: &CubeLut) -> wgpu::Texture {
    let texels: Vec<[half::f16; 4]> = lut
        .data
        .iter()
        .map(|c| {
            [
                half::f16::from_f32(c[0]),
                half::f16::from_f32(c[1]),
                half::f16::from_f32(c[2]),
                half::f16::ONE,
            ]
        })
        .collect();
    let n = lut.size as u32;
    ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("tonemap.lut"),
            size: wgpu::Extent3d {
                width: n,
                height: n,
                depth_or_array_layers: n,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&texels),
    )
}

/// The `.cube` file `s` grades with: its `lut`, unless `grade` is off.
pub fn graded_by(s: &TonemapSettings) -> Option<&Path> {
    s.lut.as_deref().filter(|_| s.grade).map(Path::new)
}

/// What the tonemap keeps between frames in the renderer's frame state: the grading LUT on
/// the GPU, read again only when its file changes.
#[derive(Clone, Default)]
pub struct TonemapState {
    lut: Option<Arc<LoadedLut>>,
}

impl std::fmt::Debug for TonemapState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TonemapState")
            .field("lut", &self.lut.as_ref().map(|l| &l.path))
            .finish()
    }
}

impl TonemapState {
    /// The LUT of `path` on the GPU, read again only when the file changes.
    fn lut(&mut self, ctx: &GpuContext, path: &Path) -> Result<Arc<LoadedLut>> {
        let held = &mut self.lut;
        let stamp = file_stamp(path);
        if let Some(l) = held.as_ref()
            && l.path == path
            && l.stamp == stamp
            && stamp.is_some()
        {
            return Ok(l.clone());
        }
        let lut = CubeLut::read(path).map_err(|e| RenderError::Setting {
            field: "tonemap.lut".into(),
            message: e.to_string(),
        })?;
        let loaded = Arc::new(LoadedLut {
            path: path.to_path_buf(),
            stamp,
            texture: upload_lut(ctx, &lut),
            lut,
        });
        *held = Some(loaded.clone());
        Ok(loaded)
    }

    /// The LUT that `s` grades with, read from its file (cached), if any.
    pub fn grade(&mut self, ctx: &GpuContext, s: &TonemapSettings) -> Result<Option<CubeLut>> {
        Ok(match graded_by(s) {
            Some(p) => Some(self.lut(ctx, p)?.lut.clone()),
            None => None,
        })
    }
}

pub struct Tonemap {
    apply: ComputePipeline,
}

impl Tonemap {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            apply: ComputePipeline::new(ctx, lib, "tonemap/apply.wgsl", "main", &[])?,
        })
    }

    /// The display image (`tonemap.ldr`, Rgba8Unorm, sRGB-encoded) of `inputs.hdr`.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut TonemapState,
        s: &TonemapSettings,
        inputs: TonemapInputs,
        size: [u32; 2],
    ) -> Result<Tex> {
        let loaded = match graded_by(s) {
            Some(p) => Some(state.lut(g.ctx(), p)?),
            None => None,
        };
        let mut params = TonemapParams::new(
            s,
            loaded.as_ref().map(|l| &l.lut),
            matches!(inputs.local, Some(LocalGain::Image(_))),
            // One fixed pattern: a frame's image depends on its input alone (renders of the
            // same input are bitwise equal), and nothing after this pass averages frames.
            0,
        )?;
        let (gain, grid, wide) = match inputs.local {
            Some(LocalGain::Grid {
                grid,
                wide,
                params: p,
            }) => {
                params = params.with_local_grid(p);
                let gain = stand_in(g, "tonemap.no_gain", TextureDesc::d2(1, 1, GAIN_FORMAT))?;
                (gain, grid, wide)
            }
            other => {
                let gain = match other {
                    Some(LocalGain::Image(t)) => t,
                    _ => stand_in(g, "tonemap.no_gain", TextureDesc::d2(1, 1, GAIN_FORMAT))?,
                };
                let grid = stand_in(
                    g,
                    "tonemap.no_grid",
                    TextureDesc::d3(1, 1, 1, wgpu::TextureFormat::Rgba32Float),
                )?;
                let wide = stand_in(
                    g,
                    "tonemap.no_wide",
                    TextureDesc::d2(1, 1, wgpu::TextureFormat::R32Float),
                )?;
                (gain, grid, wide)
            }
        };
        let lut = match &loaded {
            Some(l) => g.import_texture("tonemap.lut", &l.texture),
            None => {
                g.persistent_texture(
                    "tonemap.no_lut",
                    TextureDesc::d3(2, 2, 2, wgpu::TextureFormat::Rgba16Float),
                )?
                .0
            }
        };
        let ldr = g.texture("tonemap.ldr", TextureDesc::d2(size[0], size[1], LDR_FORMAT))?;
        g.pass("tonemap.apply")
            .constants(&params)
            .read(inputs.hdr)
            .read(inputs.exposure)
            .read(gain)
            .read(grid)
            .read(wide)
            .read(lut)
            .sampler(SamplerKind::LinearClamp)
            .write(ldr)
            .dispatch_threads(&self.apply, [size[0], size[1], 1])?;
        Ok(ldr)
    }
}

/// A 1-texel texture bound where the switches leave a binding unread; persistent so that it
/// counts as written.
fn stand_in(g: &mut FrameGraph<'_>, name: &str, desc: TextureDesc) -> Result<Tex> {
    Ok(g.persistent_texture(name, desc)?.0)
}

/// An `exposure.value` buffer written from a fixed EV100 on the CPU, for driving the tonemap
/// alone (tests, tools) without the exposure technique.
pub fn fixed_exposure_buffer<'r>(
    g: &mut FrameGraph<'r>,
    ev100: f32,
    metered_lux: f32,
) -> Result<Buf> {
    let value = exposure_value_from_ev100(ev100, metered_lux);
    // Persistent, so that no other buffer of the frame shares its memory: the queue writes
    // it before the frame's commands run.
    let (buf, _) = g.persistent_buffer("tonemap.fixed_exposure", 16)?;
    let ctx = g.ctx();
    g.pass("tonemap.fixed_exposure")
        .uses(buf, true)
        .encode(move |_, res| {
            ctx.queue
                .write_buffer(res.buffer(buf), 0, bytemuck::cast_slice(&value))
        })?;
    Ok(buf)
}
