//! Relit reflection probes (Ghost of Tsushima): cube maps of albedo, normal and distance
//! captured at fixed points, relit by today's sun, sky and irradiance probes a few a frame,
//! prefiltered for GGX roughness, and read by the deferred lighting for its indirect specular.
//! docs/reflection-probes.md.
//!
//! * `reflection_probes.capture.p{i}f{k}.*`: the G-buffer of probe i's face k, drawn by the
//!   rasteriser with a 90-degree camera, and `reflection_probes.capture`, which keeps what
//!   relighting needs in the persistent `reflection_probes.albedo`, `.normal_depth` and
//!   `.emission` (`capture.wgsl`). Done once, when the probes or the resolution change: the
//!   talk captured offline; on a GPU it takes milliseconds.
//! * `reflection_probes.relight` (`relight.wgsl`): this frame's probes (the talk: one a frame,
//!   round robin; all of them when the sun jumps) into level 0 of `reflection_probes.relit`.
//! * `reflection_probes.downsample{m}`: level m of the relit maps' mip chain.
//! * `reflection_probes.prefilter{k}` (`prefilter.wgsl`): GGX filtered importance sampling
//!   into level k of the persistent `reflection_probes.radiance`, one roughness a level; with
//!   `compress`, into this frame's `reflection_probes.radiance` (the relit probes only), then
//!   `reflection_probes.bc6h_encode{k}` and `.bc6h_copy{k}` into the persistent
//!   `reflection_probes.radiance_bc6h` (docs/bc6h.md).
//! * [`ReflectionLookup`]: what the deferred lighting reads the probes through
//!   (`direct_lighting/shade.wgsl`'s `reflection_probe_radiance`, with the per-probe math of
//!   `common.wgsl`).
//!
//! CPU twins: [`reference`].

pub mod reference;
pub mod settings;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_bake::reflection_probes::ReflectionProbeBox;
use hikari_scene::{Camera, Sun};

use super::clouds::CloudsFrame;
use super::gbuffer::GBufferPass;
use super::irradiance_probes::ProbesFrame;
use super::sky::SkyFrame;
use crate::bc6h::reference::BLOCK_BYTES;
use crate::bc6h::{Bc6hEncoder, BlockLayout, Quality};
use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::scene::raster::{RasterQueues, Rasterizer};
use crate::scene::upload::SceneInFrame;
use crate::shader::ShaderLibrary;
use crate::steady_light::{FrameLight, SteadyLight};
use crate::view::View;
use settings::ReflectionProbesSettings;

pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const NORMAL_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const EMISSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Near plane of the capture cameras, metres.
pub const CAPTURE_NEAR_M: f32 = 0.05;

pub const RP_ON: u32 = 1;
pub const RP_HORIZON: u32 = 2;
pub const RP_PARALLAX_ROUGHNESS: u32 = 4;
pub const RP_NORMALIZE: u32 = 8;

pub const RELIGHT_SHADOWS: u32 = 1;
pub const RELIGHT_SKY: u32 = 2;
pub const RELIGHT_PROBES: u32 = 4;

/// One probe on the GPU (`hikari::reflection_probe_math::ReflectionProbeGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ReflectionProbeGpu {
    pub to_box: [[f32; 4]; 4],
    pub capture: [f32; 4],
    pub half_m: [f32; 4],
}

impl ReflectionProbeGpu {
    pub fn new(p: &ReflectionProbeBox) -> Self {
        Self {
            to_box: p.transform.inverse().to_cols_array_2d(),
            capture: p.capture.extend(p.blend_m.max(0.0)).to_array(),
            half_m: p.half_extents().extend(1.0).to_array(),
        }
    }
}

/// The lookup's numbers, which the deferred lighting's uniform carries
/// (`LightingParams::reflection`): probes, roughness levels, `RP_*` flags; the
/// normalisation's largest ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectionProbeParams {
    pub config: [u32; 4],
    pub values: [f32; 4],
}

