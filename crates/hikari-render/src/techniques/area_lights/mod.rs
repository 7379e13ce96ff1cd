//! Polygonal area lights with ray-traced soft shadows, and the ray-traced shadows of point
//! and spot lights (docs/area-lights.md). One pass, `area_lights.shade`, writes
//! `area_lights.radiance` (nits) and the same light unshadowed (`area_lights.unshadowed`)
//! before the deferred lighting, which adds the first, or the shadow denoiser's output
//! ([`denoise`], `area_lights.denoised`) with `denoise` on. CPU twin: [`reference`].

pub mod denoise;
pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use naga_oil::compose::ShaderDefValue;

pub use crate::lights::polygon::{AreaLightGpu, AreaTriangleGpu, PolygonLights};
pub use crate::lights::tables::{AreaLightScene, shadow_casters};
pub use denoise::{DenoisedShadows, ShadowDenoiseInputs, ShadowDenoiseParams, ShadowDenoiser};
pub use settings::AreaLightsSettings;

use super::gbuffer::GBuffer;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{BindingSet, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::lights::RADIANCE_FORMAT;
use crate::pipeline::ComputePipeline;
use crate::scene::bvh_trace::BvhBuffers;
use crate::scene::upload::SceneInFrame;
use crate::shader::ShaderLibrary;
use crate::view::View;

// The shader keeps its picks in arrays of its per-pixel length.
const _: () = assert!(settings::MAX_SHADOW_PICKS == settings::MAX_LIGHTS_PER_PIXEL);

/// [`AreaLightParams::config`] `.y` bit: shade the polygonal lights.
pub const AREA_POLYGONS: u32 = 1;
/// [`AreaLightParams::config`] `.y` bit: shade point and spot lights, with shadows.
pub const AREA_PUNCTUAL: u32 = 2;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct AreaLightParams {
    /// Area lights, `AREA_*` flags, frame index, point and spot lights.
    pub config: [u32; 4],
    /// Shadow rays per pixel in all (the budget), area lights per pixel, lights picked for
    /// those rays per pixel (min(budget, [`settings::MAX_SHADOW_PICKS`])), 0.
    pub counts: [u32; 4],
    /// Minimum flux (lm), point and spot radius (m) where a light has none of its own, point
    /// and spot cut-off (lux), 0.
    pub values: [f32; 4],
    /// xy: the frame's random rotation of the sample pattern, in [0, 1).
    pub rotation: [f32; 4],
}

impl AreaLightParams {
    /// `cutoff_lux`: the frame context's point and spot light cut-off, the deferred
    /// lighting's too.
    /// This frame's parameters for `area_lights` polygonal lights in the scene, with the
    /// frame context's point and spot lights and cut-off.
    pub fn for_frame(
        cx: &crate::frame_context::FrameContext,
        s: &AreaLightsSettings,
        area_lights: u32,
    ) -> Self {
        Self::new(
            s,
            area_lights,
            cx.punctual_lights,
            cx.light_cutoff_lux,
            cx.frame_index,
        )
    }

    pub fn new(
        s: &AreaLightsSettings,
        area_lights: u32,
        punctual_lights: u32,
        cutoff_lux: f32,
        frame: u64,
    ) -> Self {
        let mut flags = 0;
        if s.enabled && area_lights > 0 {
            flags |= AREA_POLYGONS;
        }
        if s.enabled && s.punctual_shadows && punctual_lights > 0 {
            flags |= AREA_PUNCTUAL;
        }
        Self {
            config: [area_lights, flags, frame as u32, punctual_lights],
            counts: [
                s.ray_budget,
                s.lights_per_pixel,
                s.ray_budget.min(settings::MAX_SHADOW_PICKS),
                0,
            ],
            values: [s.min_flux_lm, s.punctual_radius_m, cutoff_lux, 0.0],
            rotation: frame_rotation(frame),
        }
    }

    /// Whether this pass shades any light this frame (else it writes zeros, which the shadow
    /// denoiser need not see).
    pub fn shades_any(&self) -> bool {
        self.config[1] != 0
    }

    /// Whether this pass shades the point and spot lights (the deferred lighting must then
    /// leave them out).
    pub fn shades_punctual(&self) -> bool {
        self.config[1] & AREA_PUNCTUAL != 0
    }

    /// Shadow rays of pick `s` (of `counts.z`): the budget split as evenly as it goes, the
    /// first picks taking the remainder. Returns (first ray's index in the pixel, rays).
    pub fn pick_rays(&self, s: u32) -> (u32, u32) {
        let (budget, picks) = (self.counts[0], self.counts[2]);
        if picks == 0 {
            return (0, 0);
        }
        let (each, extra) = (budget / picks, budget % picks);
        (s * each + s.min(extra), each + (s < extra) as u32)
    }
}

/// One random rotation of the sample pattern per frame, shared by all pixels (a hash of the
/// frame index; frame 0 is not rotated, so single renders are repeatable).
pub fn frame_rotation(frame: u64) -> [f32; 4] {
    if frame == 0 {
        return [0.0; 4];
    }
    let mut rng = hikari_math::sampling::rng::SplitMix64::stream(frame, "area_lights");
    [rng.next_f32(), rng.next_f32(), 0.0, 0.0]
}

pub struct AreaLights {
    shade: ComputePipeline,
    pub denoiser: ShadowDenoiser,
}

/// What `area_lights.shade` writes.
#[derive(Clone, Copy, Debug)]
pub struct AreaLightsFrame {
    /// `area_lights.radiance`: shadowed, nits (rgb) and lux (a).
    pub radiance: Tex,
    /// `area_lights.unshadowed`: the same lights in closed form without shadows.
    pub unshadowed: Tex,
}

impl AreaLights {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            shade: ComputePipeline::new(
                ctx,
                lib,
                "area_lights/shade.wgsl",
                "main",
                &[("BVH_ALPHA", ShaderDefValue::Bool(true))],
            )?,
            denoiser: ShadowDenoiser::new(ctx, lib)?,
        })
    }

    /// `area_lights.radiance`: the area lights' light, and the point and spot lights' when
    /// `params` says so, in nits (rgb), and the illuminance in lux they bring to the surface,
    /// shadowed (a: what the deferred lighting's illuminance for the exposure meter lacks);
    /// zero where the pass is off and on the sky; and `area_lights.unshadowed`, the same
    /// without shadows. `bvh`: the frame's shadow TLAS (`SceneRtBuffers::shadow`).
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        area: &'r AreaLightScene,
        bvh: &BvhBuffers,
        gb: &GBuffer,
        brdf_tables: BindingSet,
        scene: &SceneInFrame,
        view: &View,
        params: &AreaLightParams,
    ) -> Result<AreaLightsFrame> {
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let radiance = g.texture(
            "area_lights.radiance",
            TextureDesc::d2(w, h, RADIANCE_FORMAT),
        )?;
        let unshadowed = g.texture(
            "area_lights.unshadowed",
            TextureDesc::d2(w, h, RADIANCE_FORMAT),
        )?;
        let bvh = bvh.binding_set(g);
        let (lights, triangles) = area.import(g);
        let uvs = area.import_uvs(g);
        g.pass("area_lights.shade")
            .constants(view)
            .constants(params)
            .read(gb.depth)
            .read(gb.normal)
            .read(gb.albedo)
            .read(gb.material)
            .read(lights)
            .read(triangles)
            .read(scene.lights)
            .write(radiance)
            .write(unshadowed)
            .read(uvs)
            .read(scene.materials)
            .read(scene.color_textures)
            .sampler(SamplerKind::LinearRepeat)
            .read(gb.emissive)
            .set(brdf_tables)
            .set(bvh)
            .dispatch_threads(&self.shade, [w, h, 1])?;
        Ok(AreaLightsFrame {
            radiance,
            unshadowed,
        })
    }
}
