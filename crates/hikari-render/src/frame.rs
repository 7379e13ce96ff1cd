//! One frame, top to bottom, its steps numbered in the order they run (docs/architecture.md
//! lists them). The techniques are recorded in [`crate::techniques::FRAME_ORDER`]; each may
//! use what the ones before it publish. The G-buffer comes first, as nothing it draws depends
//! on the lighting; the clouds come before the atmosphere, whose SH sees the sky through them,
//! and before the probes, whose sun bounce and sky they shadow and cover.

use crate::brdf_tables::BrdfTables;
use crate::context::GpuContext;
use crate::error::Result;
use crate::frame_context::FrameContext;
pub use crate::frame_context::FrameSettings;
use crate::graph::{FrameGraph, Tex};
use crate::scene::raster::{RasterQueues, Rasterizer};
use crate::scene::rt::SceneRt;
use crate::scene::upload::SceneGpu;
use crate::shader;
use crate::steady_light::{FrameLight, LightKey};
use crate::techniques::area_lights::{
    AreaLightParams, AreaLightScene, AreaLights, DenoisedShadows, ShadowDenoiseInputs,
    ShadowDenoiseParams,
};
use crate::techniques::clouds::settings::CloudsSettings;
use crate::techniques::clouds::{self, CloudParams, Clouds};
use crate::techniques::direct_lighting::{DirectLighting, LightingParams};
use crate::techniques::exposure::{Exposure, ExposureFrame, ExposureParams};
use crate::techniques::gbuffer::overrides::{GBufferTexel, override_gbuffer};
use crate::techniques::gbuffer::{GBuffer, GBufferPass};
use crate::techniques::gi_denoiser::{self, DenoisedGi, GiDenoiser, RecurrentNames};
use crate::techniques::haze::{Haze, HazeFrame, HazeInputs, HazeParams};
use crate::techniques::irradiance_probes::{IrradianceProbes, ProbesFrame};
use crate::techniques::local_tonemap::{LocalTonemap, LocalTonemapFrame};
use crate::techniques::particles::{self, ParticleParams, Particles};
use crate::techniques::ray_traced_gi::{
    RayTracedGi, RtGiFrame, RtGiInputs, RtGiParams, RtGiRays, SharedRtGiScene,
};
use crate::techniques::reflection_probes::{
    ReflectionProbeInputs, ReflectionProbes, ReflectionProbesFrame,
};
use crate::techniques::sky::{Sky, SkyFrame};
use crate::techniques::sun_shadows::{self, SunShadowMaps, SunShadows};
use crate::techniques::taa::Taa;
use crate::techniques::tonemap::{LocalGain, Tonemap, TonemapInputs};

/// What one frame leaves for the next, besides the graph's persistent resources.
#[derive(Clone, Debug, Default)]
pub struct FrameState {
    pub shadow_cache: sun_shadows::ShadowCache,
    pub raster_queues: RasterQueues,
    /// The per-instance table of ray-traced GI, built when the technique is first on.
    pub rtgi_scene: Option<SharedRtGiScene>,
    /// Which denoiser outputs the last frame kept as the accumulation's history
    /// (`GiDenoiser::recurrent_names`): when that changes, a kept texture may be stale.
    pub rtgi_recurrent: Option<RecurrentNames>,
    /// Tests only: G-buffer texels overwritten every frame after the G-buffer pass
    /// ([`crate::renderer::Renderer::override_gbuffer_texels`]).
    pub gbuffer_overrides: Vec<GBufferTexel>,
    /// What each technique keeps between frames besides its graph textures.
    pub techniques: TechniqueStates,
}

/// Every technique's state between frames. A technique is its pipelines ([`Techniques`]) and
/// this value, which the renderer owns: a frame records from it and advances a copy, which
/// the renderer keeps only when it shows the frame.
#[derive(Clone, Debug, Default)]
pub struct TechniqueStates {
    pub irradiance_probes: crate::techniques::irradiance_probes::IrradianceProbesState,
    pub reflection_probes: crate::techniques::reflection_probes::ReflectionProbesState,
    pub sky: crate::techniques::sky::SkyState,
    pub clouds: crate::techniques::clouds::CloudsState,
    pub haze: crate::techniques::haze::HazeState,
    pub particles: crate::techniques::particles::ParticlesState,
    pub tonemap: crate::techniques::tonemap::TonemapState,
    pub ray_traced_gi: crate::techniques::ray_traced_gi::RtGiState,
}