impl ReflectionProbeParams {
    pub fn new(s: &ReflectionProbesSettings, probes: u32, levels: u32, on: bool) -> Self {
        let flags = [
            (on, RP_ON),
            (s.horizon_occlusion, RP_HORIZON),
            (s.roughness_parallax, RP_PARALLAX_ROUGHNESS),
            (s.normalization, RP_NORMALIZE),
        ]
        .iter()
        .filter(|(b, _)| *b)
        .fold(0, |acc, (_, bit)| acc | bit);
        Self {
            config: [probes, levels, flags, 0],
            values: [s.max_normalization, 0.0, 0.0, 0.0],
        }
    }
}

/// `capture.wgsl`'s uniform.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CaptureParams {
    pub face: [u32; 4],
    pub capture: [f32; 4],
}

/// `relight.wgsl`'s uniform.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct RelightParams {
    pub sun: [f32; 4],
    pub sun_color: [f32; 4],
    pub probes: [u32; 4],
    pub config: [u32; 4],
    pub cutoff: [f32; 4],
}

/// `prefilter.wgsl`'s uniform.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PrefilterParams {
    pub level: [u32; 4],
    pub probes: [u32; 4],
}

/// What the probes are relit with.
pub struct ReflectionProbeInputs<'a> {
    pub sky: &'a SkyFrame,
    pub probes: &'a ProbesFrame,
    pub clouds: &'a CloudsFrame,
    pub lights: Buf,
    pub light_count: u32,
    pub sun: Option<&'a Sun>,
    /// Lux below which a point or spot light is cut off.
    pub cutoff_lux: f32,
    /// The weather's name: a new weather relights every probe.
    pub weather: &'a str,
    /// Relight every probe this frame.
    pub relight_all: bool,
    /// Where the camera is: probes farther than `stream_distance_m` from it are not resident.
    pub camera: Vec3,
    /// The sky lights the probes (`sky.sky`; off: a black sky and no sky light).
    pub sky_light: bool,
    /// The frame's light, settled once the clouds and the irradiance probes are: the round
    /// robin rests while it stays unchanged after a whole round (`crate::steady_light`).
    pub light: FrameLight<'a>,
}

impl<'a> ReflectionProbeInputs<'a> {
    /// The inputs of a frame: the frame context's sun, lights, cut-off and history, the
    /// camera where it sees from, and the frame's sky, probes, clouds, light table and light.
    pub fn for_frame(
        cx: &'a crate::frame_context::FrameContext,
        s: &'a crate::settings::Settings,
        sky: &'a SkyFrame,
        probes: &'a ProbesFrame,
        clouds: &'a CloudsFrame,
        lights: Buf,
        light: FrameLight<'a>,
    ) -> Self {
        Self {
            sky,
            probes,
            clouds,
            lights,
            light_count: cx.punctual_lights,
            sun: cx.sun.as_ref(),
            cutoff_lux: cx.light_cutoff_lux,
            weather: &s.sky.weather,
            relight_all: cx.history.view_changed(),
            camera: Vec3::from_slice(&cx.view.position[..3]),
            sky_light: s.sky.sky,
            light: FrameLight {
                settled: light.settled && probes.settled,
                ..light
            },
        }
    }
}

/// What the deferred lighting binds to read the probes, in this order (the numbers go into
/// its uniform).
#[derive(Clone, Copy, Debug)]
pub struct ReflectionLookup {
    pub params: ReflectionProbeParams,
    /// `reflection_probes.probes`: [`ReflectionProbeGpu`] a probe, smallest box first.
    pub probes: Buf,
    /// The prefiltered cube maps (a 1 x 1 stand-in with the probes off).
    pub radiance: Tex,
    /// `reflection_probes.capture_light`: the light at each capture point.
    pub capture_light: Buf,
}

/// The probes of a frame.
#[derive(Clone, Copy, Debug)]
pub struct ReflectionProbesFrame {
    pub lookup: ReflectionLookup,
    /// `reflection_probes.radiance` (`None` with the probes off).
    pub radiance: Option<Tex>,
    /// The captured cube maps, `None` with the probes off.
    pub capture: Option<[Tex; 3]>,
    /// How many probes were relit this frame.
    pub relit: u32,
    /// Whether any cube map was captured this frame.
    pub captured: bool,
}

