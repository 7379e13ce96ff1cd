//! One frame, top to bottom. Each numbered step is the step of the same number in
//! ARCHITECTURE.md; the steps not yet built say which issue brings them.

use hikari_scene::{Camera, Sun};

use crate::brdf_tables::BrdfTables;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex};
use crate::raster::{RasterQueues, Rasterizer};
use crate::scene_gpu::SceneGpu;
use crate::settings::Settings;
use crate::shader::{self, ShaderLibrary};
use crate::techniques::direct_lighting::{DirectLighting, LightingParams};
use crate::techniques::gbuffer::{GBuffer, GBufferPass};
use crate::techniques::sky::{Sky, SkyFrame};
use crate::techniques::sun_shadows::{self, SunShadowMaps, SunShadows};
use crate::techniques::tonemap::{self, Tonemap, TonemapInputs};
use crate::view::View;

/// What a frame depends on besides the scene.
#[derive(Clone, Debug)]
pub struct FrameSettings {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    /// The camera of the previous frame, for motion vectors; `None`: it did not move.
    pub prev_camera: Option<Camera>,
    /// The sun or moon; `None`: no directional light.
    pub sun: Option<Sun>,
    pub settings: Settings,
}

impl FrameSettings {
    /// Exposure of the placeholder tonemap: the configured EV100, else the incident-light
    /// meter rule EV100 = log2(E * 100 / C) with C = 250 (ISO 2720) on the sun's illuminance,
    /// floored at 20 lux so that nights are exposed for their lamps, not for the moon.
    pub fn ev100(&self) -> f32 {
        self.ev100_with_sky(0.0)
    }

    /// [`FrameSettings::ev100`] metered on the sun and a sky of `sky_lux` on the ground.
    pub fn ev100_with_sky(&self, sky_lux: f32) -> f32 {
        self.settings
            .exposure
            .ev100
            .unwrap_or_else(|| (self.metered_lux_with_sky(sky_lux) * 100.0 / 250.0).log2())
    }

    /// The illuminance the exposure is set for: the configured EV100's, else the sun's,
    /// at least 20 lux.
    pub fn metered_lux(&self) -> f32 {
        self.metered_lux_with_sky(0.0)
    }

    /// The illuminance the exposure is set for, with the sky's own light (`sky_lux` on a
    /// horizontal plane): the configured EV100's, else the larger of the sun's and the sky's,
    /// at least 20 lux. At dawn and dusk the sky outshines the low sun.
    pub fn metered_lux_with_sky(&self, sky_lux: f32) -> f32 {
        match self.settings.exposure.ev100 {
            Some(ev) => 2f32.powf(ev) * 250.0 / 100.0,
            None => self
                .sun
                .as_ref()
                .map_or(0.0, |s| s.illuminance_lux)
                .max(sky_lux)
                .max(20.0),
        }
    }
}

/// What one frame leaves for the next, besides the graph's persistent resources.
#[derive(Clone, Debug, Default)]
pub struct FrameState {
    pub shadow_cache: sun_shadows::ShadowCache,
    pub raster_queues: RasterQueues,
}

/// Every technique's pipelines, built once.
pub struct Techniques {
    pub raster: Rasterizer,
    pub sky: Sky,
    pub sun_shadows: SunShadows,
    pub gbuffer: GBufferPass,
    pub direct_lighting: DirectLighting,
    pub tonemap: Tonemap,
    /// The BRDF's albedo tables, bound by every pass that shades with `hikari::brdf`.
    pub brdf_tables: BrdfTables,
}

impl Techniques {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features))?;
        Ok(Self {
            raster: Rasterizer::new(ctx, &mut lib)?,
            sky: Sky::new(ctx, &mut lib)?,
            sun_shadows: SunShadows::new(ctx, &mut lib)?,
            gbuffer: GBufferPass::new(ctx, &mut lib)?,
            direct_lighting: DirectLighting::new(ctx, &mut lib)?,
            brdf_tables: BrdfTables::new(ctx),
            tonemap: Tonemap::new(ctx, &mut lib)?,
        })
    }
}

/// The frame's images.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    pub gbuffer: GBuffer,
    pub shadows: SunShadowMaps,
    pub sky: SkyFrame,
    /// Linear radiance in nits (Rgba16Float), for the EXR.
    pub hdr: Tex,
    /// Display-encoded sRGB (Rgba8Unorm), for the PNG.
    pub ldr: Tex,
}

pub fn record<'r>(
    g: &mut FrameGraph<'r>,
    t: &'r Techniques,
    scene: &'r SceneGpu,
    s: &FrameSettings,
    state: &mut FrameState,
) -> Result<FrameOutputs> {
    let size = [s.width, s.height];
    let aspect = s.width as f32 / s.height as f32;

    // 1. Update: camera and sun. The sun (or moon) comes from the sky settings' date, time and
    //    place (`sky::lights`, resolved by the caller into `s.sun`) or is the scene's own.
    let view = View::with_previous(
        &s.camera,
        s.prev_camera.as_ref().unwrap_or(&s.camera),
        s.width,
        s.height,
    );
    let to_sun = s.sun.as_ref().map_or(glam::Vec3::ZERO, |sun| sun.direction);
    let scene = &scene.import(g);

    // 2. Atmosphere tables (rebuilt when the weather changes) resampled for this frame's sun
    //    and moon, and 3. the sky's deringed SH.
    let sky = t.sky.record(
        g,
        &s.settings.sky,
        s.sun.as_ref(),
        s.camera.position.y.max(0.0) / 1000.0,
    )?;

    // 4. Irradiance probes, 5. reflection probes, 6. clouds: their issues add them here.

    // 7. Sun shadow maps.
    let shadows = t.sun_shadows.record(
        g,
        &t.raster,
        scene,
        &mut state.shadow_cache,
        &s.camera,
        aspect,
        to_sun,
        &s.settings.sun_shadows,
        &mut state.raster_queues,
    )?;

    // 8. G-buffer.
    let gbuffer = t
        .gbuffer
        .record(g, &t.raster, scene, &view, size, &mut state.raster_queues)?;

    // 9. Ray tracing and 10. denoising: the ray-tracing issues add them here.

    // 11. Deferred direct lighting (sun, lights, emissive; the sky where depth is 0 and the
    //     sky's SH as ambient light, or the placeholders with the atmosphere off).
    let brdf = t.brdf_tables.binding_set(g);
    let mut lighting = LightingParams::new(
        s.sun.as_ref(),
        scene.light_count,
        s.metered_lux_with_sky(sky.sky_lux),
        &s.settings.direct_lighting,
    );
    if sky.enabled {
        lighting.use_sky(s.settings.sky.sky);
    }
    let hdr = t
        .direct_lighting
        .record(g, &gbuffer, &shadows, &sky, brdf, scene, &view, &lighting)?;

    // 12. Haze and 13. TAA: their issues add them here.

    // 14. Exposure (a fixed EV100 until the exposure technique), then the tonemap: Purkinje
    //     shift, white balance, the curve in the tonemapping space, LUT grade, dither.
    let exposure = tonemap::placeholder_exposure_buffer(
        g,
        s.ev100_with_sky(sky.sky_lux),
        s.metered_lux_with_sky(sky.sky_lux),
    )?;
    let ldr = t.tonemap.record(
        g,
        &s.settings.tonemap,
        TonemapInputs {
            hdr,
            exposure,
            log2_gain: None,
        },
        size,
    )?;

    Ok(FrameOutputs {
        gbuffer,
        shadows,
        sky,
        hdr,
        ldr,
    })
}
