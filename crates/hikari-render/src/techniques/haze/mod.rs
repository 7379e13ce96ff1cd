//! Volumetric haze (Ghost of Tsushima, after Wronski 2014 and Drobot 2017): a froxel grid
//! over the whole view frustum (128x64x64 by default, 10 cm to 100 km, each slice 20 % thicker
//! than the last) in which the haze's two analytic density layers (an exponential height
//! falloff and a sigmoidal layer) are lit and integrated front to back, then composited over
//! every pixel with the talk's density anti-aliasing (the grid holds L / alpha; each pixel
//! recomputes its own alpha in closed form) and tricubic B-spline sampling.
//!
//! * `haze.light`: a thread a froxel; the sun or moon through the sun shadow maps and a
//!   Henyey-Greenstein phase, the sky's L2 SH convolved with that phase and darkened by the
//!   sky visibility of the irradiance probes there (the talk's haze AO), and the point and
//!   spot lights (unshadowed).
//! * `haze.integrate`: a thread a froxel column, front to back.
//! * `haze.composite`: a thread a pixel; writes `haze.radiance`, which TAA then reads.
//!
//! The grids are Rgba16Float at a per-frame scale (the reciprocal of the metered illuminance),
//! so that forward scattering of a 100,000 lux sun stays inside f16. CPU twin: [`reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_scene::Sun;

use crate::context::GpuContext;
use crate::error::Result;
use crate::frame_context::FrameContext;
use crate::graph::{BindingSet, Buf, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use settings::HazeSettings;

pub const HAZE_SUN_SHADOWS: u32 = 1;
pub const HAZE_SKY: u32 = 2;
pub const HAZE_LOCAL_LIGHTS: u32 = 4;
pub const HAZE_DENSITY_AA: u32 = 8;
pub const HAZE_TRICUBIC: u32 = 16;
pub const HAZE_SKY_OCCLUSION: u32 = 32;

pub const GRID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The haze's per-frame parameters (`common.wgsl` documents each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct HazeParams {
    pub grid: [u32; 4],
    pub slicing: [f32; 4],
    pub exponential: [f32; 4],
    pub layer: [f32; 4],
    pub scatter: [f32; 4],
    pub sun: [f32; 4],
    pub sun_lux: [f32; 4],
    pub lights: [u32; 4],
}

impl HazeParams {
    /// The parameters for `s` in `weather` (a sky weather name), lit by `sun` (the frame's sun
    /// or moon), `light_count` point and spot lights whose light is cut off below
    /// `cutoff_lux`, with the grids scaled by the reciprocal of `metered_lux`.
    /// This frame's parameters: the weather's haze, lit by the frame context's sun where
    /// `direct_lighting.sun` lets it and its point and spot lights.
    pub fn for_frame(cx: &FrameContext, s: &crate::settings::Settings) -> Self {
        Self::new(
            &s.haze,
            &s.sky.weather,
            cx.lit_sun(s),
            cx.punctual_lights,
            cx.light_cutoff_lux,
            cx.metered_lux,
        )
    }

    pub fn new(
        s: &HazeSettings,
        weather: &str,
        sun: Option<&Sun>,
        light_count: u32,
        cutoff_lux: f32,
        metered_lux: f32,
    ) -> Self {
        let flags = [
            (s.sun_shadows, HAZE_SUN_SHADOWS),
            (s.sky, HAZE_SKY),
            (s.local_lights && light_count > 0, HAZE_LOCAL_LIGHTS),
            (s.density_aa, HAZE_DENSITY_AA),
            (s.tricubic, HAZE_TRICUBIC),
            (s.sky && s.sky_occlusion, HAZE_SKY_OCCLUSION),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |acc, (_, bit)| acc | bit);
        let k = HazeSettings::weather_factor(weather) * s.weather_scale;
        let first = reference::first_slice_m(s.near_m, s.far_m, s.slice_growth, s.slices)
            .max((s.far_m - s.near_m) * 1e-6);
        let (to_sun, sun_lux) = match sun {
            Some(sun) if s.sun => (
                sun.direction.normalize_or(Vec3::Y),
                sun.color * sun.illuminance_lux,
            ),
            _ => (Vec3::Y, Vec3::ZERO),
        };
        // A value of the grid is radiance times this: about 1 for the brightest haze in view.
        let scale = 1.0 / metered_lux.max(1e-3);
        Self {
            grid: [s.grid_width, s.grid_height, s.slices, flags],
            slicing: [s.near_m, first, s.slice_growth, s.slice_growth.ln()],
            exponential: [s.density * k, 1.0 / s.falloff_m, s.height_m, 0.0],
            layer: [
                s.layer_density * k,
                s.layer_top_density * k,
                s.layer_height_m,
                s.layer_thickness_m,
            ],
            scatter: [s.albedo, s.anisotropy, scale, s.far_m],
            sun: to_sun.extend(cutoff_lux).to_array(),
            sun_lux: sun_lux.extend(0.0).to_array(),
            lights: [light_count, s.sky_occlusion_samples.clamp(1, 16), 0, 0],
        }
    }
}