/// Every technique's pipelines, built once.
pub struct Techniques {
    pub raster: Rasterizer,
    pub sky: Sky,
    pub clouds: Clouds,
    pub irradiance_probes: IrradianceProbes,
    pub reflection_probes: ReflectionProbes,
    pub sun_shadows: SunShadows,
    pub gbuffer: GBufferPass,
    pub direct_lighting: DirectLighting,
    pub area_lights: AreaLights,
    /// `None` where the adapter cannot write the GI signal's 16-bit formats from compute: the
    /// lighting then resolves the accumulated signal undenoised.
    pub gi_denoiser: Option<GiDenoiser>,
    pub haze: Haze,
    pub particles: Particles,
    pub taa: Taa,
    pub exposure: Exposure,
    pub local_tonemap: LocalTonemap,
    pub ray_traced_gi: RayTracedGi,
    pub tonemap: Tonemap,
    /// What a window shows of a frame (the viewer's debug views), after the frame.
    pub debug_view: crate::techniques::debug_view::DebugView,
    /// The BRDF's albedo tables, bound by every pass that shades with `hikari::brdf`.
    pub brdf_tables: BrdfTables,
}

impl Techniques {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let mut lib = shader::library(shader::capabilities_for(ctx.features))?;
        Ok(Self {
            raster: Rasterizer::new(ctx, &mut lib)?,
            sky: Sky::new(ctx, &mut lib)?,
            clouds: Clouds::new(ctx, &mut lib)?,
            irradiance_probes: IrradianceProbes::new(ctx, &mut lib)?,
            reflection_probes: ReflectionProbes::new(ctx, &mut lib)?,
            sun_shadows: SunShadows::new(ctx, &mut lib)?,
            gbuffer: GBufferPass::new(ctx, &mut lib)?,
            direct_lighting: DirectLighting::new(ctx, &mut lib)?,
            area_lights: AreaLights::new(ctx, &mut lib)?,
            gi_denoiser: GiDenoiser::new(ctx, &mut lib)
                .inspect_err(|e| log::warn!("GI denoiser unavailable: {e}"))
                .ok(),
            brdf_tables: BrdfTables::new(ctx),
            haze: Haze::new(ctx, &mut lib)?,
            particles: Particles::new(ctx, &mut lib)?,
            taa: Taa::new(ctx, &mut lib)?,
            exposure: Exposure::new(ctx, &mut lib)?,
            local_tonemap: LocalTonemap::new(ctx, &mut lib)?,
            ray_traced_gi: RayTracedGi::new(ctx, &mut lib)?,
            tonemap: Tonemap::new(ctx, &mut lib)?,
            debug_view: crate::techniques::debug_view::DebugView::new(ctx, &mut lib)?,
        })
    }
}

/// The frame's images.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    pub gbuffer: GBuffer,
    pub shadows: SunShadowMaps,
    pub sky: SkyFrame,
    pub clouds: crate::techniques::clouds::CloudsFrame,
    pub probes: ProbesFrame,
    pub reflection_probes: ReflectionProbesFrame,
    /// Area lights and shadowed point and spot lights, nits (`area_lights.radiance`), this
    /// frame's estimate before the shadow denoiser.
    pub area_lights: Tex,
    /// The same lights unshadowed (`area_lights.unshadowed`).
    pub area_lights_unshadowed: Tex,
    /// The shadow denoiser's textures (`None` with `area_lights.denoise` off).
    pub area_lights_denoised: Option<DenoisedShadows>,
    /// Ray-traced GI and AO, accumulated (`None` with the technique off).
    pub ray_traced_gi: Option<RtGiFrame>,
    /// The GI and AO after the denoisers (`None` with ray-traced GI or the denoiser off).
    pub denoised_gi: Option<DenoisedGi>,
    /// Its hit words and BVH queue.
    pub ray_traced_gi_rays: Option<RtGiRays>,
    /// Linear radiance in nits (Rgba16Float), for the EXR: the lit image after TAA. With TAA
    /// on this is its history, whose alpha counts the frames it averages ([`Renderer::render`]
    /// sets alpha to 1 in the image it reads back).
    ///
    /// [`Renderer::render`]: crate::renderer::Renderer::render
    pub hdr: Tex,
    /// The haze's grids and the lit image through it (`None` with the haze off).
    pub haze: Option<HazeFrame>,
    /// The deferred lighting's image (`direct_lighting.radiance`), before the haze and TAA.
    pub lit: Tex,
    /// Lux arriving at each surface pixel, -1 on the sky (R32Float).
    pub illuminance: Tex,
    pub exposure: ExposureFrame,
    pub local_tonemap: LocalTonemapFrame,
    /// Display-encoded sRGB (Rgba8Unorm), for the PNG.
    pub ldr: Tex,
}

