//! Ray-traced diffuse GI and AO at one ray a pixel (Metro Exodus, GDC 2019): the ray of each
//! pixel from a 64x64x64 blue-noise set, a screen-space pre-trace against the depth buffer,
//! the rays it cannot resolve traced through the scene's BVH, the hits lit in a pass of their
//! own, the result encoded as luminance L1 SH + CoCg and accumulated over frames. The output,
//! [`RtGiFrame`], is what the denoiser (`gi_denoiser`) reads. Passes, in order:
//!
//! | pass | does | writes |
//! |---|---|---|
//! | `ray_traced_gi.clear` | empties the BVH queue | `ray_traced_gi.queue` |
//! | `ray_traced_gi.pretrace` | screen-space march | `ray_traced_gi.hits` (one word a pixel), `.hit_instances`, `.hit_normals`, the queue |
//! | `ray_traced_gi.trace` | BVH closest hit of the queued rays | the same three |
//! | `ray_traced_gi.shade` | lights hits (sun, sky, point, spot and area lights, shadowed), sky for misses, caps the radiance relative to last frame's exposure, encodes | `ray_traced_gi.raw_y`, `ray_traced_gi.raw_cocg_ao`, `ray_traced_gi.hit_distance` |
//! | `ray_traced_gi.accumulate` | temporal accumulation | `ray_traced_gi.gi_y`, `.gi_cocg`, `.ao`, `.history_length`, `.view_depth` |
//!
//! Every texture above can be dumped by that name. The hit word packs the distance (f16, bits
//! 0-15) and the hit's albedo (√albedo as R5G6B5, bits 16-31); see [`reference::pack_hit`].
//! The hit's normal is a word of its own ([`reference::pack_normal`]).
//! CPU twins: [`reference`]. Documentation: docs/ray-traced-gi.md.

pub mod instance_albedo;
pub mod reference;
pub mod settings;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_math::sampling::blue_noise::BLUE_NOISE_64X64X64;
use hikari_scene::{Scene, Sun};
use naga_oil::compose::ShaderDefValue;
use wgpu::util::DeviceExt;

use super::gbuffer::GBuffer;
use super::sky::SkyFrame;
use super::sky::{PLACEHOLDER_SKY_HORIZON, PLACEHOLDER_SKY_ZENITH};
use super::sun_shadows::SunShadowMaps;
use crate::context::GpuContext;
use crate::error::Result;
use crate::frame_context::{FrameContext, PreviousExposure};
use crate::graph::{BindingSet, Buf, FrameGraph, Tex, TextureDesc};
use crate::lights::AreaLightScene;
use crate::pipeline::ComputePipeline;
use crate::scene::bvh_trace::BvhBuffers;
use crate::shader::ShaderLibrary;
use crate::view::View;
pub use settings::RayTracedGiSettings;

/// The ray-traced GI signal the deferred lighting resolves (denoised, or accumulated when the
/// denoiser is off): luminance L1 SH (Rgba16Float), CoCg (Rg16Float) and AO (R16Float).
#[derive(Clone, Copy, Debug)]
pub struct GiLight {
    pub y: Tex,
    pub cocg: Tex,
    pub ao: Tex,
}

/// Last frame's denoised output (the GI denoiser's), for a recurrent accumulation (see
/// `GiDenoiser::recurrent_history`, which fills it): `(textures, valid)`, `None` where that
/// part is not kept.
#[derive(Clone, Copy, Debug, Default)]
pub struct RecurrentHistory {
    /// Y (Rgba16Float) and CoCg (Rg16Float).
    pub gi: Option<([Tex; 2], bool)>,
    /// R16Float.
    pub ao: Option<(Tex, bool)>,
}

/// The ray-traced GI signal of a frame (interfaces.md), all full resolution.
#[derive(Clone, Copy, Debug)]
pub struct RtGiFrame {
    /// Rgba16Float: luminance as L1 SH (c0, y, z, x), `ShL1YCoCg`'s normalisation.
    pub gi_y: Tex,
    /// Rg16Float: mean (Co, Cg).
    pub gi_cocg: Tex,
    /// R16Float: frames in the history (1 fresh; 0 where there is no surface).
    pub history_length: Tex,
    /// R16Float: ambient occlusion, 1 open.
    pub ao: Tex,
    /// R16Float: this frame's hit distance in metres, 0 for no hit or not traced.
    pub hit_distance: Tex,
}

