//! Particles: the talk's multiple-scattering ratio against the Henyey-Greenstein phase written
//! out here, and `particles.draw` against its CPU twin over a synthetic haze light, random
//! depths (sky, NaN) and a random background.

use crate::common;

use glam::{Vec3, Vec4};
use half::f16;
use hikari_render::graph::GraphRuntime;
use hikari_render::shader;
use hikari_render::techniques::haze::HazeParams;
use hikari_render::techniques::haze::settings::HazeSettings;
use hikari_render::techniques::particles::settings::ParticlesSettings;
use hikari_render::techniques::particles::{self, ParticleParams, Particles, reference as twin};
use hikari_render::view::View;
use hikari_scene::{Camera, ParticleEmitter, Sun};
use rand::{Rng, SeedableRng, rngs::SmallRng};

/// Henyey-Greenstein, per steradian, written out from its definition.
fn hg(cos: f64, g: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

#[test]
fn multiple_scattering_is_the_ratio_of_a_back_scattering_phase_to_the_hazes() {
    for (g, back, strength) in [(0.6, -0.15, 1.0), (0.3, -0.15, 0.5), (0.8, -0.3, 0.0)] {
        let (on_light_side, facing_light) = twin::multiple_scattering(g, back, strength);
        // The eye on the light's side sees light turned round (cos -1); facing it, straight on.
        let r_back = hg(-1.0, f64::from(back)) / hg(-1.0, f64::from(g));
        let r_fwd = hg(1.0, f64::from(back)) / hg(1.0, f64::from(g));
        let want_back = 1.0 + f64::from(strength) * (r_back - 1.0);
        assert!(
            (f64::from(on_light_side) - want_back).abs() < 1e-4 * want_back,
            "g {g}: {on_light_side} against {want_back}"
        );
        assert!(
            (f64::from(facing_light) - r_fwd).abs() < 1e-4 * r_fwd,
            "g {g}: {facing_light} against {r_fwd}"
        );
        // A forward-scattering haze under-lights sprites seen from the light's side.
        assert!(r_back > 1.0 && r_fwd < 1.0);
    }
}

fn camera() -> Camera {
    Camera {
        position: Vec3::new(0.0, 1.5, 6.0),
        target: Vec3::new(0.0, 1.0, 0.0),
        vfov_deg: 60.0,
        near: 0.1,
        ..Camera::default()
    }
}

/// `particles.draw` on the GPU over `background` (rgb, nits), with reverse-Z `depth` and, when
/// given, the haze's parameters and light grid (as stored); returns `particles.radiance`.
fn draw_on_gpu(
    ctx: &hikari_render::GpuContext,
    view: &View,
    params: &ParticleParams,
    sprites: &[particles::ParticleGpu],
    depth: &[f32],
    haze: Option<(&HazeParams, &[Vec4])>,
    background: &[Vec3],
) -> Vec<[f32; 4]> {
    let (w, h) = (view.viewport[0] as u32, view.viewport[1] as u32);
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let pass = Particles::new(ctx, &mut lib).unwrap();
    let depth_tex = common::texture_with_data(
        ctx,
        wgpu::TextureFormat::R32Float,
        w,
        h,
        bytemuck::cast_slice(depth),
    );
    use wgpu::util::DeviceExt;
    let light_tex = haze.map(|(hp, grid)| {
        let [gw, gh, gn, _] = hp.grid;
        let halves: Vec<f16> = grid
            .iter()
            .flat_map(|v| v.to_array())
            .map(f16::from_f32)
            .collect();
        ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("test.haze_light"),
                size: wgpu::Extent3d {
                    width: gw,
                    height: gh,
                    depth_or_array_layers: gn,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&halves),
        )
    });
    let bg: Vec<f16> = background
        .iter()
        .flat_map(|v| v.extend(1.0).to_array())
        .map(f16::from_f32)
        .collect();
    let image_tex = common::texture_with_data(
        ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&bg),
    );
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(ctx);
    let depth_t = g.import_texture("test.depth", &depth_tex);
    let light = match (haze, &light_tex) {
        (Some((hp, _)), Some(t)) => Some((hp, g.import_texture("haze.light", t))),
        _ => None,
    };
    let image = g.import_texture("test.image", &image_tex);
    let out = pass
        .record(
            &mut g,
            &mut Default::default(),
            view,
            params,
            sprites,
            depth_t,
            light,
            image,
        )
        .unwrap();
    g.readback(out);
    let r = g.execute().unwrap();
    r.image("particles.radiance").unwrap().rgba.clone()
}

