//! The sky (issue 16): the atmosphere's tables on the GPU, resampled every frame at the sun's
//! and moon's angles, the sky drawn where no geometry is, and the sky's deringed L2 SH as the
//! ambient light.
//!
//! * Tables (transmittance, and Rayleigh and Mie inscattering divided by their phases over
//!   [mu, mu_s, r]): built by the GPU passes `sky.tables.*` ([`gpu_build`]) into persistent
//!   3D and 2D textures, or with `sky.tables_on_gpu = false` built on the CPU by
//!   hikari-atmosphere (the passes' twin) and uploaded; either way rebuilt only when the
//!   atmosphere's parameters (the weather) or the table sizes change. The CPU build is cached
//!   per parameters ([`atmosphere_for`]), shared with the `hikari sky` command; with the GPU
//!   build, the few CPU-side lookups (the ground's radiance, the sky's lux for the exposure
//!   meter) read a small CPU build ([`SCALAR_TABLE_QUALITY`]).
//! * `sky.resample`: the multiple scattering (`rayleigh − rayleigh_single`) at this frame's sun
//!   and moon zenith angles into a 2D array [mu, r] (sun, moon), cubic along mu_s. The single
//!   scattering is read per pixel from the 3D tables (`sky.rayleigh_single`, `sky.mie`, with the
//!   scattering distances in alpha) with the Earth-shadow and azimuth terms of
//!   hikari-atmosphere's `sky_radiance`, at light angles that vary across the sky.
//! * `sky.sh`: 4096 directions of the sky (no disks) to L2 SH, deringed, in one dispatch (16
//!   workgroups project; the last to finish sums and derings: `sh.wgsl`).
//! * The shared WGSL modules `hikari::sky` (binding set `sky`: `sky_inscatter`,
//!   `sky_background`, `sky_transmittance`) and `hikari::sky_ambient` (binding set
//!   `sky_ambient`: irradiance and specular from the SH); the deferred lighting draws the
//!   sky with them where depth is 0 and lights surfaces with the SH.
//!
//! CPU twin of every pass: [`reference`].

pub mod gpu_build;
pub mod lights;
pub mod reference;
pub mod settings;
pub mod weather;

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use hikari_atmosphere::geometry::{Shell, coord_from_unit};
use hikari_atmosphere::{Atmosphere, AtmosphereParams, TableSizes};
use hikari_scene::Sun;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::frame_context::FrameContext;
use crate::graph::{BindingSet, Buf, FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use crate::techniques::clouds::CloudsFrame;
use gpu_build::{TableBuilder, TableTargets, WorkLayout};
use lights::SkyLights;
use settings::SkySettings;
use weather::ArtistKnobs;

/// The per-frame parameters of `hikari::sky` (see `lookup.wgsl` for each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct SkyParams {
    pub sun: [f32; 4],
    pub moon: [f32; 4],
    pub disks: [f32; 4],
    pub shell: [f32; 4],
    pub table: [f32; 4],
    pub light_coords: [f32; 4],
    pub rec709_from_working: [[f32; 4]; 3],
    pub white: [f32; 4],
    pub transmittance_size: [f32; 4],
    pub ground: [f32; 4],
}

/// What `sky.resample` needs: [`SkyParams::table`] and [`SkyParams::light_coords`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ResampleParams {
    pub table: [f32; 4],
    pub light_coords: [f32; 4],
}

/// Layers of `sky.resampled`: the multiple scattering (`rayleigh − rayleigh_single`) at the
/// sun's and at the moon's zenith angle.
/// The sky without the atmosphere (`sky.enabled` off): radiance (nits) under the default
/// 100000 lux sun, a clear-day blue zenith and a paler horizon, of the order of a real clear
/// sky (a few thousand nits). It scales with the sun's illuminance, so night skies are dark.
pub const PLACEHOLDER_SKY_ZENITH: glam::Vec3 = glam::Vec3::new(1800.0, 3200.0, 6500.0);
pub const PLACEHOLDER_SKY_HORIZON: glam::Vec3 = glam::Vec3::new(6000.0, 7000.0, 8000.0);

pub const RESAMPLED_LAYERS: u32 = 2;

/// The per-frame parameters of `hikari::sky_ambient`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct SkyAmbientParams {
    /// x: diffuse scale, y: specular scale.
    pub balance: [f32; 4],
}

