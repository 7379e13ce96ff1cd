//! Particles (Ghost of Tsushima's local fog, "haze lighting" mode for particles; docs/particles.md):
//! the scene's emitters' sprites at the sky's clock, sorted back to front and bounded on screen
//! on the CPU, composited over the hazed image before TAA.
//!
//! * `particles.draw` (`particles.wgsl`): a thread a pixel; each 16 x 16 tile marks the sprites
//!   whose screen rectangles overlap it and that come nearer than its farthest surface, and
//!   each pixel meets their planes back to front. A
//!   haze-lit sprite reads the haze's froxel light (`haze.light`, its `L_i`) there and the
//!   talk's multiple-scattering scale; a standard one is lit by the sun or moon and the sky's
//!   mean radiance. Writes `particles.radiance`.

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_scene::ParticleEmitter;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
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
    /// The pixels it may cover, x0, y0, x1, y1 inclusive ([`with_screen_rects`]).
    pub rect: [f32; 4],
}

/// `particles.wgsl`'s `ParticleParams` (the shader documents each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ParticleParams {
    pub sun_lux: [f32; 4],
    pub sun_dir: [f32; 4],
    pub sky: [f32; 4],
    pub ms: [f32; 4],
    /// x: sprites (set by [`Particles::record`]).
    pub count: [u32; 4],
}

impl ParticleParams {
    /// The frame's parameters: the sun or moon `(towards it, rgb lux)`, the sky's mean radiance
    /// (nits), and the haze's parameters when its light is there to read.
    /// This frame's parameters: lit by the frame context's sun where `direct_lighting.sun`
    /// lets it and a sky of `sky_lux` on the ground and a dark ground (about sky_lux / 2π on
    /// average over the sphere), through the haze `haze`.
    pub fn for_frame(
        cx: &crate::frame_context::FrameContext,
        s: &crate::settings::Settings,
        sky_lux: f32,
        haze: Option<&HazeParams>,
    ) -> Self {
        let sun = cx
            .lit_sun(s)
            .map(|sun| (sun.direction, sun.color * sun.illuminance_lux));
        let sky_mean = Vec3::splat(sky_lux / std::f32::consts::TAU);
        Self::new(&s.particles, sun, sky_mean, haze)
    }

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
            count: [0; 4],
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
                        rect: [0.0; 4],
                    },
                )
            })
        })
        .collect();
    out.sort_by(|a, b| b.0.total_cmp(&a.0));
    out.into_iter().map(|(_, p)| p).collect()
}

/// The emitters' sprites at the sky's clock of the frame context, back to front, with their
/// rectangles on its screen.
pub fn frame_sprites(
    emitters: &[ParticleEmitter],
    cx: &crate::frame_context::FrameContext,
) -> Vec<ParticleGpu> {
    let eye = Vec3::from_slice(&cx.view.position[..3]);
    let mut out = sprites(emitters, cx.clock_s, eye);
    with_screen_rects(&mut out, &cx.view);
    out
}

/// Sets each sprite's screen rectangle for `view`: the pixels its camera-facing square (which
/// holds its disc) covers, a pixel wider each side; the whole screen when a corner lies behind
/// the camera's near plane; none (x0 > x1 or y0 > y1) when it is off screen.
pub fn with_screen_rects(sprites: &mut [ParticleGpu], view: &View) {
    let view_proj = glam::Mat4::from_cols_array_2d(&view.view_proj);
    let cam = Vec3::from_slice(&view.position[..3]);
    let fwd = Vec3::from_slice(&view.forward_near[..3]);
    let [w, h] = [view.viewport[0], view.viewport[1]];
    for p in sprites {
        let centre = Vec3::from_slice(&p.position_radius[..3]);
        let radius = p.position_radius[3];
        let [_, right, up] = reference::sprite_basis(centre, cam, fwd);
        let mut lo = glam::Vec2::splat(f32::INFINITY);
        let mut hi = glam::Vec2::splat(f32::NEG_INFINITY);
        let mut behind = false;
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let c = view_proj * (centre + (right * x + up * y) * radius).extend(1.0);
            if c.w <= 1e-4 {
                behind = true;
                break;
            }
            let s = glam::Vec2::new((c.x / c.w * 0.5 + 0.5) * w, (0.5 - 0.5 * c.y / c.w) * h);
            lo = lo.min(s);
            hi = hi.max(s);
        }
        p.rect = if behind || !(lo.is_finite() && hi.is_finite()) {
            [0.0, 0.0, w - 1.0, h - 1.0]
        } else {
            [
                (lo.x - 1.0).floor().max(0.0),
                (lo.y - 1.0).floor().max(0.0),
                (hi.x + 1.0).ceil().min(w - 1.0),
                (hi.y + 1.0).ceil().min(h - 1.0),
            ]
        };
    }
}

/// What the particles keep between frames in the renderer's frame state: the sprites' buffer,
/// grown as needed.
#[derive(Clone, Debug, Default)]
pub struct ParticlesState {
    buffer: Option<wgpu::Buffer>,
}

pub struct Particles {
    draw: ComputePipeline,
    /// A 1 x 1 x 1 stand-in for the haze's light when there is no haze.
    no_haze: wgpu::Texture,
}

impl Particles {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let draw = ComputePipeline::new(ctx, lib, "particles/particles.wgsl", "main", &[])?;
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
        Ok(Self { draw, no_haze })
    }

    /// Composites `sprites` (with their screen rectangles) over `image` (the hazed image) into
    /// `particles.radiance`; returns `image` itself when no sprite is on screen. `haze`: the
    /// haze's parameters and its light (`haze.light`), `None` without haze.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut ParticlesState,
        view: &View,
        params: &ParticleParams,
        sprites: &[ParticleGpu],
        depth: Tex,
        haze: Option<(&HazeParams, Tex)>,
        image: Tex,
    ) -> Result<Tex> {
        if !sprites
            .iter()
            .any(|p| p.rect[0] <= p.rect[2] && p.rect[1] <= p.rect[3])
        {
            return Ok(image);
        }
        let ctx = g.ctx();
        let bytes = std::mem::size_of_val(sprites).max(std::mem::size_of::<ParticleGpu>()) as u64;
        let slot = &mut state.buffer;
        if slot.as_ref().is_none_or(|b| b.size() < bytes) {
            *slot = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("particles.sprites"),
                size: bytes.next_power_of_two().max(1024),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let buffer = slot.as_ref().expect("just made").clone();
        ctx.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(sprites));
        let sprite_buf = g.import_buffer("particles.sprites", &buffer);
        let (haze_params, light) = match haze {
            Some((p, t)) => (*p, t),
            // No haze: no extinction, and a light no pixel reads.
            None => (
                HazeParams::zeroed(),
                g.import_texture("particles.no_haze", &self.no_haze),
            ),
        };
        let params = ParticleParams {
            count: [sprites.len() as u32, 0, 0, 0],
            ..*params
        };
        let [w, h] = [view.viewport[0] as u32, view.viewport[1] as u32];
        let out = g.texture(
            "particles.radiance",
            TextureDesc::d2(w, h, crate::techniques::haze::RADIANCE_FORMAT),
        )?;
        g.pass("particles.draw")
            .constants(view)
            .constants(&params)
            .constants(&haze_params)
            .read(sprite_buf)
            .read(depth)
            .read(light)
            .sampler(SamplerKind::LinearClamp)
            .read(image)
            .write(out)
            .dispatch_threads(&self.draw, [w, h, 1])?;
        Ok(out)
    }
}