/// Every pixel of the GPU's `got` within 1 % of the twin's composite over `background` (0.05
/// nits at least: f16); returns the twin's image.
fn assert_matches_twin(
    inputs: &twin::Inputs<'_>,
    sprites: &[particles::ParticleGpu],
    got: &[[f32; 4]],
    background: &[Vec3],
) -> Vec<Vec3> {
    let w = inputs.view.viewport[0] as u32;
    let mut worst = 0.0f32;
    let want: Vec<Vec3> = background
        .iter()
        .enumerate()
        .map(|(i, bg)| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let want = twin::composite_pixel(inputs, sprites, [x, y], *bg);
            let g = Vec4::from_array(got[i]).truncate();
            let err = ((g - want).abs() / want.abs().max(Vec3::splat(0.05))).max_element();
            assert!(err < 0.01, "pixel ({x}, {y}): {g} against {want}");
            worst = worst.max(err);
            want
        })
        .collect();
    println!("worst relative difference {worst:.5}");
    want
}

/// A sprite just in front of a wall, the whole view one depth: the tiles' depth cull must keep
/// it (their farthest surface is the wall, 0.6 m behind its centre) and the soft fade dims it
/// where it nears the wall. No haze: standard lighting, no extinction.
#[test]
fn a_sprite_just_before_a_wall_survives_the_depth_cull() {
    let ctx = common::gpu_context();
    let ctx = &ctx;
    // Tiles of 16 pixels span about 10 degrees here: the central ones' farthest surface is
    // within 2 % of the wall's 5.6 m, so an error of a metre or two in the cull shows.
    let (w, h) = (128u32, 96u32);
    let cam = camera();
    let view = View::new(&cam, w, h);
    let fwd = (cam.target - cam.position).normalize();
    let centre = cam.position + fwd * 5.0;
    // The wall: the plane through centre + 0.6 fwd facing the camera, as reverse-Z depth.
    let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);
    let vp = glam::Mat4::from_cols_array_2d(&view.view_proj);
    let depth: Vec<f32> = (0..w * h)
        .map(|i| {
            let ray = hikari_render::techniques::gbuffer::reference::pixel_ray(
                inv,
                cam.position,
                [i % w, i / w],
                [w, h],
            );
            let t = 5.6 / ray.dot(fwd);
            let c = vp * (cam.position + ray * t).extend(1.0);
            c.z / c.w
        })
        .collect();
    let mut sprites = vec![particles::ParticleGpu {
        position_radius: centre.extend(1.5).to_array(),
        albedo_opacity: [0.8, 0.7, 0.6, 0.9],
        rect: [0.0; 4],
    }];
    particles::with_screen_rects(&mut sprites, &view);
    let params = ParticleParams::new(
        &ParticlesSettings::default(),
        Some((Vec3::Y, Vec3::splat(1000.0))),
        Vec3::new(30.0, 40.0, 60.0),
        None,
    );
    let background = vec![Vec3::splat(0.25); (w * h) as usize];
    let got = draw_on_gpu(ctx, &view, &params, &sprites, &depth, None, &background);
    let inputs = twin::Inputs {
        view: &view,
        params: &params,
        haze: None,
        depth: &depth,
    };
    let want = assert_matches_twin(&inputs, &sprites, &got, &background);
    let lit = want
        .iter()
        .zip(&background)
        .filter(|(w, b)| (**w - **b).abs().max_element() > 0.05)
        .count();
    assert!(lit > 100, "only {lit} pixels show the sprite");
}

