//! Particles (Ghost of Tsushima's local fog, "haze lighting" mode for particles; docs/particles.md):
//! the scene's emitters' sprites at the sky's clock, sorted back to front on the CPU, drawn as
//! camera-facing quads blended over the hazed image before TAA.
//!
//! * `particles.draw` (`particles.wgsl`): a raster pass, six vertices a sprite pulled from a
//!   storage buffer, premultiplied blending. A haze-lit sprite reads the haze's froxel light
//!   (`haze.light`, its `L_i`) at its fragment and the talk's multiple-scattering scale; a
//!   standard one is lit by the sun or moon and the sky's mean radiance.

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_scene::ParticleEmitter;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, SamplerKind, Tex};
use crate::pipeline::{RasterDesc, RasterPipeline};
use crate::shader::ShaderLibrary;
use crate::techniques::haze::HazeParams;
use crate::view::View;
use settings::ParticlesSettings;

/// One sprite on the GPU (`particles.wgsl`'s `ParticleGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ParticleGpu {
    /// xyz: centre (world, m); w: radius (m).
    pub position_radius: [f32; 4],
    /// rgb: albedo (standard lighting); a: opacity, negative for a haze-lit sprite.
    pub albedo_opacity: [f32; 4],
}

/// `particles.wgsl`'s `ParticleParams` (the shader documents each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ParticleParams {
    pub sun_lux: [f32; 4],
    pub sun_dir: [f32; 4],
    pub sky: [f32; 4],
    pub ms: [f32; 4],
}

impl ParticleParams {
    /// The frame's parameters: the sun or moon `(towards it, rgb lux)`, the sky's mean radiance
    /// (nits), and the haze's parameters when its light is there to read.
    pub fn new(
        s: &ParticlesSettings,
        sun: Option<(Vec3, Vec3)>,
        sky_mean: Vec3,
        haze: Option<&HazeParams>,
    ) -> Self {
        let (to_sun, lux) = sun.unwrap_or((Vec3::Y, Vec3::ZERO));
        let (ms_eye_on_light_side, ms_eye_facing_light, inv_scale) = match haze {
            Some(h) => {
                let [albedo, g, scale, _] = h.scatter;
                let (a, b) = if s.multiple_scattering {
                    reference::multiple_scattering(g, s.ms_asymmetry, s.ms_back_strength)
                } else {
                    (1.0, 1.0)
                };
                (a, b, 1.0 / (scale * albedo).max(1e-12))
            }
            None => (1.0, 1.0, 0.0),
        };
        Self {
            sun_lux: lux
                .extend(if haze.is_some() && s.haze_lighting {
                    1.0
                } else {
                    0.0
                })
                .to_array(),
            sun_dir: to_sun
                .normalize_or(Vec3::Y)
                .extend(s.bicubic_opacity)
                .to_array(),
            sky: sky_mean.extend(s.soft_fade).to_array(),
            ms: [
                ms_eye_on_light_side,
                ms_eye_facing_light,
                inv_scale,
                if haze.is_some() { 1.0 } else { 0.0 },
            ],
        }
    }
}

/// Every emitter's sprites at `time_s`, back to front from `eye`; sprites of no opacity are
/// left out.
pub fn sprites(emitters: &[ParticleEmitter], time_s: f64, eye: Vec3) -> Vec<ParticleGpu> {
    let mut out: Vec<(f32, ParticleGpu)> = emitters
        .iter()
        .flat_map(|e| {
            e.particles_at(time_s).filter(|p| p.opacity > 0.0).map(|p| {
                let sign = if e.haze_lit { -1.0 } else { 1.0 };
                (
                    p.position.distance_squared(eye),
                    ParticleGpu {
                        position_radius: p.position.extend(p.radius_m).to_array(),
                        albedo_opacity: e.albedo.extend(sign * p.opacity).to_array(),
                    },
                )
            })
        })
        .collect();
    out.sort_by(|a, b| b.0.total_cmp(&a.0));
    out.into_iter().map(|(_, p)| p).collect()
}

pub struct Particles {
    draw: RasterPipeline,
    /// The sprites, grown as needed.
    buffer: std::cell::RefCell<Option<wgpu::Buffer>>,
    /// A 1 x 1 x 1 stand-in for the haze's light when there is no haze.
    no_haze: wgpu::Texture,
}

impl Particles {
    pub fn new(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        let draw = RasterPipeline::new(
            ctx,
            lib,
            "particles/particles.wgsl",
            &RasterDesc {
                vertex_entry: "vs",
                fragment_entry: Some("fs"),
                color_formats: &[format],
                depth: None,
                cull_mode: None,
                blend: Some(wgpu::BlendState {
                    // Premultiplied colour; the image's alpha is kept.
                    color: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::One,
                        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                        operation: wgpu::BlendOperation::Add,
                    },
                    alpha: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::Zero,
                        dst_factor: wgpu::BlendFactor::One,
                        operation: wgpu::BlendOperation::Add,
                    },
                }),
            },
            &[],
        )?;
        let no_haze = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("particles.no_haze"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: crate::techniques::haze::GRID_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        Ok(Self {
            draw,
            buffer: std::cell::RefCell::new(None),
            no_haze,
        })
    }

    /// Draws `sprites` over `target` (the hazed image). `haze`: the haze's parameters and its
    /// light (`haze.light`), `None` without haze.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        view: &View,
        params: &ParticleParams,
        sprites: &[ParticleGpu],
        depth: Tex,
        haze: Option<(&HazeParams, Tex)>,
        target: Tex,
    ) -> Result<()> {
        if sprites.is_empty() {
            return Ok(());
        }
        let ctx = g.ctx();
        let bytes = std::mem::size_of_val(sprites) as u64;
        let mut slot = self.buffer.borrow_mut();
        if slot.as_ref().is_none_or(|b| b.size() < bytes) {
            *slot = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("particles.sprites"),
                size: bytes.next_power_of_two().max(1024),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let buffer = slot.as_ref().expect("just made").clone();
        drop(slot);
        ctx.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(sprites));
        let sprite_buf = g.import_buffer("particles.sprites", &buffer);
        let (haze_params, light) = match haze {
            Some((p, t)) => (*p, t),
            // No haze: no extinction, and a light no fragment reads.
            None => (
                HazeParams::zeroed(),
                g.import_texture("particles.no_haze", &self.no_haze),
            ),
        };
        let n = sprites.len() as u32;
        g.pass("particles.draw")
            .constants(view)
            .constants(params)
            .constants(&haze_params)
            .read(sprite_buf)
            .read(depth)
            .read(light)
            .sampler(SamplerKind::LinearClamp)
            .color(target, None)
            .draw(&self.draw, move |rp, _| rp.draw(0..6, 0..n))
    }
}
