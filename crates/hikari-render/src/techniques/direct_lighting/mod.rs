//! Deferred direct lighting: sun with cascaded shadows, point and spot lights, emissive
//! surfaces, and placeholder sky and ambient light. CPU twin:
//! [`crate::techniques::direct_lighting::reference`].

pub mod reference;
pub mod settings;

use super::sky::{PLACEHOLDER_SKY_HORIZON, PLACEHOLDER_SKY_ZENITH};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use hikari_scene::Sun;

use super::clouds::CloudsFrame;
use super::gbuffer::GBuffer;
use super::irradiance_probes::ProbesFrame;
use super::reflection_probes::{ReflectionLookup, ReflectionProbeParams};
use super::sky::SkyFrame;
use super::sun_shadows::SunShadowMaps;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{BindingSet, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::scene::upload::SceneInFrame;
use crate::settings::DirectLightingSettings;
use crate::shader::ShaderLibrary;
use crate::view::View;

pub use crate::lights::RADIANCE_FORMAT;

pub const LIGHTING_SUN: u32 = 1;
pub const LIGHTING_PUNCTUAL: u32 = 2;
pub const LIGHTING_EMISSIVE: u32 = 4;
pub const LIGHTING_PLACEHOLDER_AMBIENT: u32 = 8;
/// The sky (`hikari::sky`) where depth is 0 and its SH (`hikari::sky_ambient`) as ambient light.
pub const LIGHTING_SKY: u32 = 16;
/// With `LIGHTING_SKY`: ambient diffuse from the irradiance probes where they cover a surface.
pub const LIGHTING_PROBES: u32 = 32;
/// Ambient light from the ray-traced GI within the near field (`cutoff.y` metres), blended
/// into the probes' or the sky's over the last `cutoff.z` of it; AO darkens the far field.
pub const LIGHTING_RTGI: u32 = 64;
/// Indirect specular from the relit reflection probes where they cover a surface.
pub const LIGHTING_REFLECTION_PROBES: u32 = 128;

pub use crate::techniques::ray_traced_gi::GiLight;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightingParams {
    pub direction_lux: [f32; 4],
    pub color: [f32; 4],
    pub sky_zenith: [f32; 4],
    pub sky_horizon: [f32; 4],
    /// Number of lights, `LIGHTING_*` flags, 0, 0.
    pub config: [u32; 4],
    /// x: illuminance in lux below which a punctual light is cut off this frame; y: the
    /// ray-traced GI's near field in metres; z: the fraction of it over which the GI blends
    /// into the far field; w unused.
    pub cutoff: [f32; 4],
    /// The reflection probes: probes, roughness levels, `RP_*` flags (0: none), 0.
    pub reflection: [u32; 4],
    /// x: their normalisation's largest ratio.
    pub reflection_values: [f32; 4],
}

impl LightingParams {
    /// `cutoff_lux`: the frame context's point and spot light cut-off
    /// ([`crate::frame_context::FrameContext::light_cutoff_lux`]).
    pub fn new(
        sun: Option<&Sun>,
        light_count: u32,
        cutoff_lux: f32,
        s: &DirectLightingSettings,
    ) -> Self {
        let (dir, lux, color) = match sun {
            Some(s) => (s.direction.normalize(), s.illuminance_lux, s.color),
            None => (Vec3::Y, 0.0, Vec3::ONE),
        };
        let sky = lux / Sun::DEFAULT_LUX;
        let flags = [
            (s.sun, LIGHTING_SUN),
            (s.punctual, LIGHTING_PUNCTUAL),
            (s.emissive, LIGHTING_EMISSIVE),
            (s.placeholder_ambient, LIGHTING_PLACEHOLDER_AMBIENT),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |acc, (_, bit)| acc | bit);
        Self {
            direction_lux: dir.extend(lux).to_array(),
            color: color.extend(1.0).to_array(),
            sky_zenith: (PLACEHOLDER_SKY_ZENITH * sky).extend(0.0).to_array(),
            sky_horizon: (PLACEHOLDER_SKY_HORIZON * sky).extend(0.0).to_array(),
            config: [light_count, flags, 0, 0],
            cutoff: [cutoff_lux, 0.0, 0.0, 0.0],
            reflection: [0; 4],
            reflection_values: [0.0; 4],
        }
    }
}

impl LightingParams {
    /// Leaves the point and spot lights out (another pass shades them, with shadows).
    /// Ambient light from the ray-traced GI within `near_field_m` of the camera, blended into
    /// the far field's (probes or sky) over the last `blend` fraction of it.
    /// This frame's parameters: the frame context's sun, lights and cut-off with the sky (on
    /// when `sky_enabled`), the irradiance probes (`probes_present`), the reflection probes'
    /// lookup `reflection`, the ray-traced GI (`gi`), and the punctual lights left to the area
    /// lights' pass when `area` shades them.
    pub fn for_frame(
        cx: &crate::frame_context::FrameContext,
        s: &crate::settings::Settings,
        sky_enabled: bool,
        probes_present: bool,
        reflection: &ReflectionProbeParams,
        gi: bool,
        area: &crate::techniques::area_lights::AreaLightParams,
    ) -> Self {
        let mut p = Self::new(
            cx.sun.as_ref(),
            cx.punctual_lights,
            cx.light_cutoff_lux,
            &s.direct_lighting,
        );
        if sky_enabled {
            p.use_sky(s.sky.sky);
        }
        p.use_probes(probes_present);
        p.use_reflection_probes(reflection);
        if gi {
            p.use_ray_traced_gi(
                s.ray_traced_gi.near_field_m,
                s.ray_traced_gi.near_field_blend,
            );
        }
        if area.shades_punctual() {
            p.skip_punctual();
        }
        p
    }

    pub fn use_ray_traced_gi(&mut self, near_field_m: f32, blend: f32) {
        self.config[1] |= LIGHTING_RTGI;
        self.cutoff[1] = near_field_m;
        self.cutoff[2] = blend.clamp(1e-3, 1.0);
    }

    pub fn skip_punctual(&mut self) {
        self.config[1] &= !LIGHTING_PUNCTUAL;
    }

    /// Lights with the atmosphere instead of the placeholders: the sky and its SH ambient
    /// when `sky_light`, else a black sky and no ambient.
    pub fn use_sky(&mut self, sky_light: bool) {
        self.config[1] &= !LIGHTING_PLACEHOLDER_AMBIENT;
        if sky_light {
            self.config[1] |= LIGHTING_SKY;
        }
    }

    /// Takes the indirect specular light from the reflection probes where they cover a surface
    /// (`p`'s `RP_ON` flag).
    pub fn use_reflection_probes(&mut self, p: &ReflectionProbeParams) {
        if p.config[2] & super::reflection_probes::RP_ON != 0 {
            self.config[1] |= LIGHTING_REFLECTION_PROBES;
        }
        self.reflection = p.config;
        self.reflection_values = p.values;
    }

    /// Takes the ambient diffuse light from the irradiance probes when `present`.
    pub fn use_probes(&mut self, present: bool) {
        if present {
            self.config[1] |= LIGHTING_PROBES;
        } else {
            self.config[1] &= !LIGHTING_PROBES;
        }
    }
}

/// What the lighting pass writes.
#[derive(Clone, Copy, Debug)]
pub struct LitFrame {
    /// `direct_lighting.radiance`: nits, Rgba16Float.
    pub radiance: Tex,
    /// `direct_lighting.illuminance`: lux arriving at each surface pixel from the sun, lights
    /// and ambient light (not its own emission), -1 on the sky; R32Float. The exposure meters it.
    pub illuminance: Tex,
}

pub struct DirectLighting {
    shade: ComputePipeline,
}

impl DirectLighting {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            shade: ComputePipeline::new(ctx, lib, "direct_lighting/shade.wgsl", "main", &[])?,
        })
    }

    /// Radiance in nits of every pixel: lit surfaces, or the sky (or the placeholder sky)
    /// where depth is 0, and the illuminance at every surface pixel. `area_lights`
    /// (`area_lights.radiance`: nits, alpha its lux) is added on surfaces; when that pass shades
    /// the point and spot lights, clear `LIGHTING_PUNCTUAL` in `params`
    /// ([`LightingParams::skip_punctual`]).
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        gb: &GBuffer,
        shadows: &SunShadowMaps,
        sky: &SkyFrame,
        clouds: &CloudsFrame,
        probes: &ProbesFrame,
        brdf_tables: BindingSet,
        scene: &SceneInFrame,
        view: &View,
        params: &LightingParams,
        area_lights: Tex,
        gi: Option<&GiLight>,
        reflection_probes: &ReflectionLookup,
    ) -> Result<LitFrame> {
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let radiance = g.texture(
            "direct_lighting.radiance",
            TextureDesc::d2(w, h, RADIANCE_FORMAT),
        )?;
        let illuminance = g.texture(
            "direct_lighting.illuminance",
            TextureDesc::d2(w, h, wgpu::TextureFormat::R32Float),
        )?;
        g.pass("direct_lighting.shade")
            .constants(view)
            .constants(params)
            .read(gb.depth)
            .read(gb.normal)
            .read(gb.albedo)
            .read(gb.material)
            .read(gb.emissive)
            .read(scene.lights)
            .write(radiance)
            .write(illuminance)
            .read(area_lights)
            // Without GI the shader reads none of these: any float texture fills the slots.
            .read(gi.map_or(gb.normal, |g| g.y))
            .read(gi.map_or(gb.normal, |g| g.cocg))
            .read(gi.map_or(gb.normal, |g| g.ao))
            .read(gb.vertex_normal)
            .read(reflection_probes.probes)
            .read(reflection_probes.radiance)
            .sampler(SamplerKind::LinearClamp)
            .read(reflection_probes.capture_light)
            .set(shadows.lookup)
            .set(sky.lookup)
            .set(sky.ambient)
            .set(clouds.lookup)
            .set(probes.lookup)
            .set(brdf_tables)
            .dispatch_threads(&self.shade, [w, h, 1])?;
        Ok(LitFrame {
            radiance,
            illuminance,
        })
    }
}