/// The frame's ray buffers, for statistics and tests: one hit word a pixel, the scene
/// instance each hit is on (`u32::MAX`: none), and the BVH queue (word 0: rays the pre-trace
/// left; then their pixel indices).
#[derive(Clone, Copy, Debug)]
pub struct RtGiRays {
    pub hits: Buf,
    pub hit_instances: Buf,
    /// Each hit's normal ([`reference::pack_normal`]; 0: none).
    pub hit_normals: Buf,
    pub queue: Buf,
}

pub const FLAG_PRETRACE: u32 = 1;
pub const FLAG_BVH: u32 = 2;
pub const FLAG_SUN: u32 = 4;
/// Misses take the atmosphere's sky (`hikari::sky`).
pub const FLAG_SKY: u32 = 8;
/// Misses take the placeholder sky (the atmosphere is off).
pub const FLAG_PLACEHOLDER_SKY: u32 = 16;
pub const FLAG_PUNCTUAL: u32 = 32;
pub const FLAG_ACCUMULATE: u32 = 64;
/// Drop the history this frame (camera cut).
pub const FLAG_RESET: u32 = 128;
/// Hits are lit by the sky's ambient light (or the placeholder's).
pub const FLAG_SKY_AMBIENT: u32 = 256;
/// The sun's shadow at hits from its shadow maps inside a cascade (else a shadow ray).
pub const FLAG_SHADOW_MAPS: u32 = 512;
/// Hits visible last frame take last frame's lit image there.
pub const FLAG_REUSE_LIT: u32 = 1024;
/// Hits are lit by the area lights (shadowed by one ray to one light).
pub const FLAG_AREA: u32 = 2048;
/// The point and spot lights' light at hits is shadowed (one ray to one light).
pub const FLAG_PUNCTUAL_SHADOWS: u32 = 4096;

/// Uniform of every ray-traced GI pass (`RtGiParams` in `rtgi.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RtGiParams {
    /// Frame index, `FLAG_*`, history length cap, light count.
    pub config: [u32; 4],
    /// GI ray length (m), AO distance (m), history depth tolerance, light cut-off (lux).
    pub distances: [f32; 4],
    /// Pre-trace step (px), steps at most, thickness (fraction of view depth), length (m).
    pub pretrace: [f32; 4],
    /// Unit vector towards the sun or moon; illuminance in lux.
    pub sun: [f32; 4],
    /// Its colour (luminance 1).
    pub sun_color: [f32; 4],
    /// Placeholder sky radiance in nits at the zenith and the horizon.
    pub sky_zenith: [f32; 4],
    pub sky_horizon: [f32; 4],
    /// Lights at hits: the area lights (a count), their minimum flux (lm), the illuminance (lux)
    /// below which a local light's shadow ray plays Russian roulette (0: never), the radius (m)
    /// of point and spot lights without their own (`area_lights.punctual_radius_m`).
    pub area: [f32; 4],
    /// The accumulation's firefly clamp ([`reference::FireflyClamp`]): k (0: off), the floor
    /// (SH c0 units), the history length from which it applies; w unused.
    pub firefly: [f32; 4],
    /// The cap on each sample's radiance ([`reference::hit_radiance_cap_nits`]): x: times the
    /// radiance that maps to display white (0: off), y: the CPU meter's EV100 (kept for the
    /// twin tests; a first frame is not capped), z: 1 when `exposure.state` holds last frame's
    /// exposure (set by [`RayTracedGi::record_raw`]; 0: no cap), w unused.
    pub exposure: [f32; 4],
}

/// Where the sky for misses and ambient light comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkySource {
    /// The atmosphere (`hikari::sky`, `hikari::sky_ambient`).
    Atmosphere,
    /// The placeholder gradient of direct lighting (atmosphere off).
    Placeholder,
    /// Black (the sky's light is off).
    None,
}

