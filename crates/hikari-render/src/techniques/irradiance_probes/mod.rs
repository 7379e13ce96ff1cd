//! Irradiance probes (issue 17, Ghost of Tsushima): a bake of hikari-probes (grid tiles and
//! tetrahedral meshes of sky visibility and bounced sky visibility) uploaded once, relit on
//! the GPU every frame from the sky's SH and the sun or moon, and looked up by the deferred
//! lighting for its ambient diffuse light. docs/irradiance-probes.md.
//!
//! * [`gpu_data`]: the bake as flat buffers (NaN and Inf replaced with 0).
//! * `irradiance_probes.relight` (`relight.wgsl`): the frame's share of the probes
//!   ([`budget`]) relit into the persistent buffer `irradiance_probes.irradiance` (9 RGB
//!   irradiance coefficients a probe, `vec4` each; `--dump` names it).
//! * `hikari::irradiance_probes` (`lookup.wgsl`, binding set `irradiance_probes`):
//!   irradiance at a position, normal and interior mask.
//! * `irradiance_probes.lookup` (`pixels.wgsl`): that lookup alone at every pixel, writing the
//!   dump `irradiance_probes.pixels`; recorded for `--dump` and for `hikari bench probes`
//!   ([`IrradianceProbes::set_lookup_pass`]).
//! * [`relight_bench`]: the relight's steady-state work as separate timed dispatches.
//!
//! CPU twins: [`reference`].

pub mod budget;
pub mod gpu_data;
pub mod reference;
pub mod relight_bench;
pub mod settings;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use hikari_probes::Bake;
use hikari_scene::Sun;

use super::gbuffer::GBuffer;
use super::sky::SkyFrame;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{BindingSet, Buf, FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::steady_light::FrameLight;
use crate::view::View;
use gpu_data::{PROBES_INTERIOR_MASK, ProbeGpuData, ProbeLookupParams};
use relight_bench::RelightBench;
use settings::IrradianceProbesSettings;

pub const RELIGHT_BOUNCE: u32 = 1;
pub const RELIGHT_SUN_BOUNCE: u32 = 2;
pub const RELIGHT_BOOST: u32 = 4;
pub const RELIGHT_DERING: u32 = 8;

/// The uniform of `relight.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct RelightParams {
    /// Unit direction towards the sun or moon; w unused.
    pub light_dir: [f32; 4],
    /// The light's RGB irradiance on a surface facing it, lux; w: the sun-bounce scale.
    pub light_rgb: [f32; 4],
    /// Chunks in the work list, `RELIGHT_*` flags, 0, 0.
    pub config: [u32; 4],
    /// x: directionality boost amount.
    pub amounts: [f32; 4],
}

impl RelightParams {
    /// The parameters for `light` (the frame's sun or moon; `None`: no sun bounce) and the
    /// settings' switches.
    pub fn new(light: Option<&Sun>, s: &IrradianceProbesSettings, chunks: u32) -> Self {
        let (dir, rgb) = match light {
            Some(l) => (
                l.direction.normalize_or(Vec3::Y),
                l.color * l.illuminance_lux,
            ),
            None => (Vec3::Y, Vec3::ZERO),
        };
        let flags = [
            (s.bounce, RELIGHT_BOUNCE),
            (s.sun_bounce, RELIGHT_SUN_BOUNCE),
            (s.boost, RELIGHT_BOOST),
            (s.dering, RELIGHT_DERING),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |acc, (_, bit)| acc | bit);
        Self {
            light_dir: dir.extend(0.0).to_array(),
            light_rgb: rgb.extend(s.sun_bounce_scale).to_array(),
            config: [chunks, flags, 0, 0],
            amounts: [s.boost_amount, 0.0, 0.0, 0.0],
        }
    }
}

/// The dense 9x9x9 Gaunt table of hikari-math, as `relight.wgsl` reads it.
pub fn gaunt_table() -> Vec<f32> {
    let g = hikari_math::sh::product::gaunt_l2();
    (0..729)
        .map(|e| g[e / 81][(e / 9) % 9][e % 9] as f32)
        .collect()
}

