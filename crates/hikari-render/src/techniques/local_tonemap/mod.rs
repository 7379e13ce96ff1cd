//! Local tonemapping with a bilateral grid (Chen et al. 2007, as the talk's "Tonemapping"
//! uses it): a 64x32x64 grid over exposed log2 luminance, blurred and sampled back per pixel,
//! blended with a very wide Gaussian against ringing, then the talk's detail-preserving
//! contrast. The gain is evaluated per pixel by `tonemap.apply` (from the blurred grid and the
//! wide Gaussian this technique leaves); `local_tonemap.apply` writes it as an image,
//! `local_tonemap.log2_gain`, only when a dump or a test asks. CPU twin:
//! [`crate::techniques::local_tonemap::reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{Buf, FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

pub use settings::{LocalTonemapSettings, Look};

pub const GRID_SIZE: [u32; 3] = [64, 32, 64];
pub const WIDE_SIZE: [u32; 2] = [256, 128];
/// Taps each side of the wide Gaussian (13 in all).
pub const WIDE_RADIUS: u32 = 6;
pub const GAIN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;
const GRID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct LocalTonemapParams {
    pub grid: [f32; 4],
    pub tone: [f32; 4],
    pub blend: [f32; 4],
}

impl LocalTonemapParams {
    pub fn new(s: &LocalTonemapSettings, look: Look) -> Self {
        Self {
            grid: [
                s.grid_min_ev,
                GRID_SIZE[2] as f32 / s.grid_range_ev,
                s.grid_range_ev,
                s.max_gain_ev,
            ],
            tone: [look.contrast, look.shadow_contrast, look.detail, s.midpoint],
            blend: [
                s.bilateral_weight,
                s.highlight_target_ev,
                s.min_contrast,
                0.0,
            ],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct BlurParams {
    pub sigma: [f32; 4],
    pub config: [u32; 4],
}

impl BlurParams {
    /// A Gaussian of `sigma` texels along `axis`, cut at 3 sigma (at least one tap a side).
    pub fn gaussian(axis: u32, sigma: f32) -> Self {
        Self::taps(axis, sigma, (3.0 * sigma).ceil().max(1.0) as u32)
    }

    pub fn taps(axis: u32, sigma: f32, radius: u32) -> Self {
        Self {
            sigma: [sigma, 0.0, 0.0, 0.0],
            config: [axis, radius, 0, 0],
        }
    }
}

/// The local tonemap of one frame: what the tonemap needs to evaluate the gain per pixel.
#[derive(Clone, Copy, Debug)]
pub struct LocalTonemapFrame {
    /// `local_tonemap.grid_blurred`: the blurred grid (x: Σ w V, y: Σ w; V relative to
    /// `grid_min_ev`), 64x32x64 Rgba32Float; `None` when off.
    pub grid: Option<Tex>,
    /// `local_tonemap.wide`: the wide Gaussian of log2 luminance (relative to `grid_min_ev`),
    /// 256x128 R32Float; `None` when off.
    pub wide: Option<Tex>,
    /// The uniforms the gain is evaluated with.
    pub params: LocalTonemapParams,
    /// `local_tonemap.log2_gain` (full resolution, R16Float; 0 where off), written only when
    /// `--dump local_tonemap.log2_gain` asks for it; see [`LocalTonemap::gain_image`].
    pub log2_gain: Option<Tex>,
}

impl LocalTonemapFrame {
    /// The grid, the wide Gaussian and the uniforms, when the technique ran.
    pub fn lookup(&self) -> Option<(Tex, Tex, LocalTonemapParams)> {
        Some((self.grid?, self.wide?, self.params))
    }
}

/// The name of the gain image, for `--dump`.
pub const GAIN_NAME: &str = "local_tonemap.log2_gain";

pub struct LocalTonemap {
    fill: ComputePipeline,
    blur_grid: ComputePipeline,
    blur_wide: ComputePipeline,
    upsample: ComputePipeline,
    apply: ComputePipeline,
    zero: ComputePipeline,
}

impl LocalTonemap {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let p = |lib: &mut ShaderLibrary, path| ComputePipeline::new(ctx, lib, path, "main", &[]);
        Ok(Self {
            fill: p(lib, "local_tonemap/fill.wgsl")?,
            blur_grid: p(lib, "local_tonemap/blur_grid.wgsl")?,
            blur_wide: p(lib, "local_tonemap/blur_wide.wgsl")?,
            upsample: p(lib, "local_tonemap/upsample.wgsl")?,
            apply: p(lib, "local_tonemap/apply.wgsl")?,
            zero: p(lib, "local_tonemap/zero.wgsl")?,
        })
    }

    /// `radiance`: nits (Rgba16Float); `exposure`: `exposure.value`.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        radiance: Tex,
        exposure: Buf,
        size: [u32; 2],
        s: &LocalTonemapSettings,
        look: Look,
    ) -> Result<LocalTonemapFrame> {
        let params = LocalTonemapParams::new(s, look);
        let mut frame = LocalTonemapFrame {
            grid: None,
            wide: None,
            params,
            log2_gain: None,
        };
        if s.enabled {
            let (grid, wide) = self.record_grid(g, radiance, exposure, s, &params)?;
            frame.grid = Some(grid);
            frame.wide = Some(wide);
        }
        if g.dump_requested(GAIN_NAME) {
            frame.log2_gain = Some(self.gain_image(g, radiance, exposure, size, &frame)?);
        }
        Ok(frame)
    }

    /// `local_tonemap.log2_gain`: the gain the tonemap evaluates, as a full-resolution image
    /// (zero where the technique is off). For dumps and tests; the frame does not need it.
    pub fn gain_image<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        radiance: Tex,
        exposure: Buf,
        size: [u32; 2],
        frame: &LocalTonemapFrame,
    ) -> Result<Tex> {
        let log2_gain = g.texture(GAIN_NAME, TextureDesc::d2(size[0], size[1], GAIN_FORMAT))?;
        match frame.lookup() {
            None => g
                .pass("local_tonemap.zero")
                .write(log2_gain)
                .dispatch_threads(&self.zero, [size[0], size[1], 1])?,
            Some((grid, wide, params)) => g
                .pass("local_tonemap.apply")
                .constants(&params)
                .read(radiance)
                .read(exposure)
                .read(grid)
                .read(wide)
                .write(log2_gain)
                .dispatch_threads(&self.apply, [size[0], size[1], 1])?,
        }
        Ok(log2_gain)
    }