impl RtGiParams {
    /// `metered_lux` and `cutoff_lux`: the frame context's metered illuminance and point and
    /// spot light cut-off.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        s: &RayTracedGiSettings,
        frame: u64,
        sun: Option<&Sun>,
        light_count: u32,
        metered_lux: f32,
        cutoff_lux: f32,
        sky: SkySource,
    ) -> Self {
        let (dir, lux, color) = match sun {
            Some(s) => (s.direction.normalize(), s.illuminance_lux, s.color),
            None => (Vec3::Y, 0.0, Vec3::ONE),
        };
        let sky_scale = lux / Sun::DEFAULT_LUX;
        let mut flags = [
            (s.pretrace, FLAG_PRETRACE),
            (s.bvh_trace, FLAG_BVH),
            (s.sun, FLAG_SUN),
            (s.punctual, FLAG_PUNCTUAL),
            (s.accumulate, FLAG_ACCUMULATE),
            (s.sky, FLAG_SKY_AMBIENT),
            (s.shadow_maps, FLAG_SHADOW_MAPS),
            (s.reuse_lit, FLAG_REUSE_LIT),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |acc, (_, bit)| acc | bit);
        flags |= match sky {
            SkySource::Atmosphere => FLAG_SKY,
            SkySource::Placeholder => FLAG_PLACEHOLDER_SKY,
            SkySource::None => 0,
        };
        Self {
            config: [frame as u32, flags, s.max_history, light_count],
            distances: [
                s.max_distance_m,
                s.ao_max_distance_m,
                s.depth_tolerance,
                cutoff_lux,
            ],
            pretrace: [
                s.pretrace_step_px,
                s.pretrace_max_steps as f32,
                s.pretrace_thickness,
                s.pretrace_max_distance_m,
            ],
            sun: dir.extend(lux).to_array(),
            sun_color: color.extend(1.0).to_array(),
            sky_zenith: (PLACEHOLDER_SKY_ZENITH * sky_scale).extend(0.0).to_array(),
            sky_horizon: (PLACEHOLDER_SKY_HORIZON * sky_scale).extend(0.0).to_array(),
            area: [0.0, 0.0, s.hit_shadow_roulette * metered_lux.max(0.0), 0.0],
            firefly: reference::FireflyClamp::new(s.firefly_clamp, metered_lux).to_array(),
            // The CPU meter's EV100 of `metered_lux` (`FrameSettings::ev100_with_sky`, whose
            // illuminance this is): what a frame without last frame's exposure is capped by.
            exposure: [
                s.hit_radiance_cap.max(0.0),
                reference::cpu_meter_ev100(metered_lux),
                0.0,
                0.0,
            ],
        }
    }

    /// The frame's area lights and shadows at hits, as the area-light pass has them: its
    /// `area_lights` lights of at least `min_flux_lm` (or flagged) light hits when the pass is
    /// `enabled`, and the point and spot lights' light at hits is shadowed when it shadows
    /// them (`punctual_shadows`).
    /// This frame's parameters: the frame context's sun, lights, meter and cut-off, the sky
    /// the misses see (`sky_enabled`: the atmosphere is on this frame), and the lights hits
    /// are lit by (`area_lights` polygonal lights in the scene).
    pub fn for_frame(
        cx: &FrameContext,
        s: &crate::settings::Settings,
        sky_enabled: bool,
        area_lights: u32,
    ) -> Self {
        let sky = match (sky_enabled, s.sky.sky) {
            (true, true) => SkySource::Atmosphere,
            (true, false) => SkySource::None,
            (false, _) if s.direct_lighting.placeholder_ambient => SkySource::Placeholder,
            (false, _) => SkySource::None,
        };
        let a = &s.area_lights;
        Self::new(
            &s.ray_traced_gi,
            cx.frame_index,
            cx.sun.as_ref(),
            cx.punctual_lights,
            cx.metered_lux,
            cx.light_cutoff_lux,
            sky,
        )
        .with_hit_lights(
            a.enabled,
            area_lights,
            a.min_flux_lm,
            a.punctual_shadows,
            a.punctual_radius_m,
        )
    }

    pub fn with_hit_lights(
        mut self,
        enabled: bool,
        area_lights: u32,
        min_flux_lm: f32,
        punctual_shadows: bool,
        punctual_radius_m: f32,
    ) -> Self {
        self.set_flag(FLAG_AREA, enabled && area_lights > 0);
        self.set_flag(FLAG_PUNCTUAL_SHADOWS, enabled && punctual_shadows);
        self.area = [
            area_lights as f32,
            min_flux_lm,
            self.area[2],
            punctual_radius_m,
        ];
        self
    }

    pub fn flags(&self) -> u32 {
        self.config[1]
    }

    pub fn set_flag(&mut self, flag: u32, on: bool) {
        if on {
            self.config[1] |= flag;
        } else {
            self.config[1] &= !flag;
        }
    }
}

