//! The deferred direct lighting against its CPU twin on a real G-buffer, and determinism.

mod common;

use glam::{Vec2, Vec3, Vec4};
use hikari_render::techniques::direct_lighting::{self, LightingParams};
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
    common::small_frame_settings(scene, w, h)
}

#[test]
fn direct_lighting_matches_its_cpu_twin_on_a_real_gbuffer() {
    let Some(ctx) = common::gpu() else { return };
    let scene = lit_boxes();
    let settings = settings_for(&scene, 96, 64);
    let (w, h) = (settings.width, settings.height);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut r = renderer
        .render_reading(&settings, |o| {
            let g = &o.gbuffer;
            vec![
                g.depth.into(),
                g.normal.into(),
                g.albedo.into(),
                g.material.into(),
                g.emissive.into(),
                o.shadows.texels.into(),
                o.hdr.into(),
            ]
        })
        .unwrap();
    let texels: Vec<f32> =
        bytemuck::cast_slice::<u8, f32>(r.buffer("sun_shadows.texels").unwrap()).to_vec();
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
    let params = LightingParams::new(
        settings.sun.as_ref(),
        cpu.lights.len() as u32,
        settings.metered_lux(),
        &settings.settings.direct_lighting,
    );
    let sun = settings.sun.clone().unwrap();
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
    let (mut sky, mut lit, mut shadowed, mut bad, mut worst) = (0, 0, 0, 0, 0f32);
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
                emissive: v4(emissive.pixel(x, y)).truncate(),
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
            if d <= 0.0 {
                sky += 1;
            } else if vis < 0.5 {
                shadowed += 1;
            } else {
                lit += 1;
            }
            let want =
                direct_lighting::reference::shade(&params, &cpu.lights, &texel, world, -dir, vis);
            let got = hdr.pixel(x, y);
            let mut px_worst = 0f32;
            for c in 0..3 {
                // f16 storage keeps 11 significant bits: 2^-11 relative, plus float noise in
                // the BRDF near grazing angles.
                let err = (got[c] - want[c]).abs() / (want[c].abs() * 4e-3 + 2e-2);
                px_worst = px_worst.max(err);
            }
            if px_worst > 1.0 {
                bad += 1;
            }
            worst = worst.max(px_worst);
        }
    }
    assert!(
        sky > 100 && lit > 1000 && shadowed > 100,
        "the view shows sky ({sky}), sunlit ({lit}) and shadowed ({shadowed}) surfaces"
    );
    // A shadow edge texel compared with a receiver depth within rounding may flip one PCF tap.
    assert!(
        bad * 500 <= (w * h) as usize,
        "{bad} pixels beyond tolerance; worst {worst}"
    );
}

#[test]
fn two_renders_of_the_same_input_are_bitwise_equal() {
    let Some(ctx) = common::gpu() else { return };
    let scene = lit_boxes();
    let settings = settings_for(&scene, 80, 48);
    let mut first = Renderer::new(ctx, &scene).unwrap();
    let a = first.render(&settings, true).unwrap();
    let b = first.render(&settings, true).unwrap();
    let ctx2 = common::gpu().unwrap();
    let mut second = Renderer::new(ctx2, &scene).unwrap();
    let c = second.render(&settings, true).unwrap();
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
    assert!(bits(&a) == bits(&b), "same renderer, consecutive frames");
    assert!(bits(&a) == bits(&c), "two renderers");
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
