//! The window's picture (`debug_view.display`) against its CPU twin, for every mapping; and
//! `Renderer::frame_into` showing the final image and a named texture.

use glam::Vec4;
use hikari_render::graph::GraphRuntime;
use hikari_render::shader;
use hikari_render::techniques::debug_view::{DebugView, Mapping, TARGET_FORMAT, reference};

use crate::common;

/// A 16x8 Rgba32Float source whose texels sweep each channel over [-1, 3], with a NaN and an
/// infinity among them, and octahedral normals in the first two channels' range.
fn source_texels(w: u32, h: u32) -> Vec<Vec4> {
    (0..w * h)
        .map(|i| {
            let t = i as f32 / (w * h - 1) as f32;
            match i {
                5 => Vec4::new(f32::NAN, 0.5, 0.5, 1.0),
                9 => Vec4::new(f32::INFINITY, 0.2, -0.3, 1.0),
                _ => Vec4::new(
                    -1.0 + 4.0 * t,
                    (t * 7.0).sin(),
                    3.0 * (1.0 - t),
                    t * t * 2.0,
                ),
            }
        })
        .collect()
}

#[test]
fn every_mapping_matches_its_twin() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let view = DebugView::new(&ctx, &mut lib).unwrap();
    let (w, h) = (16u32, 8u32);
    let texels = source_texels(w, h);
    let bytes: Vec<u8> = texels
        .iter()
        .flat_map(|v| bytemuck::bytes_of(&v.to_array()).to_vec())
        .collect();
    let source = common::texture_with_data(&ctx, wgpu::TextureFormat::Rgba32Float, w, h, &bytes);
    // The target twice the source's size: each source texel covers 2x2 target pixels.
    let target = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test target"),
        size: wgpu::Extent3d {
            width: 2 * w,
            height: 2 * h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: TARGET_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let mappings = [
        Mapping::Raw,
        Mapping::Radiance { ev100: -2.0 },
        Mapping::Normal,
        Mapping::Depth,
        Mapping::Scalar {
            channel: 2,
            white: 2.5,
        },
        Mapping::Luminance { ev100: -1.0 },
    ];
    let mut rt = GraphRuntime::new();
    for mapping in mappings {
        let mut g = rt.begin_frame(&ctx);
        let src = g.import_texture("test.source", &source);
        let dst = g.import_texture("test.target", &target);
        view.record(&mut g, src, &mapping, dst).unwrap();
        g.readback(dst);
        let r = g.execute().unwrap();
        let got = r.image("test.target").unwrap();
        let mut worst = 0.0f32;
        for y in 0..2 * h {
            for x in 0..2 * w {
                let want = reference::display(texels[(y / 2 * w + x / 2) as usize], &mapping);
                let g = got.pixel(x, y);
                for c in 0..3 {
                    worst = worst.max((g[c] - want[c]).abs());
                }
            }
        }
        // 8-bit quantisation (half a step) and f32 rounding in the transfer functions.
        assert!(
            worst <= 0.6 / 255.0 + 1e-4,
            "{mapping:?}: worst difference {worst} ({} steps)",
            worst * 255.0
        );
    }
}

#[test]
fn a_mapping_suits_the_name_it_shows() {
    let m = |n| Mapping::for_name(n, 10.0);
    assert_eq!(m("gbuffer.normal"), Mapping::Normal);
    assert_eq!(m("gbuffer.depth"), Mapping::Depth);
    assert!(matches!(
        m("ray_traced_gi.hit_distance"),
        Mapping::Scalar { .. }
    ));
    assert!(matches!(m("gi_denoiser.ao"), Mapping::Scalar { white, .. } if white == 1.0));
    assert!(matches!(
        m("direct_lighting.illuminance"),
        Mapping::Luminance { .. }
    ));
    assert_eq!(m("tonemap.ldr"), Mapping::Raw);
    assert!(matches!(m("direct_lighting.radiance"), Mapping::Radiance { ev100 } if ev100 == 10.0));
}

#[test]
fn frame_into_shows_the_final_image_or_any_texture_and_names_a_wrong_one() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let s = common::small_frame_settings(&scene, 48, 32);
    let mut r = hikari_render::Renderer::new(ctx, &scene).unwrap();
    r.set_frame(s).unwrap();
    let target = r.ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("window"),
        size: wgpu::Extent3d {
            width: 48,
            height: 32,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: TARGET_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let shown = r
        .frame_into(&target, &hikari_render::Display::default())
        .unwrap();
    for name in ["gbuffer.normal", "gbuffer.depth", "tonemap.ldr"] {
        assert!(
            shown.names.iter().any(|n| n == name),
            "{name} in {:?}",
            shown.names
        );
    }
    let normals = hikari_render::Display {
        source: Some("gbuffer.normal".into()),
        mapping: None,
    };
    r.frame_into(&target, &normals).unwrap();
    let wrong = hikari_render::Display {
        source: Some("gbuffer.nope".into()),
        mapping: None,
    };
    let e = r.frame_into(&target, &wrong).err().unwrap().to_string();
    assert!(
        e.contains("gbuffer.nope") && e.contains("gbuffer.normal"),
        "{e}"
    );
}