/// What the technique keeps of a scene besides the frame's BVH (`scene::rt::SceneRt`, which it
/// traces through [`RtGiInputs::bvh`]): the per-instance albedo table, on the GPU, and the
/// scene's point and spot lights, whose light grid [`RtGiState`] keeps.
pub struct RtGiScene {
    /// The scene's point and spot lights, for their reach ([`crate::lights::grid::punctual_records`]).
    punctual: Vec<crate::scene::upload::LightGpu>,
    /// [`reference::instance_table`].
    instance_table: wgpu::Buffer,
    /// [`reference::normal_tables`]: per instance, then per mesh triangle.
    instance_normals: wgpu::Buffer,
    triangle_normals: wgpu::Buffer,
    /// Per scene mesh, its first entry in `triangle_normals`.
    mesh_first: Vec<u32>,
}

/// What the GI keeps between frames in the renderer's frame state: the grid of light lists
/// that lights hits ([`crate::lights::grid`]), rebuilt when what it was built from changes.
#[derive(Clone, Debug, Default)]
pub struct RtGiState {
    light_grid: Option<LightGridGpu>,
}

/// The uploaded light grid and what it was built from.
#[derive(Clone, Debug)]
struct LightGridGpu {
    key: crate::lights::grid::LightGridKey,
    cells: wgpu::Buffer,
    indices: wgpu::Buffer,
    stats: LightGridStats,
}

/// What the last light grid built holds, for logs and the documentation's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightGridStats {
    pub cells: [u32; 3],
    /// Light indices over all cells.
    pub entries: usize,
    pub bytes: usize,
}

impl std::fmt::Debug for RtGiScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RtGiScene").finish_non_exhaustive()
    }
}

/// Zero-sized bindings are not allowed: an empty list is uploaded as one zeroed record.
fn non_empty<T: Pod + Zeroable>(v: &[T]) -> Vec<T> {
    if v.is_empty() {
        vec![T::zeroed()]
    } else {
        v.to_vec()
    }
}

impl RtGiScene {
    /// Uploads the per-instance table of `scene` (albedo, emission).
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<Self> {
        let table = non_empty(&reference::instance_table(scene));
        let (instance_normals, triangle_normals) = reference::normal_tables(scene);
        let mesh_first = scene
            .meshes
            .iter()
            .scan(0u32, |first, m| {
                let at = *first;
                *first += (m.indices.len() / 3) as u32;
                Some(at)
            })
            .collect();
        let triangle_normals = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("ray_traced_gi.triangle_normals"),
                contents: bytemuck::cast_slice(&non_empty(&triangle_normals)),
                // COPY_DST: a deforming mesh's entries follow its refitted BLAS.
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
            });
        Ok(Self {
            mesh_first,
            punctual: crate::lights::grid::punctual_records(scene),
            instance_table: ctx
                .storage_buffer("ray_traced_gi.instance_table", bytemuck::cast_slice(&table))?,
            instance_normals: ctx.storage_buffer(
                "ray_traced_gi.instance_normals",
                bytemuck::cast_slice(&non_empty(&instance_normals)),
            )?,
            triangle_normals,
        })
    }

    /// Rewrites the hit normals of scene mesh `mesh` of `scene` for `positions`, the pose its
    /// BLAS was just refitted to, so that hits on a deforming mesh are lit with the normal of
    /// the triangle the ray met. Returns the bytes written (0 for an unknown mesh).
    pub fn update_triangle_normals(
        &self,
        ctx: &GpuContext,
        scene: &Scene,
        mesh: usize,
        positions: &[Vec3],
    ) -> u64 {
        let (Some(&first), Some(m)) = (self.mesh_first.get(mesh), scene.meshes.get(mesh)) else {
            return 0;
        };
        let words: Vec<u32> = reference::triangle_normals(&m.indices, positions).collect();
        if words.is_empty() {
            return 0;
        }
        ctx.queue.write_buffer(
            &self.triangle_normals,
            4 * first as u64,
            bytemuck::cast_slice(&words),
        );
        4 * words.len() as u64
    }

    /// The normal tables in a frame (instances, triangles).
    fn import_normals(&self, g: &mut FrameGraph<'_>) -> (Buf, Buf) {
        (
            g.import_buffer("ray_traced_gi.instance_normals", &self.instance_normals),
            g.import_buffer("ray_traced_gi.triangle_normals", &self.triangle_normals),
        )
    }

    /// The per-instance table in a frame.
    pub fn import(&self, g: &mut FrameGraph<'_>) -> Buf {
        g.import_buffer("ray_traced_gi.instance_table", &self.instance_table)
    }
}