/// Below this sun (or moon) zenith cosine the scattering tables end (hikari-atmosphere's
/// `MU_S_MIN`, 12° below the horizon); a light lower than that lights no sky.
pub const MU_S_MIN: f32 = hikari_atmosphere::geometry::MU_S_MIN as f32;

/// With the tables built on the GPU, the CPU-side lookups of a frame (the ground's radiance in
/// [`SkyParams`], the sky's horizontal lux) read a CPU build at this `table_quality`: a few
/// tens of ms once per weather instead of the full build, and within a few per cent of it.
pub const SCALAR_TABLE_QUALITY: u32 = 0;

/// The CPU atmosphere for `params` at `sizes`, shared by every caller that asks for the same
/// ([`Atmosphere::shared`]).
pub fn atmosphere_for(params: &AtmosphereParams, sizes: TableSizes) -> Result<Arc<Atmosphere>> {
    let a = Atmosphere::shared(params, sizes)
        .map_err(|e| RenderError::Graph(format!("sky: atmosphere: {e}")))?;
    log::debug!(
        "sky: atmosphere tables built in {:.0} ms",
        a.report.build_ms
    );
    Ok(a)
}

/// The sky's CPU side of one frame, resolved in the frame context: the sun and moon as the
/// sky sees them, the weather's knobs at the sun's elevation, the sky's own illuminance on the
/// ground, and the CPU atmosphere whose lookups the frame makes (the full tables with
/// `sky.tables_on_gpu` off, else a small build of the same parameters).
#[derive(Clone, Debug)]
pub struct FrameSky {
    /// The sun and the moon from the date, time and place, except that a fixed directional
    /// light (a scene's own sun) takes the sun's place and the moon goes.
    pub lights: SkyLights,
    pub knobs: ArtistKnobs,
    /// The sky's illuminance on a horizontal plane at the ground, lux (0 with `sky.sky` off).
    pub sky_lux: f32,
    pub atmosphere: Arc<Atmosphere>,
    pub params: AtmosphereParams,
    /// The GPU tables' sizes.
    pub sizes: TableSizes,
}

impl FrameSky {
    pub fn new(s: &SkySettings, fixed_sun: Option<&Sun>) -> Result<Self> {
        let mut lights = SkyLights::new(s)?;
        if let Some(d) = fixed_sun {
            lights.sun.direction = d.direction.normalize();
            lights.sun.elevation_deg =
                f64::from(lights.sun.direction.y.clamp(-1.0, 1.0).asin().to_degrees());
            lights.moon.extraterrestrial_lux = 0.0;
        }
        let knobs = frame_knobs(s, &lights);
        if !s.sky {
            lights.sun.extraterrestrial_lux = 0.0;
            lights.moon.extraterrestrial_lux = 0.0;
        }
        // The tables follow the weather alone; the time of day moves only the knobs.
        let (params, sizes) = s.table_key()?;
        let atmosphere = if s.tables_on_gpu {
            atmosphere_for(&params, settings::table_sizes(SCALAR_TABLE_QUALITY))?
        } else {
            atmosphere_for(&params, sizes)?
        };
        let sky_lux = if s.sky {
            [&lights.sun, &lights.moon]
                .iter()
                .map(|b| (sky_lux(b.extraterrestrial_lux, b.direction), b.direction))
                .filter(|(lux, _)| *lux > 0.0)
                .map(|(lux, dir)| {
                    let zenith = dir.y.clamp(-1.0, 1.0).acos();
                    lights::luminance(atmosphere.sky_irradiance(0.0, zenith, Vec3::splat(lux)))
                })
                .sum::<f32>()
                * knobs.sky_brightness
        } else {
            0.0
        };
        Ok(Self {
            lights,
            knobs,
            sky_lux,
            atmosphere,
            params,
            sizes,
        })
    }
}

fn rows(m: [[f64; 3]; 3]) -> [[f32; 4]; 3] {
    m.map(|r| [r[0] as f32, r[1] as f32, r[2] as f32, 0.0])
}

/// Extraterrestrial illuminance of a light for the sky: none once the tables no longer cover
/// it, fading over the last degree above that.
fn sky_lux(lux: f32, dir: Vec3) -> f32 {
    let fade_from = (MU_S_MIN.acos() - 1f32.to_radians()).cos();
    let f = ((dir.y - MU_S_MIN) / (fade_from - MU_S_MIN)).clamp(0.0, 1.0);
    lux * f
}