/// The probes of one frame, for the lighting.
#[derive(Clone, Copy, Debug)]
pub struct ProbesFrame {
    /// Whether a bake is uploaded and the probes are on (else the lookup covers nothing).
    pub present: bool,
    /// Binding set `irradiance_probes` of `hikari::irradiance_probes`.
    pub lookup: BindingSet,
    /// Whether every probe holds the frame's settled light (absent probes hold nothing that
    /// changes).
    pub settled: bool,
    /// `irradiance_probes.irradiance`: 9 RGB coefficients (vec4) a probe, lux.
    pub irradiance: Buf,
}

struct Uploaded {
    data: ProbeGpuData,
    probe_data: wgpu::Buffer,
    positions: wgpu::Buffer,
    topology: wgpu::Buffer,
    irradiance: wgpu::Buffer,
    chunks: wgpu::Buffer,
}

/// What the irradiance probes keep between frames in the renderer's frame state: the bake on
/// the GPU ([`IrradianceProbesState::set_bake`]), how far its relight has gone, and whether
/// the lookup pass is recorded every frame.
#[derive(Clone, Default)]
pub struct IrradianceProbesState {
    uploaded: Option<Arc<Uploaded>>,
    /// Relights since the upload (0: the next relights everything).
    updates: u64,
    /// Whether the round robin may rest (`crate::steady_light`).
    steady: crate::steady_light::SteadyLight,
    /// Record [`LOOKUP_PASS`] every frame, not only for `--dump` (to time it).
    lookup_pass: bool,
    /// Relight the round robin's share every frame, even at an unchanging light (to time it).
    never_rest: bool,
}

impl std::fmt::Debug for IrradianceProbesState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IrradianceProbesState")
            .field(
                "probes",
                &self.uploaded.as_ref().map(|u| u.data.probe_count()),
            )
            .field("updates", &self.updates)
            .field("steady", &self.steady)
            .field("lookup_pass", &self.lookup_pass)
            .finish()
    }
}

/// The dump of the probes' irradiance at every pixel (`pixels.wgsl`).
pub const PIXELS_DUMP: &str = "irradiance_probes.pixels";
/// The pass that writes it: the probes' lookup alone at every pixel.
pub const LOOKUP_PASS: &str = "irradiance_probes.lookup";

impl IrradianceProbesState {
    /// Uploads `bake` (replacing any earlier one; `None` removes it). Non-finite numbers in it
    /// become 0 (logged). The next frame relights every probe.
    pub fn set_bake(&mut self, ctx: &GpuContext, bake: Option<&Bake>) -> Result<()> {
        let uploaded = bake.map(|b| {
            let data = ProbeGpuData::new(b);
            if data.replaced_non_finite > 0 {
                log::warn!(
                    "irradiance probes: {} non-finite numbers in the bake replaced with 0",
                    data.replaced_non_finite
                );
            }
            upload(ctx, data).map(Arc::new)
        });
        self.uploaded = uploaded.transpose()?.filter(|u| u.data.probe_count() > 0);
        self.updates = 0;
        self.steady = Default::default();
        Ok(())
    }

    /// The uploaded bake's layout, if any.
    pub fn data(&self) -> Option<ProbeGpuData> {
        self.uploaded.as_ref().map(|u| u.data.clone())
    }

    /// Whether every frame records [`LOOKUP_PASS`] (else only a frame whose `--dump` names
    /// [`PIXELS_DUMP`]): the lookup's cost on its own, as `hikari bench probes` times it. The
    /// deferred lighting's own lookup is unchanged.
    pub fn set_lookup_pass(&mut self, on: bool) {
        self.lookup_pass = on;
    }

    /// Whether the round robin runs every frame even when the light does not change (it
    /// rests otherwise, `crate::steady_light`): for `hikari bench probes`, which times it.
    pub fn set_never_rest(&mut self, on: bool) {
        self.never_rest = on;
    }
}

pub struct IrradianceProbes {
    relight: ComputePipeline,
    pixels: ComputePipeline,
    gaunt: wgpu::Buffer,
    /// Bound when there is no bake: one zero element each.
    empty: Arc<Uploaded>,
}