impl RtGiState {
    /// The light grid for `area`'s lights and the scene's point and spot lights at `params`'
    /// cut-off and minimum flux, in a frame (cells, indices): built and uploaded when the key
    /// changed, else the last one.
    fn import_light_grid(
        &mut self,
        scene: &RtGiScene,
        g: &mut FrameGraph<'_>,
        area: &AreaLightScene,
        params: &RtGiParams,
    ) -> Result<(Buf, Buf)> {
        let (min_flux, cutoff) = (params.area[1], params.distances[3]);
        let key = crate::lights::grid::LightGridKey::new(
            &area.lights.lights,
            &scene.punctual,
            min_flux,
            cutoff,
        );
        let slot = &mut self.light_grid;
        if slot.as_ref().map(|s| s.key) != Some(key) {
            let grid = crate::lights::grid::LightGrid::build(
                &area.lights.lights,
                &scene.punctual,
                min_flux,
                crate::lights::grid::grid_cutoff(cutoff),
            );
            let s = LightGridStats {
                cells: grid.dims(),
                entries: grid.entries(),
                bytes: grid.bytes(),
            };
            log::info!(
                "ray_traced_gi: light grid {:?} cells, {} entries, {} KiB",
                s.cells,
                s.entries,
                s.bytes / 1024
            );
            let ctx = g.ctx();
            *slot = Some(LightGridGpu {
                key,
                cells: ctx.storage_buffer(
                    "ray_traced_gi.light_grid",
                    bytemuck::cast_slice(&grid.cells),
                )?,
                indices: ctx.storage_buffer(
                    "ray_traced_gi.light_grid_indices",
                    bytemuck::cast_slice(&grid.indices),
                )?,
                stats: s,
            });
        }
        let grid = slot.as_ref().expect("set above");
        Ok((
            g.import_buffer("ray_traced_gi.light_grid", &grid.cells),
            g.import_buffer("ray_traced_gi.light_grid_indices", &grid.indices),
        ))
    }

    /// The stats of the light grid in use (built by the last frame), `None` before one.
    pub fn light_grid_stats(&self) -> Option<LightGridStats> {
        Some(self.light_grid.as_ref()?.stats)
    }
}

/// What the passes read of the frame.
#[derive(Clone, Copy)]
pub struct RtGiInputs<'a> {
    pub gbuffer: &'a GBuffer,
    pub sky: &'a SkyFrame,
    pub shadows: &'a SunShadowMaps,
    /// The clouds' binding set (`CloudsFrame::lookup`): misses see them over the sky, and
    /// they shadow the sun at hits.
    pub clouds: BindingSet,
    /// `SceneInFrame::lights`.
    pub lights: Buf,
    pub view: &'a View,
    pub params: &'a RtGiParams,
    /// The frame's scene BVH for GI rays (`SceneRtBuffers::gi`).
    pub bvh: BvhBuffers,
    /// The BVH that the shadow rays of hits trace (`SceneRtBuffers::shadow`: without the
    /// lamps' glowing shells, which stand for their point light's light passing through).
    pub shadow_bvh: BvhBuffers,
    /// The area lights that light hits (`RtGiParams::with_hit_lights`).
    pub area: &'a AreaLightScene,
    /// Last frame's exposure, which caps each sample's radiance (`hit_radiance_cap`).
    pub exposure: PreviousExposure,
    /// Last frame's denoised output where the denoiser is recurrent: the accumulation's
    /// history (`RecurrentHistory::default()`: its own).
    pub denoised_history: RecurrentHistory,
}

/// The raw (unaccumulated) signal of a frame.
#[derive(Clone, Copy, Debug)]
pub struct RtGiRaw {
    /// Rgba16Float: this frame's sample, luminance L1 SH.
    pub y: Tex,
    /// Rgba16Float: Co, Cg, AO, 0.
    pub cocg_ao: Tex,
    /// R16Float, metres.
    pub hit_distance: Tex,
    pub rays: RtGiRays,
}