/// Records one frame, step by step, from the frame context `cx` (step 0, resolved by the
/// renderer before this) and the frame's settings `s`.
#[allow(clippy::too_many_arguments)]
pub fn record<'r>(
    g: &mut FrameGraph<'r>,
    t: &'r Techniques,
    scene: &'r SceneGpu,
    area: &'r AreaLightScene,
    rt: &'r SceneRt,
    cx: &FrameContext,
    s: &FrameSettings,
    state: &mut FrameState,
) -> Result<FrameOutputs> {
    // The scene BVH as the caller updated it for this frame (`SceneRt::update`): GI rays
    // trace every kept instance, shadow rays all but the lamp shells.
    let rt_bvh = rt.import(g)?;
    let size = cx.size;
    let view = cx.view;
    let history = cx.history.valid();
    let sun = cx.sun.as_ref();
    let emitters = &scene.cpu.particles;
    let scene = &scene.import(g);

    // 1. Update: camera, sun or moon, the sky's clock, the metered light and the lights'
    //    cut-off are the frame context's (`frame_context.rs`), resolved before this walk.

    // 2. G-buffer: the scene rasterised into visibility, resolved into surfaces. First, as
    //    nothing it draws depends on the lighting; the reflection probes' captures use its
    //    pipelines.
    let gbuffer = t
        .gbuffer
        .record(g, &t.raster, scene, &view, size, &mut state.raster_queues)?;
    override_gbuffer(g, &gbuffer, size, &state.gbuffer_overrides)?;

    // 3. Clouds, before the atmosphere: this frame's share of the paraboloid cloud map and the
    //    clouds' shadow map. The sky's SH sees the sky through them, the deferred lighting
    //    draws them over the sky, and they shadow the sun there, in the haze, the GI and the
    //    probes' sun bounce.
    let clouds_settings = CloudsSettings {
        map_size: clouds::map_size_for(&s.settings.clouds, size[1], s.camera.vfov_deg),
        ..s.settings.clouds.clone()
    };
    let clouds = t.clouds.record(
        g,
        &mut state.techniques.clouds,
        &clouds_settings,
        CloudParams::new(
            &clouds_settings,
            &s.settings.sky.weather,
            sun,
            cx.clock_s,
            s.settings.sky.enabled && s.settings.sky.sky,
        ),
        s.camera.position,
    )?;

    // 4. Atmosphere tables (rebuilt when the weather changes) resampled for this frame's sun
    //    and moon, and the sky's deringed SH, with the clouds in it (`clouds.ambient`).
    let sky = t.sky.record(
        g,
        &mut state.techniques.sky,
        cx,
        &s.settings.sky,
        &clouds,
        s.settings.clouds.ambient,
    )?;

    // 5. Irradiance probes: this frame's share relit from the sky's SH and the sun or moon,
    //    whose bounce the clouds shadow; none once a whole round holds an unchanged light.
    let light_key = LightKey::new(cx, &s.settings, &clouds.params);
    let light = FrameLight {
        key: &light_key,
        settled: clouds.settled,
    };
    let probes = t.irradiance_probes.record(
        g,
        &mut state.techniques.irradiance_probes,
        cx,
        &s.settings.irradiance_probes,
        &sky,
        clouds.lookup,
        light,
    )?;

    // 6. Reflection probes (after the clouds, which shadow and cover their sky): captured
    //    once, this frame's share relit and prefiltered.
    let reflection_probes = t.reflection_probes.record(
        g,
        &mut state.techniques.reflection_probes,
        &t.gbuffer,
        &t.raster,
        scene,
        &mut state.raster_queues,
        &s.settings.reflection_probes,
        &ReflectionProbeInputs::for_frame(
            cx,
            &s.settings,
            &sky,
            &probes,
            &clouds,
            scene.lights,
            light,
        ),
    )?;

    // 7. Sun shadow maps (cascades redrawn only where the view or the sun moved).
    let shadows = t.sun_shadows.record(
        g,
        &t.raster,
        scene,
        &mut state.shadow_cache,
        &s.camera,
        cx.aspect,
        sun.map_or(glam::Vec3::ZERO, |sun| sun.direction),
        &s.settings.sun_shadows,
        &mut state.raster_queues,
    )?;

    // The probes' irradiance per pixel, only for `--dump irradiance_probes.pixels`.
    t.irradiance_probes.record_pixels_dump(
        g,
        &state.techniques.irradiance_probes,
        &probes,
        &gbuffer,
        &view,
    )?;

    // 8. Ray-traced GI and AO: one ray a pixel, pre-traced in screen space, the
    //    rest through the BVH, lit, encoded and accumulated for the denoiser.
    let mut ray_traced_gi = None;
    let mut ray_traced_gi_rays = None;
    if s.settings.ray_traced_gi.enabled {
        let rt_scene = state.rtgi_scene.clone().ok_or_else(|| {
            crate::error::RenderError::Graph(
                "ray_traced_gi: the instance table is not built (the Renderer builds it)".into(),
            )
        })?;
        let params = RtGiParams::for_frame(cx, &s.settings, sky.enabled, area.light_count());
        let recurrent = t
            .gi_denoiser
            .as_ref()
            .map(|_| GiDenoiser::recurrent_names(&s.settings.gi_denoiser));
        let recurrence_changed = state.rtgi_recurrent != recurrent;
        state.rtgi_recurrent = recurrent;
        let inputs = RtGiInputs {
            gbuffer: &gbuffer,
            sky: &sky,
            shadows: &shadows,
            clouds: clouds.lookup,
            lights: scene.lights,
            view: &view,
            params: &params,
            bvh: rt_bvh.gi,
            shadow_bvh: rt_bvh.shadow,
            area,
            // Step 13's exposure of the last frame: this frame's is not known yet.
            exposure: Exposure::previous(g)?,
            denoised_history: match t.gi_denoiser {
                Some(_) => GiDenoiser::recurrent_history(g, &s.settings.gi_denoiser, size)?,
                None => Default::default(),
            },
        };
        let (frame, rays) = t.ray_traced_gi.record(
            g,
            &mut state.techniques.ray_traced_gi,
            &rt_scene,
            &inputs,
            !history || recurrence_changed,
        )?;
        ray_traced_gi = Some(frame);
        ray_traced_gi_rays = Some(rays);
    }

    // 9. Denoising: the two-pass GI denoiser and the AO denoiser, then the signal the deferred
    //     lighting resolves.
    let (gi_light, denoised_gi) = match &ray_traced_gi {
        Some(rt) => {
            let denoiser = t.gi_denoiser.as_ref();
            let (light, d) =
                gi_denoiser::signal(denoiser, g, &s.settings.gi_denoiser, &view, &gbuffer, rt)?;
            (Some(light), d)
        }
        None => (None, None),
    };

    // 10. Deferred direct lighting (sun, lights, emissive; the sky where depth is 0 and the
    //     sky's SH as ambient light, or the placeholders with the atmosphere off).
    let brdf = t.brdf_tables.binding_set(g);
    // Area lights, and point and spot lights with ray-traced shadows, added by the deferred
    // lighting, which then leaves the point and spot lights to them.
    let area_params = AreaLightParams::for_frame(cx, &s.settings.area_lights, area.light_count());
    let lighting = LightingParams::for_frame(
        cx,
        &s.settings,
        sky.enabled,
        probes.present,
        &reflection_probes.lookup.params,
        gi_light.is_some(),
        &area_params,
    );
    let area_frame = t.area_lights.record(
        g,
        area,
        &rt_bvh.shadow,
        &gbuffer,
        brdf,
        scene,
        &view,
        &area_params,
    )?;
    // The shadows' visibility accumulated and filtered (docs/area-lights.md, "Denoising the
    // shadows"); the deferred lighting then adds the denoised light.
    let area_lights_denoised = if s.settings.area_lights.denoise && area_params.shades_any() {
        Some(t.area_lights.denoiser.record(
            g,
            &view,
            &ShadowDenoiseParams::new(&s.settings.area_lights, !history),
            &ShadowDenoiseInputs {
                depth: gbuffer.depth,
                normal: gbuffer.normal,
                motion: gbuffer.motion,
                shadowed: area_frame.radiance,
                unshadowed: area_frame.unshadowed,
            },
            size,
        )?)
    } else {
        None
    };
    let area_lights = area_frame.radiance;
    let area_light_for_lighting = area_lights_denoised.map_or(area_lights, |d| d.radiance);
    let lit_frame = t.direct_lighting.record(
        g,
        &gbuffer,
        &shadows,
        &sky,
        &clouds,
        &probes,
        brdf,
        scene,
        &view,
        &lighting,
        area_light_for_lighting,
        gi_light.as_ref(),
        &reflection_probes.lookup,
    )?;
    if ray_traced_gi.is_some() {
        // The lit image lights next frame's GI hits where they were visible.
        t.ray_traced_gi.keep_lit(g, lit_frame.radiance, size)?;
    }

    // 11. Haze: the froxel grid lit by the sun or moon (through the shadow maps), the sky and
    //     the local lights, integrated front to back and composited over every pixel. It needs
    //     the atmosphere: the placeholder sky has no SH to light it.
    let haze = if s.settings.haze.enabled && sky.enabled {
        let params = HazeParams::for_frame(cx, &s.settings);
        let frame = t.haze.record(
            g,
            &mut state.techniques.haze,
            cx,
            &s.settings.haze,
            &params,
            &HazeInputs {
                depth: gbuffer.depth,
                lit: lit_frame.radiance,
                lights: scene.lights,
                shadows: shadows.lookup,
                sky_ambient: sky.ambient,
                clouds: clouds.lookup,
                probes: probes.lookup,
            },
        )?;
        Some((params, frame))
    } else {
        None
    };
    let lit = lit_frame.radiance;
    let mut hazed = haze.as_ref().map_or(lit, |(_, h)| h.radiance);

    //     Particles: the emitters' sprites at the sky's clock, back to front, composited over
    //     the hazed image; the haze-lit ones take the haze's froxel light (the talk's "haze
    //     lighting" for particles).
    if s.settings.particles.enabled && !emitters.is_empty() {
        let sprites = particles::frame_sprites(emitters, cx);
        let haze_params = haze.as_ref().map(|(p, _)| p);
        let params = ParticleParams::for_frame(cx, &s.settings, sky.sky_lux, haze_params);
        hazed = t.particles.record(
            g,
            &mut state.techniques.particles,
            &view,
            &params,
            &sprites,
            gbuffer.depth,
            haze.as_ref().map(|(p, h)| (p, h.light)),
            hazed,
        )?;
    }

    // 12. TAA; below render scale 1, temporal upsampling to the output's size, which every
    //     step after this works at.
    let out_size = cx.output_size;
    let taa_settings = &s.settings.taa;
    let hdr = if size != out_size {
        let valid = history && taa_settings.enabled;
        t.taa
            .record_upsampled(
                g,
                hazed,
                gbuffer.motion,
                size,
                out_size,
                taa_settings,
                valid,
                cx.jitter,
            )?
            .output
    } else if taa_settings.enabled {
        t.taa
            .record(g, hazed, gbuffer.motion, size, taa_settings, history)?
            .output
    } else {
        hazed
    };
    let size = out_size;

    // 13. Exposure, metered on the illuminance; the local tonemap's grid; the tonemap: the local
    //     gain from that grid, Purkinje shift, white balance, the curve in the tonemapping
    //     space, LUT grade, dither.
    let exposure = t.exposure.record(
        g,
        hdr,
        lit_frame.illuminance,
        cx.size,
        &ExposureParams::new(&s.settings.exposure, sky.knobs.exposure_bias_ev, cx.ev100),
    )?;
    let local_tonemap = t.local_tonemap.record(
        g,
        hdr,
        exposure.value,
        size,
        &s.settings.local_tonemap,
        s.settings
            .local_tonemap
            .look_for(&s.settings.sky.weather, cx.sun_elevation_deg()),
    )?;
    let ldr = t.tonemap.record(
        g,
        &mut state.techniques.tonemap,
        &s.settings.tonemap,
        TonemapInputs {
            hdr,
            exposure: exposure.value,
            local: LocalGain::of(&local_tonemap),
        },
        size,
    )?;

    Ok(FrameOutputs {
        gbuffer,
        shadows,
        sky,
        clouds,
        probes,
        reflection_probes,
        area_lights,
        area_lights_unshadowed: area_frame.unshadowed,
        area_lights_denoised,
        ray_traced_gi,
        denoised_gi,
        ray_traced_gi_rays,
        haze: haze.map(|(_, h)| h),
        hdr,
        lit,
        illuminance: lit_frame.illuminance,
        exposure,
        local_tonemap,
        ldr,
    })
}