impl SkyParams {
    /// The parameters for `lights` over `atmosphere`, seen from `camera_altitude_km`.
    pub fn new(
        atmosphere: &Atmosphere,
        lights: &SkyLights,
        s: &SkySettings,
        camera_altitude_km: f32,
    ) -> Self {
        Self::with_sizes(
            atmosphere,
            atmosphere.tables.sizes,
            lights,
            s,
            camera_altitude_km,
        )
    }

    /// The same for GPU tables at `sizes`, with `atmosphere` (same parameters, any sizes)
    /// giving the CPU-side lookups.
    pub fn with_sizes(
        atmosphere: &Atmosphere,
        sizes: TableSizes,
        lights: &SkyLights,
        s: &SkySettings,
        camera_altitude_km: f32,
    ) -> Self {
        let p = &atmosphere.params;
        let shell = Shell::new(p.bottom_radius_km, p.top_radius_km);
        let [nmu, nmus, nr] = sizes.scattering;
        let coord = |dir: Vec3| {
            let u = coord_from_unit(shell.x_mu_s(f64::from(dir.y)), nmus);
            (u * nmus as f64 - 0.5) as f32
        };
        let brightness = frame_knobs(s, lights).sky_brightness;
        let white = atmosphere.to_working(Vec3::ONE);
        let sun_lux = sky_lux(lights.sun.extraterrestrial_lux, lights.sun.direction);
        let moon_lux = sky_lux(lights.moon.extraterrestrial_lux, lights.moon.direction);
        // The ground: Lambertian, lit by the direct light that reaches it and by the sky.
        let mut ground = Vec3::ZERO;
        for (body, lux) in [(&lights.sun, sun_lux), (&lights.moon, moon_lux)] {
            if lux > 0.0 {
                let zenith = body.direction.y.clamp(-1.0, 1.0).acos();
                let direct = atmosphere.sun_illuminance_at_ground(zenith)
                    / p.solar_illuminance_lux as f32
                    * lux
                    * body.direction.y.max(0.0);
                let sky = atmosphere.sky_irradiance(0.0, zenith, Vec3::splat(lux));
                ground += (direct + sky) * (p.ground_albedo as f32 / std::f32::consts::PI);
            }
        }
        Self {
            sun: lights.sun.direction.normalize().extend(sun_lux).to_array(),
            moon: lights
                .moon
                .direction
                .normalize()
                .extend(moon_lux)
                .to_array(),
            disks: [
                lights.sun.angular_radius,
                lights.moon.angular_radius,
                lights.moon_illuminated_fraction,
                1.0,
            ],
            shell: [
                p.bottom_radius_km as f32,
                p.top_radius_km as f32,
                shell.h as f32,
                camera_altitude_km.max(0.0),
            ],
            table: [nmu as f32, nmus as f32, nr as f32, p.mie_g as f32],
            light_coords: [
                coord(lights.sun.direction),
                coord(lights.moon.direction),
                brightness,
                0.0,
            ],
            rec709_from_working: rows(p.color_space.to_rec709()),
            white: [white[0] as f32, white[1] as f32, white[2] as f32, 0.0],
            transmittance_size: [
                sizes.transmittance[0] as f32,
                sizes.transmittance[1] as f32,
                0.0,
                0.0,
            ],
            ground: {
                let w = atmosphere.to_working(ground * brightness);
                [w[0] as f32, w[1] as f32, w[2] as f32, 0.0]
            },
        }
    }
}

/// The weather's artist knobs for this frame's sun (the settings' weather; clear if it names
/// none, as validation refuses that before a frame).
pub fn frame_knobs(s: &SkySettings, lights: &SkyLights) -> ArtistKnobs {
    s.knobs(lights.sun.elevation_deg).unwrap_or_else(|_| {
        settings::Weather::by_name("clear")
            .expect("clear is a weather")
            .knobs_at(lights.sun.elevation_deg)
    })
}