/// What the haze needs from the frame besides its parameters.
#[derive(Clone, Copy, Debug)]
pub struct HazeInputs {
    /// Reverse-Z depth (`gbuffer.depth`, 0 on the sky).
    pub depth: Tex,
    /// Radiance in nits to composite the haze over.
    pub lit: Tex,
    /// Point and spot lights (`scene.lights`).
    pub lights: Buf,
    /// Binding set `sun_shadows` (`SunShadowMaps::lookup`).
    pub shadows: BindingSet,
    /// Binding set `sky_ambient` (`SkyFrame::ambient`): the sky's SH.
    pub sky_ambient: BindingSet,
    /// Binding set `clouds` (`CloudsFrame::lookup`): their shadow on the sun.
    pub clouds: BindingSet,
    /// Binding set `irradiance_probes` (`ProbesFrame::lookup`): the sky visibility of the
    /// sky's light.
    pub probes: BindingSet,
}

/// The haze's textures in a frame.
#[derive(Clone, Copy, Debug)]
pub struct HazeFrame {
    /// `haze.light`: L_i times albedo and scale per froxel.
    pub light: Tex,
    /// `haze.grid`: L / alpha (or L) times scale, and alpha, per froxel.
    pub grid: Tex,
    /// `haze.radiance`: the lit image seen through the haze, nits.
    pub radiance: Tex,
}

/// `light.wgsl`'s temporal parameters: this frame's sample offset in the froxel and the
/// history's weight, and the rescale of last frame's grid to this frame's storage scale.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct HazeTemporal {
    pub jitter_blend: [f32; 4],
    pub rescale: [f32; 4],
}

impl HazeTemporal {
    /// Frame `frame`'s parameters: with `s.temporal`, the jittered sample and, where
    /// `history` (last frame's parameters) grids the same froxels, its weight; else the centre
    /// alone.
    pub fn new(
        s: &HazeSettings,
        frame: u64,
        params: &HazeParams,
        history: Option<&HazeParams>,
    ) -> Self {
        if !s.temporal {
            return Self {
                jitter_blend: reference::jitter(0).extend(0.0).to_array(),
                rescale: [1.0, 0.0, 0.0, 0.0],
            };
        }
        let same_grid = history
            .filter(|h| h.grid == params.grid && h.slicing == params.slicing && h.scatter[2] > 0.0);
        let (blend, rescale) = match same_grid {
            Some(h) => (s.temporal_blend, params.scatter[2] / h.scatter[2]),
            None => (0.0, 1.0),
        };
        Self {
            jitter_blend: reference::jitter(frame).extend(blend).to_array(),
            rescale: [rescale, 0.0, 0.0, 0.0],
        }
    }
}

/// What the haze keeps between frames in the renderer's frame state.
#[derive(Clone, Copy, Debug, Default)]
pub struct HazeState {
    /// The frame index and parameters of the last frame that drew the haze, for the temporal
    /// filter: only the frame just before counts.
    last: Option<(u64, HazeParams)>,
}

pub struct Haze {
    light: ComputePipeline,
    integrate: ComputePipeline,
    composite: ComputePipeline,
}

impl Haze {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            light: ComputePipeline::new(ctx, lib, "haze/light.wgsl", "main", &[])?,
            integrate: ComputePipeline::new(ctx, lib, "haze/integrate.wgsl", "main", &[])?,
            composite: ComputePipeline::new(ctx, lib, "haze/composite.wgsl", "main", &[])?,
        })
    }

    /// Lights and integrates the grid, and composites it over `inputs.lit`. A frame whose
    /// history is invalid (a camera cut) starts the temporal filter afresh.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut HazeState,
        cx: &FrameContext,
        s: &HazeSettings,
        params: &HazeParams,
        inputs: &HazeInputs,
    ) -> Result<HazeFrame> {
        let view = &cx.view;
        let keep_history = cx.history.valid();
        let [gw, gh, gn, _] = params.grid;
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let history = g.history_texture("haze.light", TextureDesc::d3(gw, gh, gn, GRID_FORMAT))?;
        let frame = g.frame_index();
        let last = state.last.replace((frame, *params));
        let temporal = HazeTemporal::new(
            s,
            frame,
            params,
            last.as_ref()
                .filter(|(f, _)| keep_history && history.valid && f + 1 == frame)
                .map(|(_, p)| p),
        );
        let light = history.cur;
        let grid = g.texture("haze.grid", TextureDesc::d3(gw, gh, gn, GRID_FORMAT))?;
        let radiance = g.texture("haze.radiance", TextureDesc::d2(w, h, RADIANCE_FORMAT))?;
        g.pass("haze.light")
            .constants(view)
            .constants(params)
            .read(inputs.lights)
            .write(light)
            .constants(&temporal)
            .read(history.prev)
            .sampler(SamplerKind::LinearClamp)
            .set(inputs.shadows)
            .set(inputs.sky_ambient)
            .set(inputs.clouds)
            .set(inputs.probes)
            .dispatch_threads(&self.light, [gw, gh, gn])?;
        g.pass("haze.integrate")
            .constants(view)
            .constants(params)
            .read(light)
            .write(grid)
            .dispatch_threads(&self.integrate, [gw, gh, 1])?;
        g.pass("haze.composite")
            .constants(view)
            .constants(params)
            .read(inputs.depth)
            .read(inputs.lit)
            .read(grid)
            .sampler(SamplerKind::LinearClamp)
            .write(radiance)
            .dispatch_threads(&self.composite, [w, h, 1])?;
        Ok(HazeFrame {
            light,
            grid,
            radiance,
        })
    }
}