pub struct RayTracedGi {
    clear: ComputePipeline,
    pretrace: ComputePipeline,
    trace: ComputePipeline,
    shade: ComputePipeline,
    accumulate: ComputePipeline,
    check: ComputePipeline,
    resolve_check: ComputePipeline,
    keep_lit: ComputePipeline,
    noise: wgpu::Buffer,
}

pub const Y_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const COCG_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;
pub const SCALAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;
pub const VIEW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

impl RayTracedGi {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let alpha = [("BVH_ALPHA", ShaderDefValue::Bool(true))];
        let p = |lib: &mut ShaderLibrary, path: &str, defs: &[(&str, ShaderDefValue)]| {
            ComputePipeline::new(ctx, lib, path, "main", defs)
        };
        Ok(Self {
            clear: p(lib, "ray_traced_gi/clear.wgsl", &[])?,
            pretrace: p(lib, "ray_traced_gi/pretrace.wgsl", &[])?,
            trace: p(lib, "ray_traced_gi/trace.wgsl", &alpha)?,
            shade: p(lib, "ray_traced_gi/shade.wgsl", &alpha)?,
            accumulate: p(lib, "ray_traced_gi/accumulate.wgsl", &[])?,
            check: p(lib, "ray_traced_gi/check.wgsl", &[])?,
            resolve_check: p(lib, "ray_traced_gi/resolve_check.wgsl", &[])?,
            keep_lit: p(lib, "ray_traced_gi/keep_lit.wgsl", &[])?,
            noise: ctx.storage_buffer("ray_traced_gi.blue_noise", &BLUE_NOISE_64X64X64[..])?,
        })
    }

    /// The binding set `rtgi_noise` of `hikari::ray_traced_gi`.
    pub fn noise_set(&self, g: &mut FrameGraph<'_>) -> BindingSet {
        let b = g.import_buffer("ray_traced_gi.blue_noise", &self.noise);
        g.binding_set("rtgi_noise").read(b).finish()
    }

    /// The whole technique: rays, pre-trace, BVH, lighting of hits, accumulation. `reset`
    /// drops the history (a camera cut); a resize drops it by itself.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut RtGiState,
        scene: &RtGiScene,
        inputs: &RtGiInputs<'_>,
        reset: bool,
    ) -> Result<(RtGiFrame, RtGiRays)> {
        let raw = self.record_raw(g, state, scene, inputs)?;
        let mut params = *inputs.params;
        if reset {
            params.set_flag(FLAG_RESET, true);
        }
        let gb = inputs.gbuffer;
        let frame = self.record_accumulate_onto(
            g,
            inputs.view,
            &params,
            [gb.depth, gb.motion],
            [raw.y, raw.cocg_ao, raw.hit_distance],
            &inputs.denoised_history,
        )?;
        Ok((frame, raw.rays))
    }

    /// Rays, pre-trace, BVH and the lighting of hits: this frame's raw sample a pixel.
    pub fn record_raw<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut RtGiState,
        scene: &RtGiScene,
        inputs: &RtGiInputs<'_>,
    ) -> Result<RtGiRaw> {
        let [w, h] = [
            inputs.view.viewport[0] as u32,
            inputs.view.viewport[1] as u32,
        ];
        let pixels = w as u64 * h as u64;
        let gb = inputs.gbuffer;
        let view = inputs.view;
        let params = inputs.params;
        let hits = g.buffer("ray_traced_gi.hits", pixels * 4)?;
        let hit_instances = g.buffer("ray_traced_gi.hit_instances", pixels * 4)?;
        let hit_normals = g.buffer("ray_traced_gi.hit_normals", pixels * 4)?;
        let queue = g.buffer("ray_traced_gi.queue", (pixels + 1) * 4)?;
        let (bvh, table) = (inputs.bvh, scene.import(g));

        g.pass("ray_traced_gi.clear")
            .write(queue)
            .dispatch(&self.clear, [1, 1, 1])?;

        let noise = self.noise_set(g);
        g.pass("ray_traced_gi.pretrace")
            .constants(view)
            .constants(params)
            .read(gb.depth)
            .read(gb.normal)
            .read(gb.albedo)
            .read(gb.material)
            .read(gb.motion)
            .read(gb.instance)
            .write(hits)
            .write(hit_instances)
            .write(queue)
            .write(hit_normals)
            .set(noise)
            .dispatch_threads(&self.pretrace, [w, h, 1])?;

        if params.flags() & FLAG_BVH != 0 {
            let noise = self.noise_set(g);
            let bvh_set = bvh.binding_set(g);
            // 64 invocations of 8 rays each a workgroup (trace.wgsl).
            let total = pixels.div_ceil(64 * 8).max(1);
            let max = g.ctx().limits.max_compute_workgroups_per_dimension.max(1) as u64;
            let gy = total.div_ceil(max);
            let gx = total.div_ceil(gy);
            let (instance_normals, triangle_normals) = scene.import_normals(g);
            g.pass("ray_traced_gi.trace")
                .constants(view)
                .constants(params)
                .read(gb.depth)
                .read(gb.normal)
                .read(queue)
                .write(hits)
                .write(hit_instances)
                .read(table)
                .write(hit_normals)
                .read(instance_normals)
                .read(triangle_normals)
                .set(noise)
                .set(bvh_set)
                .dispatch(&self.trace, [gx as u32, gy as u32, 1])?;
        }

        let tex = |g: &mut FrameGraph<'r>, name: &str, format| {
            g.texture(name, TextureDesc::d2(w, h, format))
        };
        let raw_y = tex(g, "ray_traced_gi.raw_y", Y_FORMAT)?;
        let raw_cocg_ao = tex(g, "ray_traced_gi.raw_cocg_ao", Y_FORMAT)?;
        let hit_distance = tex(g, "ray_traced_gi.hit_distance", SCALAR_FORMAT)?;
        // Last frame's lit image and view depth (zeros, and not used, on a first frame).
        let lit = g.history_texture("ray_traced_gi.lit", TextureDesc::d2(w, h, Y_FORMAT))?;
        let vz = g.history_texture(
            "ray_traced_gi.view_depth",
            TextureDesc::d2(w, h, VIEW_DEPTH_FORMAT),
        )?;
        let mut params = *params;
        if !(lit.valid && vz.valid) {
            params.set_flag(FLAG_REUSE_LIT, false);
        }
        params.exposure[2] = if inputs.exposure.valid { 1.0 } else { 0.0 };
        let params = &params;
        let noise = self.noise_set(g);
        let bvh_set = inputs.shadow_bvh.binding_set(g);
        let (area_lights, area_triangles) = inputs.area.import(g);
        let (grid_cells, grid_indices) = state.import_light_grid(scene, g, inputs.area, params)?;
        g.pass("ray_traced_gi.shade")
            .constants(view)
            .constants(params)
            .read(gb.depth)
            .read(gb.normal)
            .read(hits)
            .read(hit_instances)
            .read(table)
            .read(inputs.lights)
            .write(raw_y)
            .write(raw_cocg_ao)
            .write(hit_distance)
            .read(lit.prev)
            .read(vz.prev)
            .read(gb.instance)
            .read(area_lights)
            .read(area_triangles)
            .read(hit_normals)
            .read(grid_cells)
            .read(grid_indices)
            .read(inputs.exposure.state)
            .set(noise)
            .set(bvh_set)
            .set(inputs.sky.lookup)
            .set(inputs.sky.ambient)
            .set(inputs.shadows.lookup)
            .set(inputs.clouds)
            .dispatch_threads(&self.shade, [w, h, 1])?;
        Ok(RtGiRaw {
            y: raw_y,
            cocg_ao: raw_cocg_ao,
            hit_distance,
            rays: RtGiRays {
                hits,
                hit_instances,
                hit_normals,
                queue,
            },
        })
    }

    /// Keeps the frame's lit image (`direct_lighting.radiance`) for the next frame's lighting
    /// of hits (`reuse_lit`); call after the deferred lighting.
    pub fn keep_lit<'r>(&'r self, g: &mut FrameGraph<'r>, lit: Tex, size: [u32; 2]) -> Result<()> {
        let hist = g.history_texture(
            "ray_traced_gi.lit",
            TextureDesc::d2(size[0], size[1], Y_FORMAT),
        )?;
        g.pass("ray_traced_gi.keep_lit")
            .read(lit)
            .write(hist.cur)
            .dispatch_threads(&self.keep_lit, [size[0], size[1], 1])
    }

    /// Temporal accumulation of a raw signal (`raw_y`: Rgba16Float L1 SH; `raw_cocg_ao`:
    /// Rgba16Float Co, Cg, AO) against the history kept under `ray_traced_gi.*`. `depth` and
    /// `motion` are the G-buffer's. `FLAG_RESET` or a resize starts the history again.
    #[allow(clippy::too_many_arguments)]
    pub fn record_accumulate<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        view: &View,
        params: &RtGiParams,
        depth: Tex,
        motion: Tex,
        raw_y: Tex,
        raw_cocg_ao: Tex,
        hit_distance: Tex,
    ) -> Result<RtGiFrame> {
        self.record_accumulate_onto(
            g,
            view,
            params,
            [depth, motion],
            [raw_y, raw_cocg_ao, hit_distance],
            &RecurrentHistory::default(),
        )
    }

    /// [`RayTracedGi::record_accumulate`] whose history is, where `denoised` has it, last
    /// frame's denoised output (the recurrent denoiser) instead of the accumulation's own.
    pub fn record_accumulate_onto<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        view: &View,
        params: &RtGiParams,
        [depth, motion]: [Tex; 2],
        [raw_y, raw_cocg_ao, hit_distance]: [Tex; 3],
        denoised: &RecurrentHistory,
    ) -> Result<RtGiFrame> {
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let hist = |g: &mut FrameGraph<'r>, name: &str, format| {
            g.history_texture(name, TextureDesc::d2(w, h, format))
        };
        let y = hist(g, "ray_traced_gi.gi_y", Y_FORMAT)?;
        let cocg = hist(g, "ray_traced_gi.gi_cocg", COCG_FORMAT)?;
        let ao = hist(g, "ray_traced_gi.ao", SCALAR_FORMAT)?;
        let len = hist(g, "ray_traced_gi.history_length", SCALAR_FORMAT)?;
        let vz = hist(g, "ray_traced_gi.view_depth", VIEW_DEPTH_FORMAT)?;
        let ([y_prev, cocg_prev], gi_valid) = denoised
            .gi
            .unwrap_or(([y.prev, cocg.prev], y.valid && cocg.valid));
        let (ao_prev, ao_valid) = denoised.ao.unwrap_or((ao.prev, ao.valid));
        let valid = gi_valid && ao_valid && len.valid && vz.valid;
        let mut params = *params;
        if !valid {
            params.set_flag(FLAG_RESET, true);
        }
        // The shader's module declares the noise set beside the uniform's struct.
        let noise = self.noise_set(g);
        g.pass("ray_traced_gi.accumulate")
            .constants(view)
            .constants(&params)
            .read(depth)
            .read(motion)
            .read(raw_y)
            .read(raw_cocg_ao)
            .read(y_prev)
            .read(cocg_prev)
            .read(ao_prev)
            .read(len.prev)
            .read(vz.prev)
            .write(y.cur)
            .write(cocg.cur)
            .write(ao.cur)
            .write(len.cur)
            .write(vz.cur)
            .set(noise)
            .dispatch_threads(&self.accumulate, [w, h, 1])?;
        Ok(RtGiFrame {
            gi_y: y.cur,
            gi_cocg: cocg.cur,
            history_length: len.cur,
            ao: ao.cur,
            hit_distance,
        })
    }

    /// The verification kernel `ray_traced_gi/check.wgsl`: `cases` records of three vec4s in
    /// `inputs`, as many out in `outputs` (see the shader).
    pub fn record_check<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        inputs: Buf,
        outputs: Buf,
        cases: u32,
    ) -> Result<()> {
        let noise = self.noise_set(g);
        g.pass("ray_traced_gi.check")
            .read(inputs)
            .write(outputs)
            .set(noise)
            .dispatch(&self.check, [cases.div_ceil(64).max(1), 1, 1])
    }

    /// The verification kernel `ray_traced_gi/resolve_check.wgsl` of `hikari::rtgi_resolve`:
    /// five vec4s a case in, two out (see the shader). `brdf_tables`: `BrdfTables::binding_set`.
    pub fn record_resolve_check<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        inputs: Buf,
        outputs: Buf,
        cases: u32,
        brdf_tables: BindingSet,
    ) -> Result<()> {
        g.pass("ray_traced_gi.resolve_check")
            .read(inputs)
            .write(outputs)
            .set(brdf_tables)
            .dispatch(&self.resolve_check, [cases.div_ceil(64).max(1), 1, 1])
    }
}

/// A shared handle, so that the frame state can keep the scene's BVH between frames.
pub type SharedRtGiScene = Arc<RtGiScene>;
