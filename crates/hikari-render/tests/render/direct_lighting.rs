//! The deferred direct lighting against its CPU twin on a real G-buffer, and determinism.

use crate::common;

use glam::{Vec2, Vec3, Vec4};
use hikari_math::sh::Sh;
use hikari_render::techniques::direct_lighting::{self, LightingParams};
use hikari_render::techniques::sky::{self, reference::SkyTwin};
use hikari_render::techniques::{gbuffer, sun_shadows};
use hikari_render::{FrameSettings, Renderer};

/// The boxes scene with every kind of light and material the lighting pass handles: a point
/// light, a spot light, a rough metal, an anisotropic metal, an emitter.
fn lit_boxes() -> hikari_scene::Scene {
    use hikari_scene::{Anisotropy, Light};
    let mut scene = hikari_scene::builtin::boxes();
    scene.lights.push(Light::point_lumens(
        "lamp",
        Vec3::new(0.0, 2.5, 1.5),
        8000.0,
        Vec3::new(1.0, 0.8, 0.6),
    ));
    scene.lights.push(Light::spot(
        "spot",
        Vec3::new(-3.0, 5.0, 3.0),
        Vec3::new(0.3, -1.0, -0.4).normalize(),
        20000.0,
        0.2,
        0.5,
        Vec3::ONE,
    ));
    scene.materials[2].metalness = 1.0;
    scene.materials[2].roughness = 0.3;
    scene.materials[3].metalness = 1.0;
    scene.materials[3].roughness = 0.4;
    scene.materials[3].anisotropy = Some(Anisotropy {
        strength: 0.8,
        rotation: 0.6,
    });
    scene.materials[4].emissive_nits = Vec3::new(3000.0, 1500.0, 500.0);
    scene
}

fn settings_for(scene: &hikari_scene::Scene, w: u32, h: u32) -> FrameSettings {
    let mut s = common::small_frame_settings(scene, w, h);
    // The twin is of this pass alone: the area lights (tests/render/area_lights/) off, so the point
    // and spot lights stay here, unshadowed.
    s.settings.area_lights.enabled = false;
    s
}

/// What a comparison of the lighting pass with its twin found.
struct Compared {
    /// Sky pixels compared, and those skipped on the sun's or moon's disk.
    sky: usize,
    disk: usize,
    lit: usize,
    shadowed: usize,
    /// Surface pixels beyond tolerance, and the worst of them (1 = the tolerance).
    bad: usize,
    worst: f32,
    /// Sky pixels beyond tolerance, and the worst.
    sky_bad: usize,
    sky_worst: f32,
}