/// The cube face cameras: the face's axis and an up that keeps the image square with the face.
const FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y),
    (Vec3::NEG_X, Vec3::Y),
    (Vec3::Y, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::Z),
    (Vec3::Z, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y),
];

/// The camera that captures `face` of a cube map at `at`.
pub fn face_camera(at: Vec3, face: usize) -> Camera {
    let (axis, up) = FACES[face];
    Camera {
        name: format!("reflection probe face {face}"),
        position: at,
        target: at + axis,
        vfov_deg: 90.0,
        near: CAPTURE_NEAR_M,
        up,
    }
}

struct Uploaded {
    /// Sorted by volume, smallest first (the lookup's nesting order).
    boxes: Vec<ReflectionProbeBox>,
    /// `probes` as uploaded, every one resident.
    gpu: Vec<ReflectionProbeGpu>,
    probes: wgpu::Buffer,
    capture_light: wgpu::Buffer,
    /// The probes relit this frame (`relight.wgsl`, `prefilter.wgsl`).
    relit_list: wgpu::Buffer,
    generation: u64,
}

#[derive(Clone, Debug, Default)]
struct Progress {
    /// (generation, resolution) the persistent cube maps hold, and which probes they hold.
    captured_with: Option<(u64, u32)>,
    captured: Vec<bool>,
    /// Which probes were resident last frame.
    resident: Vec<bool>,
    /// The next probe to relight.
    next: u32,
    /// The sun's direction and the weather at the last relight of every probe.
    relit_all_with: Option<(Vec3, String)>,
    /// Whether the round robin may rest (`crate::steady_light`).
    steady: SteadyLight,
}

/// What the reflection probes keep between frames in the renderer's frame state: the probe
/// set on the GPU ([`ReflectionProbesState::set_probes`]) and which probes the persistent cube
/// maps hold and relit.
#[derive(Clone, Default)]
pub struct ReflectionProbesState {
    uploaded: Option<Arc<Uploaded>>,
    progress: Progress,
}

impl std::fmt::Debug for ReflectionProbesState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReflectionProbesState")
            .field("probes", &self.uploaded.as_ref().map(|u| u.boxes.len()))
            .field("progress", &self.progress)
            .finish()
    }
}

impl ReflectionProbesState {
    /// Uses `probes` from the next frame on (captured then). Each is validated; the error
    /// names the first bad one.
    pub fn set_probes(&mut self, ctx: &GpuContext, probes: &[ReflectionProbeBox]) -> Result<()> {
        for p in probes {
            p.validate()
                .map_err(|e| RenderError::Graph(format!("reflection probes: {e}")))?;
        }
        let guard = &mut self.uploaded;
        let generation = guard.as_ref().map_or(1, |u| u.generation + 1);
        if probes.is_empty() {
            *guard = None;
            return Ok(());
        }
        let mut boxes = probes.to_vec();
        boxes.sort_by(|a, b| a.volume().total_cmp(&b.volume()));
        let gpu: Vec<ReflectionProbeGpu> = boxes.iter().map(ReflectionProbeGpu::new).collect();
        let limit = ctx.limits.max_texture_array_layers / 6;
        if boxes.len() as u32 > limit {
            return Err(RenderError::Limit {
                what: "reflection probes (six texture layers each)".into(),
                requested: boxes.len() as u64,
                limit: u64::from(limit),
            });
        }
        *guard = Some(Arc::new(Uploaded {
            probes: ctx.storage_buffer("reflection_probes.probes", bytemuck::cast_slice(&gpu))?,
            capture_light: ctx.storage_buffer(
                "reflection_probes.capture_light",
                &vec![0u8; boxes.len() * 16],
            )?,
            relit_list: ctx
                .storage_buffer("reflection_probes.relit_list", &vec![0u8; boxes.len() * 4])?,
            gpu,
            boxes,
            generation,
        }));
        Ok(())
    }