/// The sky of one frame, for the techniques that read it.
#[derive(Clone, Copy, Debug)]
pub struct SkyFrame {
    /// Whether the atmosphere ran (else the placeholders light the frame).
    pub enabled: bool,
    pub params: SkyParams,
    /// `sky.resampled`: [mu, r] x [`RESAMPLED_LAYERS`] layers, Rgba32Float.
    pub resampled: Tex,
    /// `sky.sh`: 9 raw then 9 deringed RGB coefficients (vec4 each), nits.
    pub sh: Buf,
    /// Binding set `sky` of `hikari::sky`.
    pub lookup: BindingSet,
    /// Binding set `sky_ambient` of `hikari::sky_ambient`.
    pub ambient: BindingSet,
    /// Illuminance of the sky alone on a horizontal plane at the ground, in lux (luminance of
    /// the CPU model's sky irradiance), for the placeholder exposure meter: at dawn the sky
    /// outshines the low sun.
    pub sky_lux: f32,
    /// The weather's artist knobs at this frame's sun elevation (neutral with the sky off),
    /// including the exposure hint for the exposure issue.
    pub knobs: ArtistKnobs,
}

struct Uploaded {
    params: AtmosphereParams,
    sizes: TableSizes,
    atmosphere: Arc<Atmosphere>,
    rayleigh: wgpu::Texture,
    rayleigh_single: wgpu::Texture,
    mie: wgpu::Texture,
    transmittance: wgpu::Texture,
}

/// The sky's four tables in this frame's graph, and the CPU atmosphere for its CPU-side
/// lookups.
struct FrameTables {
    atmosphere: Arc<Atmosphere>,
    rayleigh: Tex,
    rayleigh_single: Tex,
    mie: Tex,
    transmittance: Tex,
}

/// Uploads `t` as an Rgba32Float texture; `alpha`, when given, is its fourth channel (the
/// scattering distances: `(table, channel)`).
fn upload(
    ctx: &GpuContext,
    name: &str,
    t: &hikari_atmosphere::table::Table,
    alpha: Option<(&hikari_atmosphere::table::Table, usize)>,
) -> wgpu::Texture {
    let [nx, ny, nz] = t.size;
    let texels: Vec<[f32; 4]> = t
        .data
        .iter()
        .enumerate()
        .map(|(i, v)| [v[0], v[1], v[2], alpha.map_or(0.0, |(a, c)| a.data[i][c])])
        .collect();
    ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(name),
            size: wgpu::Extent3d {
                width: nx as u32,
                height: ny as u32,
                depth_or_array_layers: nz as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: if nz > 1 {
                wgpu::TextureDimension::D3
            } else {
                wgpu::TextureDimension::D2
            },
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&texels),
    )
}

/// What the sky keeps between frames in the renderer's frame state: its tables on the GPU.
#[derive(Clone, Default)]
pub struct SkyState {
    /// The CPU-built tables uploaded (`sky.tables_on_gpu` off).
    uploaded: Option<Arc<Uploaded>>,
    /// What the persistent GPU-built tables hold now.
    gpu_built: Option<(AtmosphereParams, TableSizes)>,
}

impl std::fmt::Debug for SkyState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SkyState")
            .field("uploaded", &self.uploaded.as_ref().map(|u| u.sizes))
            .field("gpu_built", &self.gpu_built.as_ref().map(|b| b.1))
            .finish()
    }
}

impl SkyState {
    /// The tables of `params` at `sizes` on the GPU, built (on the CPU) and uploaded only when
    /// they differ from the last frame's.
    fn tables(
        &mut self,
        ctx: &GpuContext,
        params: &AtmosphereParams,
        sizes: TableSizes,
    ) -> Result<Arc<Uploaded>> {
        let held = &mut self.uploaded;
        if let Some(u) = held.as_ref()
            && u.params == *params
            && u.sizes == sizes
        {
            return Ok(u.clone());
        }
        let atmosphere = atmosphere_for(params, sizes)?;
        let t = &atmosphere.tables;
        let u = Arc::new(Uploaded {
            params: params.clone(),
            sizes,
            rayleigh: upload(ctx, "sky.rayleigh", &t.rayleigh, None),
            rayleigh_single: upload(
                ctx,
                "sky.rayleigh_single",
                &t.rayleigh_single,
                Some((&t.scattering_distance, 0)),
            ),
            mie: upload(ctx, "sky.mie", &t.mie, Some((&t.scattering_distance, 1))),
            transmittance: upload(ctx, "sky.transmittance", &t.transmittance, None),
            atmosphere: atmosphere.clone(),
        });
        *held = Some(u.clone());
        Ok(u)
    }
}