/// Renders `settings` and compares every pixel of `direct_lighting.radiance` with the CPU twin;
/// with the sky on, the twin is given the frame's deringed SH as read back from `sky.sh`, the
/// weather's balance and the sky twin for the sky pixels.
fn render_and_compare(scene: &hikari_scene::Scene, settings: &FrameSettings) -> Compared {
    let ctx = common::gpu_context();
    let (w, h) = (settings.width, settings.height);
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let mut frame_sky = None;
    let mut r = renderer
        .render_reading(settings, |o| {
            frame_sky = Some((o.sky.enabled, o.sky.params, o.sky.sky_lux));
            let g = &o.gbuffer;
            vec![
                g.depth.into(),
                g.normal.into(),
                g.albedo.into(),
                g.material.into(),
                g.emissive.into(),
                o.shadows.texels.into(),
                o.lit.into(),
                o.sky.sh.into(),
            ]
        })
        .unwrap();
    let (sky_enabled, sky_params, sky_lux) = frame_sky.unwrap();
    let texels: Vec<f32> =
        bytemuck::cast_slice::<u8, f32>(r.buffer("sun_shadows.texels").unwrap()).to_vec();
    let sh_buffer = bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec();
    let mut img = |n: &str| r.take_image(n).unwrap();
    let (depth, normal, albedo, material, emissive, hdr) = (
        img("gbuffer.depth"),
        img("gbuffer.normal"),
        img("gbuffer.albedo"),
        img("gbuffer.material"),
        img("gbuffer.emissive"),
        img("direct_lighting.radiance"),
    );
    let cpu = &renderer.scene().cpu;
    let cx = settings.context().unwrap();
    assert_eq!(
        cx.sky_lux, sky_lux,
        "the frame's sky is the frame context's"
    );
    let mut params = LightingParams::new(
        cx.sun.as_ref(),
        cpu.lights.len() as u32,
        cx.light_cutoff_lux,
        &settings.settings.direct_lighting,
    );
    assert_eq!(sky_enabled, settings.settings.sky.enabled);

    // The sky's light for the twin: the GPU's deringed SH (its projection is checked against
    // the sky twin in tests/render/sky.rs), the weather's balance, the sky twin for sky pixels.
    let sky_twin_atmosphere = if sky_enabled {
        params.use_sky(settings.settings.sky.sky);
        let weather = settings.settings.sky.weather().unwrap();
        Some((
            sky::atmosphere_for(&weather.atmosphere(), settings.settings.sky.table_sizes())
                .unwrap(),
            weather,
        ))
    } else {
        None
    };
    let sky_twin = sky_twin_atmosphere
        .as_ref()
        .map(|(a, _)| SkyTwin::new(a, sky_params));
    let sky_light = sky_twin_atmosphere.as_ref().map(|(_, weather)| {
        let mut sh = Sh::<Vec3, 9>::zero();
        for (c, x) in sh.coeffs.iter_mut().zip(&sh_buffer[9..18]) {
            *c = Vec3::new(x[0], x[1], x[2]);
        }
        direct_lighting::reference::SkyLight {
            sh,
            balance: {
                // The weather's knobs at this frame's sun elevation, as the frame takes them.
                let sky_settings = &settings.settings.sky;
                let k = cx.sky.as_ref().unwrap().knobs;
                debug_assert_eq!(weather.name, sky_settings.weather);
                [k.ambient_diffuse, k.ambient_specular]
            },
            background: sky_twin.as_ref(),
            probe_irradiance: None,
        }
    });

    let sun = cx.sun.clone().unwrap();
    let cascades = sun_shadows::fit_cascades(
        &settings.camera,
        w as f32 / h as f32,
        sun.direction,
        renderer.scene().bounds.unwrap(),
        &settings.settings.sun_shadows,
    );
    let shadow = sun_shadows::ShadowParams::new(
        &cascades,
        sun_shadows::depth_range(sun.direction, renderer.scene().bounds.unwrap()),
        &settings.settings.sun_shadows,
    );
    let view = hikari_render::view::View::new(&settings.camera, w, h);
    let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);

    let v4 = |p: [f32; 4]| Vec4::from_array(p);
    let mut c = Compared {
        sky: 0,
        disk: 0,
        lit: 0,
        shadowed: 0,
        bad: 0,
        worst: 0.0,
        sky_bad: 0,
        sky_worst: 0.0,
    };
    for y in 0..h {
        for x in 0..w {
            let d = depth.pixel(x, y)[0];
            let dir = gbuffer::reference::pixel_ray(inv, settings.camera.position, [x, y], [w, h]);
            let world = gbuffer::reference::world_from_depth(inv, [x, y], [w, h], d);
            let texel = direct_lighting::reference::Texel {
                depth: d,
                normal: v4(normal.pixel(x, y)),
                albedo: v4(albedo.pixel(x, y)),
                material: v4(material.pixel(x, y)),
                emissive: v4(emissive.pixel(x, y)),
            };
            let vis = if d > 0.0 {
                let n = hikari_render::reference::octahedral::decode(Vec2::new(
                    texel.normal.x,
                    texel.normal.y,
                ));
                sun_shadows::reference::visibility(&shadow, &texels, world, n)
            } else {
                1.0
            };
            // The sky twin draws no disks: pixels near one are not compared.
            if d <= 0.0
                && sky_enabled
                && [sky_params.sun, sky_params.moon]
                    .iter()
                    .any(|b| b[3] > 0.0 && dir.dot(Vec3::new(b[0], b[1], b[2])) > 0.999)
            {
                c.disk += 1;
                continue;
            }
            let want = direct_lighting::reference::shade_with_sky(
                &params,
                &cpu.lights,
                &texel,
                world,
                -dir,
                vis,
                sky_light.as_ref(),
            );
            let got = hdr.pixel(x, y);
            let mut px_worst = 0f32;
            for k in 0..3 {
                let tol = if d <= 0.0 {
                    // As tests/render/sky.rs: f16 output (2^-11 relative); f32 against f64 table
                    // arithmetic.
                    want[k].abs() * 5e-3 + want.max_element() * 1e-3 + 1e-6
                } else {
                    // f16 storage keeps 11 significant bits: 2^-11 relative, plus float noise
                    // in the BRDF near grazing angles.
                    want[k].abs() * 4e-3 + 2e-2
                };
                px_worst = px_worst.max((got[k] - want[k]).abs() / tol);
            }
            if d <= 0.0 {
                c.sky += 1;
                c.sky_bad += (px_worst > 1.0) as usize;
                c.sky_worst = c.sky_worst.max(px_worst);
                continue;
            }
            if vis < 0.5 {
                c.shadowed += 1;
            } else {
                c.lit += 1;
            }
            c.bad += (px_worst > 1.0) as usize;
            c.worst = c.worst.max(px_worst);
        }
    }
    c
}