fn upload(ctx: &GpuContext, data: ProbeGpuData) -> Result<Uploaded> {
    let chunk_capacity = budget::chunks(
        &data,
        &budget::FrameWork {
            tiles: (0..data.tiles.len()).collect(),
            meshes: (0..data.meshes.len()).collect(),
        },
    )
    .len()
    .max(1);
    let irradiance = vec![[0.0f32; 4]; data.probe_data.len()];
    Ok(Uploaded {
        probe_data: ctx.storage_buffer(
            "irradiance_probes.probes",
            bytemuck::cast_slice(&data.probe_data),
        )?,
        positions: ctx.storage_buffer(
            "irradiance_probes.positions",
            bytemuck::cast_slice(&data.positions),
        )?,
        topology: ctx.storage_buffer(
            "irradiance_probes.topology",
            bytemuck::cast_slice(&data.topology),
        )?,
        irradiance: ctx.storage_buffer(
            "irradiance_probes.irradiance",
            bytemuck::cast_slice(&irradiance),
        )?,
        chunks: ctx.storage_buffer("irradiance_probes.chunks", &vec![0u8; chunk_capacity * 8])?,
        data,
    })
}

impl IrradianceProbes {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let empty = hikari_probes::Bake::new(
            Default::default(),
            hikari_probes::BakeSettings::with_rays(1),
        );
        Ok(Self {
            relight: ComputePipeline::new(ctx, lib, "irradiance_probes/relight.wgsl", "main", &[])?,
            pixels: ComputePipeline::new(ctx, lib, "irradiance_probes/pixels.wgsl", "main", &[])?,
            gaunt: ctx.storage_buffer(
                "irradiance_probes.gaunt",
                bytemuck::cast_slice(&gaunt_table()),
            )?,
            empty: Arc::new(upload(ctx, ProbeGpuData::new(&empty))?),
        })
    }

    /// Relights this frame's share of the probes, lit by the frame context's sun or moon and
    /// chosen around its camera, and makes the lookup's binding set. The round robin rests
    /// while `frame_light` stays settled and unchanged after a whole round (`crate::steady_light`).
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut IrradianceProbesState,
        cx: &crate::frame_context::FrameContext,
        s: &IrradianceProbesSettings,
        sky: &SkyFrame,
        clouds: BindingSet,
        frame_light: FrameLight,
    ) -> Result<ProbesFrame> {
        let light = cx.sun.as_ref();
        let camera = Vec3::from_slice(&cx.view.position[..3]);
        let (u, update) = {
            match (&state.uploaded, s.enabled && sky.enabled) {
                (Some(u), true) => {
                    let out = (u.clone(), Some(state.updates));
                    state.updates += 1;
                    out
                }
                _ => (self.empty.clone(), None),
            }
        };
        let irradiance = g.import_buffer("irradiance_probes.irradiance", &u.irradiance);
        let positions = g.import_buffer("irradiance_probes.positions", &u.positions);
        let topology = g.import_buffer("irradiance_probes.topology", &u.topology);
        let mut params: ProbeLookupParams = u.data.params;
        params.grid[3] = sky.knobs.ambient_diffuse;
        if s.interior_mask {
            params.grid_size[3] |= PROBES_INTERIOR_MASK;
        }
        let mut settled = true;
        if let Some(update) = update {
            let cycle = budget::cycle_frames(&u.data, s);
            let work = if !state.never_rest && state.steady.rests(frame_light, cycle) {
                budget::FrameWork::default()
            } else {
                state.steady.relit(update == 0, cycle);
                budget::frame_work(&u.data, update, [camera.x, camera.z], s)
            };
            settled = state.steady.done(cycle);
            let chunks = budget::chunks(&u.data, &work);
            if !chunks.is_empty() {
                g.ctx()
                    .queue
                    .write_buffer(&u.chunks, 0, bytemuck::cast_slice(&chunks));
                let chunk_buf = g.import_buffer("irradiance_probes.chunks", &u.chunks);
                let gaunt = g.import_buffer("irradiance_probes.gaunt", &self.gaunt);
                let probes = g.import_buffer("irradiance_probes.probes", &u.probe_data);
                g.pass("irradiance_probes.relight")
                    .constants(&RelightParams::new(light, s, chunks.len() as u32))
                    .read(sky.sh)
                    .read(gaunt)
                    .read(chunk_buf)
                    .read(probes)
                    .write(irradiance)
                    .read(positions)
                    .set(clouds)
                    .dispatch(&self.relight, [chunks.len() as u32, 1, 1])?;
            }
        } else {
            params.grid_size[3] = 0;
        }
        let lookup = g
            .binding_set("irradiance_probes")
            .constants(&params)
            .read(irradiance)
            .read(positions)
            .read(topology)
            .finish();
        Ok(ProbesFrame {
            present: update.is_some(),
            lookup,
            settled,
            irradiance,
        })
    }

    /// Records the dispatches of `bench` (one pass each, named by its workloads), relit from
    /// its sky and `light` (the frame's sun or moon) with the switches of `s`; returns their
    /// output, `irradiance_probes.bench_irradiance` (9 `vec4` a probe, the workloads' probes
    /// one after the other).
    pub fn record_relight_bench<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        bench: &'r RelightBench,
        light: Option<&Sun>,
        s: &IrradianceProbesSettings,
    ) -> Result<Buf> {
        let sky = g.import_buffer("irradiance_probes.bench_sky_sh", &bench.sky_sh);
        let gaunt = g.import_buffer("irradiance_probes.gaunt", &self.gaunt);
        let probes = g.import_buffer("irradiance_probes.bench_probes", &bench.probe_data);
        let irradiance = g.import_buffer("irradiance_probes.bench_irradiance", &bench.irradiance);
        let positions = g.import_buffer("irradiance_probes.bench_positions", &bench.positions);
        let clouds = super::clouds::disabled_lookup(g)?;
        for w in &bench.workloads {
            let chunks = g.import_buffer(w.pass, &w.chunks);
            g.pass(w.pass)
                .constants(&RelightParams::new(light, s, w.chunk_count))
                .read(sky)
                .read(gaunt)
                .read(chunks)
                .read(probes)
                .write(irradiance)
                .read(positions)
                .set(clouds)
                .dispatch(&self.relight, [w.chunk_count, 1, 1])?;
        }
        Ok(irradiance)
    }

    /// The probes' irradiance at every pixel's surface ([`PIXELS_DUMP`], Rgba16Float: lux,
    /// alpha 1 where probes cover it) by the pass [`LOOKUP_PASS`], recorded only when `--dump`
    /// asks for it or [`IrradianceProbes::set_lookup_pass`] is on.
    pub fn record_pixels_dump<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &IrradianceProbesState,
        probes: &ProbesFrame,
        gb: &GBuffer,
        view: &View,
    ) -> Result<Option<Tex>> {
        if !state.lookup_pass && !g.dump_requested(PIXELS_DUMP) {
            return Ok(None);
        }
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let out = g.texture(
            PIXELS_DUMP,
            TextureDesc::d2(w, h, wgpu::TextureFormat::Rgba16Float),
        )?;
        g.pass(LOOKUP_PASS)
            .constants(view)
            .read(gb.depth)
            .read(gb.normal)
            .read(gb.albedo)
            .write(out)
            .set(probes.lookup)
            .dispatch_threads(&self.pixels, [w, h, 1])?;
        Ok(Some(out))
    }
}

/// The binding set `irradiance_probes` of a frame without probes (its lookup covers nothing),
/// for a pass that reads the probes recorded on its own, as tests and benchmarks do.
pub fn absent_lookup(g: &mut FrameGraph<'_>) -> Result<BindingSet> {
    let irradiance = g.buffer("irradiance_probes.irradiance", 16)?;
    let positions = g.buffer("irradiance_probes.positions", 16)?;
    let topology = g.buffer("irradiance_probes.topology", 16)?;
    g.pass("irradiance_probes.absent")
        // Never read: the flags say there are no probes. wgpu zeroes the buffers.
        .uses(irradiance, true)
        .uses(positions, true)
        .uses(topology, true)
        .encode(|_, _| {})?;
    Ok(g.binding_set("irradiance_probes")
        .constants(&ProbeLookupParams::zeroed())
        .read(irradiance)
        .read(positions)
        .read(topology)
        .finish())
}