    /// Captures the cube maps again next frame (a rasteriser queue overflowed while they were
    /// drawn).
    pub fn invalidate_capture(&mut self) {
        self.progress.captured_with = None;
    }
}

pub struct ReflectionProbes {
    capture: ComputePipeline,
    relight: ComputePipeline,
    downsample: ComputePipeline,
    prefilter: ComputePipeline,
    /// BC6H for the prefiltered maps (`compress`).
    bc6h: Bc6hEncoder,
    /// Stand-ins for the lookup with no probes.
    empty_probe: wgpu::Buffer,
    empty_light: wgpu::Buffer,
}

/// Mip levels of a cube map `n` texels a side down to 1 x 1.
pub fn mip_count(n: u32) -> u32 {
    32 - n.max(1).leading_zeros()
}

/// The compressed copy's format: BC6H, unsigned (radiance has no sign).
pub const COMPRESSED_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Bc6hRgbUfloat;

/// Whether the prefiltered maps are kept as BC6H: asked for, sampled by the adapter, and
/// every level whole 4x4 blocks (the smallest at least 4 texels wide).
pub fn compresses(ctx: &GpuContext, s: &ReflectionProbesSettings) -> bool {
    s.compress
        && ctx.has(wgpu::Features::TEXTURE_COMPRESSION_BC)
        && s.resolution >> s.levels.saturating_sub(1) >= 4
        && s.resolution.is_multiple_of(4 << s.levels.saturating_sub(1))
}