    /// The fill, the blurs and the upsampled wide Gaussian: the blurred grid and the wide image.
    fn record_grid<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        radiance: Tex,
        exposure: Buf,
        s: &LocalTonemapSettings,
        params: &LocalTonemapParams,
    ) -> Result<(Tex, Tex)> {
        let [gw, gh, gd] = GRID_SIZE;
        let grid_desc = TextureDesc::d3(gw, gh, gd, GRID_FORMAT);
        let coarse_desc = TextureDesc::d2(gw, gh, GRID_FORMAT);
        let grid = g.texture("local_tonemap.grid", grid_desc)?;
        let coarse = g.texture("local_tonemap.coarse", coarse_desc)?;
        g.pass("local_tonemap.fill")
            .constants(params)
            .read(radiance)
            .read(exposure)
            .write(grid)
            .write(coarse)
            .dispatch(&self.fill, [gw, gh, 1])?;

        // Separable blur: x, y, then z unless its sigma is 0.
        let blur_x = g.texture("local_tonemap.grid_blur_x", grid_desc)?;
        let blur_xy = g.texture("local_tonemap.grid_blur_xy", grid_desc)?;
        let mut blurred = blur_xy;
        for (axis, sigma, src, dst) in [
            (0, s.blur_sigma_xy, grid, blur_x),
            (1, s.blur_sigma_xy, blur_x, blur_xy),
        ] {
            g.pass("local_tonemap.blur_grid")
                .constants(&BlurParams::gaussian(axis, sigma))
                .read(src)
                .write(dst)
                .dispatch_threads(&self.blur_grid, GRID_SIZE)?;
        }
        if s.blur_sigma_z > 0.0 {
            blurred = g.texture("local_tonemap.grid_blurred", grid_desc)?;
            g.pass("local_tonemap.blur_grid")
                .constants(&BlurParams::gaussian(2, s.blur_sigma_z))
                .read(blur_xy)
                .write(blurred)
                .dispatch_threads(&self.blur_grid, GRID_SIZE)?;
        }

        let wide_x = g.texture("local_tonemap.wide_x", coarse_desc)?;
        let wide_xy = g.texture("local_tonemap.wide_xy", coarse_desc)?;
        for (axis, src, dst) in [(0, coarse, wide_x), (1, wide_x, wide_xy)] {
            g.pass("local_tonemap.blur_wide")
                .constants(&BlurParams::taps(axis, s.wide_sigma, WIDE_RADIUS))
                .read(src)
                .write(dst)
                .dispatch_threads(&self.blur_wide, [gw, gh, 1])?;
        }
        let wide = g.texture(
            "local_tonemap.wide",
            TextureDesc::d2(WIDE_SIZE[0], WIDE_SIZE[1], wgpu::TextureFormat::R32Float),
        )?;
        g.pass("local_tonemap.upsample")
            .constants(params)
            .read(wide_xy)
            .write(wide)
            .dispatch_threads(&self.upsample, [WIDE_SIZE[0], WIDE_SIZE[1], 1])?;
        Ok((blurred, wide))
    }
}