#[test]
fn direct_lighting_matches_its_cpu_twin_on_a_real_gbuffer() {
    let scene = lit_boxes();
    let settings = settings_for(&scene, 96, 64);
    let (w, h) = (settings.width, settings.height);
    let c = render_and_compare(&scene, &settings);
    assert!(
        c.sky > 100 && c.lit > 1000 && c.shadowed > 100,
        "the view shows sky ({}), sunlit ({}) and shadowed ({}) surfaces",
        c.sky,
        c.lit,
        c.shadowed
    );
    assert!(
        c.sky_bad == 0,
        "{} placeholder sky pixels beyond tolerance; worst {}",
        c.sky_bad,
        c.sky_worst
    );
    // A shadow edge texel compared with a receiver depth within rounding may flip one PCF tap.
    assert!(
        c.bad * 500 <= (w * h) as usize,
        "{} pixels beyond tolerance; worst {}",
        c.bad,
        c.worst
    );
}

/// With the atmosphere on, the sky's deringed SH lights every surface (diffuse and specular,
/// scaled by the weather's balance) and the sky fills the background: both against the twin,
/// fed the frame's SH as read back from `sky.sh`. Morning (sun up) and night (the moon).
#[test]
fn direct_lighting_with_the_sky_matches_its_cpu_twin() {
    let scene = lit_boxes();
    for time in ["09:00", "23:30"] {
        let mut settings = settings_for(&scene, 96, 64);
        settings.settings.sky.enabled = true;
        // The twin has no clouds (tests/render/clouds.rs holds them to theirs).
        settings.settings.clouds.enabled = false;
        settings.settings.sky.table_quality = 0;
        settings.settings.sky.time = time.into();
        settings.sun = hikari_render::SunSource::Sky;
        let (w, h) = (settings.width, settings.height);
        let c = render_and_compare(&scene, &settings);
        assert!(
            c.sky > 100 && c.lit > 1000 && c.shadowed > 100,
            "{time}: the view shows sky ({}), sunlit ({}) and shadowed ({}) surfaces",
            c.sky,
            c.lit,
            c.shadowed
        );
        assert!(
            c.sky_bad == 0,
            "{time}: {} sky pixels beyond tolerance; worst {} ({} on a disk skipped)",
            c.sky_bad,
            c.sky_worst,
            c.disk
        );
        assert!(
            c.bad * 500 <= (w * h) as usize,
            "{time}: {} pixels beyond tolerance; worst {}",
            c.bad,
            c.worst
        );
    }
}

#[test]
fn two_renders_of_the_same_input_are_bitwise_equal() {
    let ctx = common::gpu_context();
    let scene = lit_boxes();
    let settings = settings_for(&scene, 80, 48);
    let mut first = Renderer::new(ctx, &scene).unwrap();
    let a = first.render(&settings, true).unwrap();
    let a2 = first.render(&settings, true).unwrap();
    let ctx2 = common::gpu_context();
    let mut second = Renderer::new(ctx2, &scene).unwrap();
    let c = second.render(&settings, true).unwrap();
    let c2 = second.render(&settings, true).unwrap();
    // Without TAA, consecutive frames of a still view are the same frame.
    let mut still = settings.clone();
    still.settings.taa.enabled = false;
    let mut third = Renderer::new(common::gpu_context(), &scene).unwrap();
    let b = third.render(&still, true).unwrap();
    let b2 = third.render(&still, true).unwrap();
    let bits = |f: &hikari_render::RenderedFrame| {
        let h: Vec<u32> = f
            .hdr
            .as_ref()
            .unwrap()
            .rgba
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect();
        let l: Vec<u32> = f
            .ldr
            .as_ref()
            .unwrap()
            .rgba
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect();
        (h, l)
    };
    assert!(
        bits(&b) == bits(&b2),
        "same renderer, consecutive frames, no TAA"
    );
    assert!(bits(&a) == bits(&b), "TAA leaves the first frame alone");
    assert!(bits(&a) == bits(&c), "two renderers");
    assert!(
        bits(&a2) == bits(&c2),
        "two renderers, second frames (jittered, blended)"
    );
    assert!(bits(&a2) != bits(&a), "the second frame is jittered");
    assert!(
        a.hdr
            .as_ref()
            .unwrap()
            .rgba
            .iter()
            .flatten()
            .all(|v| v.is_finite())
    );
}