impl ReflectionProbes {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            bc6h: Bc6hEncoder::with_library(ctx, lib)?,
            capture: ComputePipeline::new(ctx, lib, "reflection_probes/capture.wgsl", "main", &[])?,
            relight: ComputePipeline::new(ctx, lib, "reflection_probes/relight.wgsl", "main", &[])?,
            downsample: ComputePipeline::new(
                ctx,
                lib,
                "reflection_probes/downsample.wgsl",
                "main",
                &[],
            )?,
            prefilter: ComputePipeline::new(
                ctx,
                lib,
                "reflection_probes/prefilter.wgsl",
                "main",
                &[],
            )?,
            empty_probe: ctx.storage_buffer(
                "reflection_probes.empty",
                bytemuck::bytes_of(&ReflectionProbeGpu::zeroed()),
            )?,
            empty_light: ctx.storage_buffer("reflection_probes.empty_light", &[0; 16])?,
        })
    }

    /// Encodes the relit probes' (`list`) prefiltered levels of `radiance` (their faces in
    /// list order) into `compressed`: per level, the probes' six faces into a block buffer,
    /// copied into the BC6H texture at the probes' own layers.
    fn compress<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        radiance: Tex,
        compressed: Tex,
        list: &[u32],
        n: u32,
        levels: u32,
    ) -> Result<()> {
        for level in 0..levels {
            let side = n >> level;
            let layout = BlockLayout::for_copy([side, side]);
            let face_bytes = u64::from(layout.layer_stride) * BLOCK_BYTES as u64;
            let blocks = g.buffer(
                &format!("reflection_probes.bc6h{level}"),
                face_bytes * 6 * list.len() as u64,
            )?;
            for k in 0..list.len() {
                self.bc6h.record(
                    g,
                    &format!("reflection_probes.bc6h_encode{level}"),
                    radiance,
                    blocks,
                    [side, side],
                    (6 * k as u32, 6, level),
                    BlockLayout {
                        first_block: 6 * k as u32 * layout.layer_stride,
                        ..layout
                    },
                    Quality::Fast,
                )?;
            }
            let list = list.to_vec();
            g.pass(&format!("reflection_probes.bc6h_copy{level}"))
                .uses(blocks, false)
                .uses(compressed, true)
                .encode(move |encoder, res| {
                    for (k, &probe) in list.iter().enumerate() {
                        encoder.copy_buffer_to_texture(
                            wgpu::TexelCopyBufferInfo {
                                buffer: res.buffer(blocks),
                                layout: wgpu::TexelCopyBufferLayout {
                                    offset: 6 * k as u64 * face_bytes,
                                    bytes_per_row: Some(layout.row_stride * BLOCK_BYTES as u32),
                                    rows_per_image: Some(side / 4),
                                },
                            },
                            wgpu::TexelCopyTextureInfo {
                                texture: res.texture(compressed),
                                mip_level: level,
                                origin: wgpu::Origin3d {
                                    x: 0,
                                    y: 0,
                                    z: 6 * probe,
                                },
                                aspect: wgpu::TextureAspect::All,
                            },
                            wgpu::Extent3d {
                                width: side,
                                height: side,
                                depth_or_array_layers: 6,
                            },
                        );
                    }
                })?;
        }
        Ok(())
    }

    fn disabled_frame(
        &self,
        g: &mut FrameGraph<'_>,
        s: &ReflectionProbesSettings,
    ) -> Result<ReflectionProbesFrame> {
        let radiance = g.texture(
            "reflection_probes.radiance",
            TextureDesc::d2_array(1, 1, 6, RADIANCE_FORMAT),
        )?;
        g.pass("reflection_probes.clear")
            // Never sampled with the probes off; wgpu zeroes it.
            .uses(radiance, true)
            .encode(|_, _| {})?;
        let probes = g.import_buffer("reflection_probes.probes", &self.empty_probe);
        let light = g.import_buffer("reflection_probes.capture_light", &self.empty_light);
        let lookup = ReflectionLookup {
            params: ReflectionProbeParams::new(s, 0, 1, false),
            probes,
            radiance,
            capture_light: light,
        };
        Ok(ReflectionProbesFrame {
            lookup,
            radiance: None,
            capture: None,
            relit: 0,
            captured: false,
        })
    }

    /// Captures the probes that became resident, relights this frame's share, prefilters it,
    /// and gives the lookup's resources. With the probes off (or none, or no atmosphere), a lookup that
    /// covers nothing.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut ReflectionProbesState,
        gbuffer: &'r GBufferPass,
        raster: &'r Rasterizer,
        scene: &SceneInFrame,
        queues: &mut RasterQueues,
        s: &ReflectionProbesSettings,
        inputs: &ReflectionProbeInputs<'_>,
    ) -> Result<ReflectionProbesFrame> {
        let uploaded = state.uploaded.clone();
        let on = s.enabled && inputs.sky.enabled;
        let Some(u) = uploaded.filter(|_| on) else {
            return self.disabled_frame(g, s);
        };
        let n = s.resolution;
        let mips = mip_count(n);
        if s.levels > mips {
            return Err(RenderError::Graph(format!(
                "reflection_probes.levels is {} but a {n}-texel cube map has only {mips} mip levels",
                s.levels
            )));
        }
        let count = u.boxes.len() as u32;
        let layers = 6 * count;
        let array = |format| TextureDesc::d2_array(n, n, layers, format);
        let (albedo, f0) =
            g.persistent_texture("reflection_probes.albedo", array(ALBEDO_FORMAT))?;
        let (normal_depth, f1) =
            g.persistent_texture("reflection_probes.normal_depth", array(NORMAL_DEPTH_FORMAT))?;
        let (emission, f2) =
            g.persistent_texture("reflection_probes.emission", array(EMISSION_FORMAT))?;
        // The talk keeps the relit, prefiltered maps as BC6H: each relit probe's levels are
        // prefiltered into a texture of this frame, encoded, and copied into the persistent
        // compressed maps the lookup samples. Uncompressed, the prefilter writes the
        // persistent RGBA16F maps themselves.
        let compressed = compresses(g.ctx(), s);
        let (stored, fresh) = if compressed {
            g.persistent_texture(
                "reflection_probes.radiance_bc6h",
                array(COMPRESSED_FORMAT).with_mips(s.levels),
            )?
        } else {
            g.persistent_texture(
                "reflection_probes.radiance",
                array(RADIANCE_FORMAT).with_mips(s.levels),
            )?
        };
        let probes = g.import_buffer("reflection_probes.probes", &u.probes);
        let capture_light = g.import_buffer("reflection_probes.capture_light", &u.capture_light);

        let progress = &mut state.progress;
        let key = (u.generation, n);
        if f0 || f1 || f2 || progress.captured_with != Some(key) {
            progress.captured_with = Some(key);
            progress.captured = vec![false; count as usize];
            progress.resident = vec![false; count as usize];
        }
        // The talk streamed its probes in on demand; here a probe is resident while the camera
        // is within `stream_distance_m` of its box (0: always), captured the first frame it is.
        let resident: Vec<bool> = u
            .boxes
            .iter()
            .map(|b| {
                s.stream_distance_m <= 0.0 || b.distance_to(inputs.camera) <= s.stream_distance_m
            })
            .collect();
        let mut captured_now = false;
        for (i, b) in u.boxes.iter().enumerate() {
            if !resident[i] || progress.captured[i] {
                continue;
            }
            captured_now = true;
            progress.captured[i] = true;
            for face in 0..6 {
                let view = View::new(&face_camera(b.capture, face), n, n);
                let gb = gbuffer.record_as(
                    g,
                    raster,
                    scene,
                    &view,
                    [n, n],
                    queues,
                    &format!("reflection_probes.capture.p{i}f{face}"),
                )?;
                g.pass("reflection_probes.capture")
                    .constants(&view)
                    .constants(&CaptureParams {
                        face: [face as u32, i as u32 * 6 + face as u32, n, 0],
                        capture: b.capture.extend(0.0).to_array(),
                    })
                    .read(gb.depth)
                    .read(gb.normal)
                    .read(gb.albedo)
                    .read(gb.material)
                    .read(gb.emissive)
                    .write(albedo)
                    .write(normal_depth)
                    .write(emission)
                    .dispatch_threads(&self.capture, [n, n, 1])?;
            }
        }

        // Which probes to relight: every resident one after a new radiance texture, a jump of
        // the sun or a new weather; else those that just became resident and the next
        // `per_frame` resident ones, round robin.
        let sun_dir = inputs.sun.map_or(Vec3::ZERO, |s| s.direction);
        let moved = match &progress.relit_all_with {
            Some((d, w)) => {
                let (had, has) = (d.length_squared() > 0.0, sun_dir.length_squared() > 0.0);
                w != inputs.weather
                    || had != has
                    || (has
                        && d.dot(sun_dir).clamp(-1.0, 1.0).acos().to_degrees() > s.relight_all_deg)
            }
            None => true,
        };
        let all = fresh || moved || inputs.relight_all;
        if all {
            progress.relit_all_with = Some((sun_dir, inputs.weather.to_owned()));
        }
        let mut list: Vec<u32> = (0..count)
            .filter(|&i| resident[i as usize] && (all || !progress.resident[i as usize]))
            .collect();
        let cycle = count.div_ceil(s.per_frame.max(1));
        let rests = progress.steady.rests(inputs.light, cycle);
        if !rests {
            progress.steady.relit(all, cycle);
        }
        let mut budget = if all || rests { 0 } else { s.per_frame };
        for step in 0..count {
            if budget == 0 {
                break;
            }
            let i = (progress.next + step) % count;
            if resident[i as usize] && !list.contains(&i) {
                list.push(i);
                budget -= 1;
                progress.next = (i + 1) % count;
            }
        }
        progress.resident = resident.clone();
        let gpu: Vec<ReflectionProbeGpu> = u
            .gpu
            .iter()
            .zip(&resident)
            .map(|(p, &r)| ReflectionProbeGpu {
                half_m: [
                    p.half_m[0],
                    p.half_m[1],
                    p.half_m[2],
                    f32::from(u8::from(r)),
                ],
                ..*p
            })
            .collect();
        let queue = &g.ctx().queue;
        queue.write_buffer(&u.probes, 0, bytemuck::cast_slice(&gpu));
        let k = list.len() as u32;
        if k > 0 {
            queue.write_buffer(&u.relit_list, 0, bytemuck::cast_slice(&list));
        }
        let relit_list = g.import_buffer("reflection_probes.relit_list", &u.relit_list);
        let lookup_params = ReflectionProbeParams::new(s, count, s.levels, true);
        if k == 0 {
            let lookup = ReflectionLookup {
                params: lookup_params,
                probes,
                radiance: stored,
                capture_light,
            };
            return Ok(ReflectionProbesFrame {
                lookup,
                radiance: (!compressed).then_some(stored),
                capture: Some([albedo, normal_depth, emission]),
                relit: 0,
                captured: captured_now,
            });
        }

        let relit = g.texture(
            "reflection_probes.relit",
            TextureDesc::d2_array(n, n, 6 * k, RADIANCE_FORMAT).with_mips(mips),
        )?;
        let (sun, sun_color) = match inputs.sun {
            Some(sun) if sun.illuminance_lux > 0.0 => (
                sun.direction
                    .normalize_or(Vec3::Y)
                    .extend(sun.illuminance_lux),
                sun.color.extend(1.0),
            ),
            _ => (glam::Vec4::ZERO, glam::Vec4::ZERO),
        };
        let flags = [
            (s.shadow_tracing, RELIGHT_SHADOWS),
            (inputs.sky_light, RELIGHT_SKY),
            (inputs.probes.present, RELIGHT_PROBES),
        ]
        .iter()
        .filter(|(b, _)| *b)
        .fold(0, |acc, (_, bit)| acc | bit);
        g.pass("reflection_probes.relight")
            .constants(&RelightParams {
                sun: sun.to_array(),
                sun_color: sun_color.to_array(),
                probes: [0, count, k, flags],
                config: [inputs.light_count, n, s.shadow_pcf_radius, 0],
                cutoff: [inputs.cutoff_lux, 0.0, 0.0, 0.0],
            })
            .read(probes)
            .read(albedo)
            .read(normal_depth)
            .read(emission)
            .read(inputs.lights)
            .write(relit)
            .write(capture_light)
            .read(relit_list)
            .set(inputs.sky.lookup)
            .set(inputs.sky.ambient)
            .set(inputs.probes.lookup)
            .set(inputs.clouds.lookup)
            .dispatch_threads(&self.relight, [n, n, 6 * k])?;
        for m in 0..mips - 1 {
            let side = (n >> (m + 1)).max(1);
            g.pass(&format!("reflection_probes.downsample{}", m + 1))
                .read_mip(relit, m)
                .write_mip(relit, m + 1)
                .dispatch_threads(&self.downsample, [side, side, 6 * k])?;
        }
        // Compressed, the prefiltered levels of this frame's probes only, in list order.
        let radiance = if compressed {
            g.texture(
                "reflection_probes.radiance",
                TextureDesc::d2_array(n, n, 6 * k, RADIANCE_FORMAT).with_mips(s.levels),
            )?
        } else {
            stored
        };
        for level in 0..s.levels {
            let side = (n >> level).max(1);
            g.pass(&format!("reflection_probes.prefilter{level}"))
                .constants(&PrefilterParams {
                    level: [level, s.levels, s.samples, n],
                    probes: [u32::from(compressed), count, k, 0],
                })
                .read(relit)
                .sampler(SamplerKind::LinearClamp)
                .write_mip(radiance, level)
                .read(relit_list)
                .dispatch_threads(&self.prefilter, [side, side, 6 * k])?;
        }
        if compressed {
            self.compress(g, radiance, stored, &list, n, s.levels)?;
        }
        let lookup = ReflectionLookup {
            params: lookup_params,
            probes,
            radiance: stored,
            capture_light,
        };
        Ok(ReflectionProbesFrame {
            lookup,
            radiance: Some(radiance),
            capture: Some([albedo, normal_depth, emission]),
            relit: k,
            captured: captured_now,
        })
    }
}