#[test]
fn the_draw_pass_matches_its_twin() {
    let ctx = common::gpu_context();
    let ctx = &ctx;
    let (w, h) = (64u32, 48u32);
    let mut rng = SmallRng::seed_from_u64(11);
    let cam = camera();
    let view = View::new(&cam, w, h);
    let sun = Sun {
        direction: Vec3::new(0.5, 0.4, -0.6).normalize(),
        illuminance_lux: 20_000.0,
        color: Vec3::new(1.0, 0.9, 0.8),
    };
    let hs = HazeSettings {
        grid_width: 16,
        grid_height: 12,
        slices: 24,
        layer_density: 0.05,
        layer_height_m: 2.0,
        ..HazeSettings::default()
    };
    let haze = HazeParams::new(&hs, "clear", Some(&sun), 0, 0.01, 2000.0);
    let [gw, gh, gn, _] = haze.grid;
    // The haze light as stored (L_i times albedo and scale): smooth plus noise, so that the
    // trilinear and bicubic reads differ.
    let grid: Vec<Vec4> = (0..gw * gh * gn)
        .map(|i| {
            let base = 0.2 + 0.1 * ((i % gw) as f32).sin();
            Vec4::new(
                base + rng.random::<f32>() * 0.3,
                base,
                0.1 + rng.random::<f32>() * 0.2,
                0.0,
            )
        })
        .collect();
    let grid = grid
        .iter()
        .map(|v| Vec4::from_array(v.to_array().map(|x| f16::from_f32(x).to_f32())))
        .collect::<Vec<_>>();
    // Sky along the top; surfaces 4 to 20 m away (reverse-Z depth near / z, near 0.1 m),
    // nearer ones (6 to 7.5 m, just behind the sprites) in the left half from row 16 (whole
    // 16 x 16 tiles), where the tiles cull
    // by depth: the sprites in front must survive it; a few NaN.
    let depth: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if y < h / 4 {
                0.0
            } else if i % 37 == 0 {
                f32::NAN
            } else if x < w / 2 && y >= 16 {
                0.1 / rng.random_range(6.0..7.5f32)
            } else {
                0.1 / rng.random_range(4.0..20.0f32)
            }
        })
        .collect();
    let background: Vec<Vec3> = (0..w * h)
        .map(|_| Vec3::new(rng.random(), rng.random(), rng.random()) * 0.5)
        .map(|v| Vec3::from_array(v.to_array().map(|x| f16::from_f32(x).to_f32())))
        .collect();
    let emitters = [
        ParticleEmitter {
            name: "haze-lit".into(),
            centre: Vec3::new(-0.5, 1.0, 0.0),
            half_extents: Vec3::new(1.5, 0.6, 1.5),
            count: 24,
            size_m: [0.4, 1.2],
            opacity: 0.9,
            haze_lit: true,
            seed: 3,
            ..Default::default()
        },
        ParticleEmitter {
            name: "standard".into(),
            centre: Vec3::new(0.8, 1.2, 1.0),
            half_extents: Vec3::new(1.0, 0.5, 1.0),
            count: 12,
            size_m: [0.3, 0.9],
            opacity: 0.5,
            albedo: Vec3::new(0.8, 0.6, 0.4),
            haze_lit: false,
            seed: 4,
            ..Default::default()
        },
    ];
    let mut sprites = particles::sprites(&emitters, 4321.0, cam.position);
    particles::with_screen_rects(&mut sprites, &view);
    assert!(sprites.len() > 30);
    let s = ParticlesSettings::default();
    let params = ParticleParams::new(
        &s,
        Some((sun.direction, sun.color * sun.illuminance_lux)),
        Vec3::new(300.0, 400.0, 600.0),
        Some(&haze),
    );

    let got = draw_on_gpu(
        ctx,
        &view,
        &params,
        &sprites,
        &depth,
        Some((&haze, &grid)),
        &background,
    );

    // The twin.
    let inputs = twin::Inputs {
        view: &view,
        params: &params,
        haze: Some((&haze, &grid)),
        depth: &depth,
    };
    assert_matches_twin(&inputs, &sprites, &got, &background);
    let (mut covered, mut standard, mut trilinear, mut bicubic) = (0, 0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let hits: Vec<_> = sprites
                .iter()
                .filter(|p| twin::fragment(&inputs, p, [x, y]).is_some())
                .collect();
            covered += usize::from(!hits.is_empty());
            let a: Vec<f32> = hits.iter().map(|p| p.albedo_opacity[3]).collect();
            standard += usize::from(a.iter().any(|&a| a > 0.0));
            trilinear += usize::from(a.iter().any(|&a| a < 0.0 && a >= -s.bicubic_opacity));
            bicubic += usize::from(a.iter().any(|&a| a < -s.bicubic_opacity));
        }
    }
    // Every branch drawn: standard lighting, the haze light read trilinear and bicubic.
    println!(
        "{covered} pixels covered: {standard} by standard \
         sprites, {trilinear} by faint haze-lit ones (trilinear), {bicubic} by bicubic ones"
    );
    assert!(covered > 500 && standard > 100 && trilinear > 20 && bicubic > 200);
}
