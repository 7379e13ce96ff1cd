//! Each GPU pass against its CPU twin, on small inputs.

mod common;

use glam::{Vec2, Vec3, Vec4};
use hikari_render::graph::GraphRuntime;
use hikari_render::passes::direct_lighting::SunParams;
use hikari_render::passes::placeholder_tonemap::{PlaceholderTonemap, TonemapParams};
use hikari_render::reference;
use hikari_render::shader::{self, ShaderLibrary};
use hikari_render::{FrameSettings, Renderer};
use rand::{Rng, SeedableRng, rngs::SmallRng};

#[test]
fn placeholder_tonemap_matches_its_cpu_twin() {
    let Some(ctx) = common::gpu() else { return };
    let (w, h) = (64u32, 32u32);
    let mut rng = SmallRng::seed_from_u64(7);
    let mut hdr: Vec<[f32; 4]> = (0..w * h)
        .map(|_| {
            // Log-uniform over the range a frame sees, from starlight to the sun's reflection.
            let mut c = [0f32; 4];
            for v in c.iter_mut().take(3) {
                *v = 10f32.powf(rng.random_range(-3.0..4.8));
            }
            c[3] = 1.0;
            c
        })
        .collect();
    hdr[0] = [f32::NAN, -5.0, 0.0, 1.0];
    hdr[1] = [0.0, 0.0, 0.0, 1.0];
    let halves: Vec<half::f16> = hdr
        .iter()
        .flatten()
        .map(|&v| half::f16::from_f32(v))
        .collect();
    let input = common::texture_with_data(
        &ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&halves),
    );

    let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features)).unwrap();
    let tonemap = PlaceholderTonemap::new(&ctx, &mut lib).unwrap();
    let params = TonemapParams::from_ev100(12.0);
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let hdr_tex = g.import_texture("test.hdr", &input);
    let ldr = tonemap.record(&mut g, hdr_tex, [w, h], &params).unwrap();
    g.readback(ldr);
    let r = g.execute().unwrap();
    let out = r.image("placeholder_tonemap.ldr").unwrap();

    let mut worst = 0i32;
    for (i, px) in halves.chunks(4).enumerate() {
        let rgb = [px[0].to_f32(), px[1].to_f32(), px[2].to_f32()];
        let want = reference::placeholder_tonemap::apply(rgb, params.exposure[0]);
        for (got, exp) in out.rgba[i].iter().zip(want) {
            let diff = (got * 255.0).round() as i32 - (exp * 255.0).round() as i32;
            worst = worst.max(diff.abs());
        }
    }
    // One 8-bit step: the GPU's pow and the rounding of the unorm store may differ by that.
    assert!(worst <= 1, "largest difference {worst} steps");
    assert_eq!(
        &out.rgba[0][..3],
        &[0.0, 0.0, 0.0],
        "NaN and negatives become black"
    );
}

#[test]
fn direct_lighting_matches_its_cpu_twin_on_a_real_gbuffer() {
    let Some(ctx) = common::gpu() else { return };
    let scene = hikari_scene::builtin::boxes();
    let settings = FrameSettings {
        width: 96,
        height: 64,
        camera: scene.cameras[0].clone(),
        ev100: 14.0,
    };
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    renderer.runtime.set_dumps(vec![
        "gbuffer.depth".into(),
        "gbuffer.normal".into(),
        "gbuffer.albedo".into(),
    ]);
    let frame = renderer.render(&settings, true).unwrap();
    let img = |n: &str| frame.result.image(n).unwrap();
    let (depth, normal, albedo) = (
        img("gbuffer.depth"),
        img("gbuffer.normal"),
        img("gbuffer.albedo"),
    );
    let hdr = frame.hdr.as_ref().unwrap();
    let params = SunParams::new(scene.sun.as_ref());
    let view = hikari_render::view::View::new(&settings.camera, settings.width, settings.height);
    let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);

    let (mut sky, mut lit, mut worst) = (0, 0, 0f32);
    for y in 0..settings.height {
        for x in 0..settings.width {
            let want = if depth.pixel(x, y)[0] <= 0.0 {
                sky += 1;
                // The ray through the pixel centre, from a point on the near plane.
                let uv = (Vec2::new(x as f32, y as f32) + 0.5)
                    / Vec2::new(settings.width as f32, settings.height as f32);
                let near = inv * Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
                let dir = (near.truncate() / near.w - settings.camera.position).normalize();
                reference::direct_lighting::clamp(reference::direct_lighting::sky_placeholder(
                    &params, dir,
                ))
            } else {
                lit += 1;
                let n = normal.pixel(x, y);
                let a = albedo.pixel(x, y);
                reference::direct_lighting::surface(
                    &params,
                    Vec2::new(n[0], n[1]),
                    Vec3::new(a[0], a[1], a[2]),
                )
            };
            let got = hdr.pixel(x, y);
            for c in 0..3 {
                // f16 storage keeps 11 significant bits: 2^-11 relative, plus float noise.
                let err = (got[c] - want[c]).abs() / (want[c].abs() * 2e-3 + 1e-2);
                worst = worst.max(err);
            }
        }
    }
    assert!(
        sky > 100 && lit > 1000,
        "the view shows both sky ({sky}) and surfaces ({lit})"
    );
    assert!(worst <= 1.0, "worst error {worst} of the tolerance");
}

#[test]
fn two_renders_of_the_same_input_are_bitwise_equal() {
    let Some(ctx) = common::gpu() else { return };
    let scene = hikari_scene::builtin::boxes();
    let settings = FrameSettings {
        width: 80,
        height: 48,
        camera: scene.cameras[0].clone(),
        ev100: 14.0,
    };
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