pub struct Sky {
    resample: ComputePipeline,
    sh: ComputePipeline,
    /// `sh.wgsl` with CLOUDS: the sky's SH seen through the clouds.
    sh_clouds: ComputePipeline,
    builder: TableBuilder,
}

impl Sky {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            resample: ComputePipeline::new(ctx, lib, "sky/resample.wgsl", "main", &[])?,
            sh: ComputePipeline::new(ctx, lib, "sky/sh.wgsl", "project_dering", &[])?,
            sh_clouds: ComputePipeline::new(
                ctx,
                lib,
                "sky/sh.wgsl",
                "project_dering",
                &[("CLOUDS", naga_oil::compose::ShaderDefValue::Bool(true))],
            )?,
            builder: TableBuilder::new(ctx, lib)?,
        })
    }

    /// The GPU table builder (for tests and timing: [`TableBuilder::build_and_read`]).
    pub fn table_builder(&self) -> &TableBuilder {
        &self.builder
    }

    /// This frame's tables: persistent textures the `sky.tables.*` passes fill when the
    /// parameters changed (or the textures are new), else CPU-built uploads.
    fn frame_tables<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut SkyState,
        s: &SkySettings,
        fs: &FrameSky,
    ) -> Result<FrameTables> {
        let (params, sizes) = (&fs.params, fs.sizes);
        if !s.tables_on_gpu {
            let u = state.tables(g.ctx(), params, sizes)?;
            return Ok(FrameTables {
                atmosphere: u.atmosphere.clone(),
                rayleigh: g.import_texture("sky.rayleigh", &u.rayleigh),
                rayleigh_single: g.import_texture("sky.rayleigh_single", &u.rayleigh_single),
                mie: g.import_texture("sky.mie", &u.mie),
                transmittance: g.import_texture("sky.transmittance", &u.transmittance),
            });
        }
        let (d3, d2) = gpu_build::table_descs(&sizes);
        let layout = WorkLayout::new(&sizes, params.max_scattering_orders);
        let (rayleigh, fresh_r) = g.persistent_texture("sky.rayleigh", d3)?;
        let (rayleigh_single, fresh_s) = g.persistent_texture("sky.rayleigh_single", d3)?;
        let (mie, fresh_m) = g.persistent_texture("sky.mie", d3)?;
        let (transmittance, fresh_t) = g.persistent_texture("sky.transmittance", d2)?;
        let (work, fresh_w) = g.persistent_buffer("sky.tables.work", layout.bytes())?;
        let built = &mut state.gpu_built;
        let current = built
            .as_ref()
            .is_some_and(|(p, z)| p == params && *z == sizes);
        if !current || fresh_r || fresh_s || fresh_m || fresh_t || fresh_w {
            let to = TableTargets {
                rayleigh,
                rayleigh_single,
                mie,
                transmittance,
                work,
            };
            self.builder.record(g, params, &sizes, to)?;
            *built = Some((params.clone(), sizes));
        }
        Ok(FrameTables {
            atmosphere: fs.atmosphere.clone(),
            rayleigh,
            rayleigh_single,
            mie,
            transmittance,
        })
    }

    /// Adds the sky's passes for the frame context's sky, seen from its camera and lit by its
    /// directional light. `clouds` are this frame's clouds, which enter the sky's SH (the
    /// ambient light of every pass that reads it) where they are drawn and `clouds_in_sh`.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut SkyState,
        cx: &FrameContext,
        s: &SkySettings,
        clouds: &CloudsFrame,
        clouds_in_sh: bool,
    ) -> Result<SkyFrame> {
        let (fs, directional) = (cx.sky.as_ref(), cx.sun.as_ref());
        // The camera's height above the ground.
        let camera_altitude_km = cx.view.position[1].max(0.0) / 1000.0;
        let sh = g.buffer("sky.sh", 18 * 16)?;
        let Some(fs) = fs.filter(|_| s.enabled) else {
            return self.disabled(g, sh);
        };
        let u = self.frame_tables(g, state, s, fs)?;
        let sizes = fs.sizes;
        let (lights, knobs) = (&fs.lights, fs.knobs);
        let mut params = SkyParams::with_sizes(&u.atmosphere, sizes, lights, s, camera_altitude_km);
        let horizontal_sky_lux = fs.sky_lux;
        if !s.sun {
            params.disks[3] = 0.0;
        }
        let (rayleigh, rayleigh_single, mie, transmittance) =
            (u.rayleigh, u.rayleigh_single, u.mie, u.transmittance);
        let [nmu, _, nr] = sizes.scattering;
        let resampled = g.texture(
            "sky.resampled",
            TextureDesc::d2_array(
                nmu as u32,
                nr as u32,
                RESAMPLED_LAYERS,
                wgpu::TextureFormat::Rgba32Float,
            ),
        )?;
        g.pass("sky.resample")
            .constants(&ResampleParams {
                table: params.table,
                light_coords: params.light_coords,
            })
            .read(rayleigh)
            .read(rayleigh_single)
            .write(resampled)
            .dispatch_threads(&self.resample, [nmu as u32, nr as u32, RESAMPLED_LAYERS])?;
        let lookup = g
            .binding_set("sky")
            .constants(&params)
            .read(resampled)
            .read(transmittance)
            .read(rayleigh_single)
            .read(mie)
            .finish();
        // 16 workgroups' partial sums, and their count, which the last workgroup resets.
        let partials = g.buffer("sky.sh_partials", 64 * 9 * 16)?;
        let (done, _) = g.persistent_buffer("sky.sh_done", 4)?;
        let in_sh = clouds_in_sh && clouds.drawn;
        let clear = if in_sh {
            g.buffer("sky.sh_clear", 18 * 16)?
        } else {
            sh
        };
        g.pass("sky.sh")
            .write(partials)
            .write(clear)
            .write(done)
            .set(lookup)
            .set(clouds.lookup)
            .dispatch(&self.sh, [16, 1, 1])?;
        if in_sh {
            // As the deferred lighting lights the clouds it draws: the directional light.
            let sun_lux = directional
                .filter(|_| clouds.params.sun[3] > 0.0)
                .map_or(Vec3::ZERO, |d| d.color * d.illuminance_lux);
            g.pass("sky.sh_clouds")
                .write(partials)
                .write(sh)
                .write(done)
                .read(clear)
                .constants(&sun_lux.extend(0.0).to_array())
                .set(lookup)
                .set(clouds.lookup)
                .dispatch(&self.sh_clouds, [16, 1, 1])?;
        }
        let ambient = g
            .binding_set("sky_ambient")
            .constants(&SkyAmbientParams {
                balance: [knobs.ambient_diffuse, knobs.ambient_specular, 0.0, 0.0],
            })
            .read(sh)
            .finish();
        Ok(SkyFrame {
            enabled: true,
            params,
            resampled,
            sh,
            lookup,
            ambient,
            sky_lux: horizontal_sky_lux,
            knobs,
        })
    }

    fn disabled<'r>(&'r self, g: &mut FrameGraph<'r>, sh: Buf) -> Result<SkyFrame> {
        let resampled = g.texture(
            "sky.resampled",
            TextureDesc::d2_array(1, 1, RESAMPLED_LAYERS, wgpu::TextureFormat::Rgba32Float),
        )?;
        let transmittance = g.texture(
            "sky.transmittance",
            TextureDesc::d2(1, 1, wgpu::TextureFormat::Rgba32Float),
        )?;
        let d3 = TextureDesc::d3(1, 1, 1, wgpu::TextureFormat::Rgba32Float);
        let rayleigh_single = g.texture("sky.rayleigh_single", d3)?;
        let mie = g.texture("sky.mie", d3)?;
        g.pass("sky.clear")
            .uses(sh, true)
            // Never read with the sky off; wgpu zeroes them.
            .uses(resampled, true)
            .uses(transmittance, true)
            .uses(rayleigh_single, true)
            .uses(mie, true)
            .encode(move |enc, res| enc.clear_buffer(res.buffer(sh), 0, None))?;
        let params = SkyParams::zeroed();
        let lookup = g
            .binding_set("sky")
            .constants(&params)
            .read(resampled)
            .read(transmittance)
            .read(rayleigh_single)
            .read(mie)
            .finish();
        let ambient = g
            .binding_set("sky_ambient")
            .constants(&SkyAmbientParams::zeroed())
            .read(sh)
            .finish();
        Ok(SkyFrame {
            enabled: false,
            params,
            resampled,
            sh,
            lookup,
            ambient,
            sky_lux: 0.0,
            knobs: ArtistKnobs::NEUTRAL,
        })
    }
}
