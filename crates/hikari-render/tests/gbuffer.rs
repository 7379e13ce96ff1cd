//! `gbuffer.resolve` against its CPU twin (`gbuffer::reference::resolve`): interpolated
//! normals, vertex colours, per-vertex interior mask, sampled textures, material factors,
//! motion vectors under camera motion, view depth and instance ids.

mod common;

use glam::{Mat4, Vec2, Vec3, Vec4};
use hikari_render::techniques::gbuffer;
use hikari_render::techniques::gbuffer::reference::ResolvedTexel;
use hikari_render::{FrameSettings, Renderer, Settings};
use hikari_scene::{Material, Mesh, Scene, Texture, TextureRef, Wrap};

/// 64x64 RGBA8 with R = G = u and B = v, linear ramps: every mip level of a linear ramp is the
/// same ramp, so trilinear filtering at any level returns the bilinear value.
fn ramp_texture(name: &str) -> Texture {
    let n = 64u32;
    let mut data = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let u = ((x as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            let v = ((y as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            data.extend([u, u, v, 255]);
        }
    }
    Texture {
        name: name.into(),
        width: n,
        height: n,
        data,
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
    }
}

fn solid_texture(rgba: [u8; 4]) -> Texture {
    Texture {
        name: "solid".into(),
        width: 4,
        height: 4,
        data: rgba.repeat(16),
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
    }
}

fn textured_scene() -> Scene {
    let mut scene = hikari_scene::builtin::boxes();
    let quad = Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-3.0, 0.01, -3.0),
            Vec3::new(3.0, 0.01, -3.0),
            Vec3::new(3.0, 0.01, 3.0),
            Vec3::new(-3.0, 0.01, 3.0),
        ],
        normals: vec![
            Vec3::Y,
            Vec3::new(0.2, 1.0, 0.0).normalize(),
            Vec3::new(0.0, 1.0, 0.3).normalize(),
            Vec3::Y,
        ],
        indices: vec![0, 2, 1, 0, 3, 2],
        // Away from the ramp's ends, where coarser mips stop being the same ramp.
        uvs: vec![
            Vec2::new(0.25, 0.25),
            Vec2::new(0.75, 0.25),
            Vec2::new(0.75, 0.75),
            Vec2::new(0.25, 0.75),
        ],
        colors: Some(vec![
            Vec4::new(1.0, 1.0, 1.0, 1.0),
            Vec4::new(0.5, 1.0, 0.8, 1.0),
            Vec4::new(1.0, 0.3, 0.6, 1.0),
            Vec4::new(0.7, 0.7, 1.0, 1.0),
        ]),
        interior: vec![0.0, 1.0, 0.5, 0.25],
        ..Default::default()
    };
    scene.meshes.push(quad);
    scene.textures.push(ramp_texture("ramp"));
    scene.textures.push(solid_texture([200, 150, 100, 255]));
    scene.materials.push(Material {
        name: "textured".into(),
        base_color: Vec3::new(0.9, 0.8, 1.0),
        roughness: 0.9,
        metalness: 0.7,
        base_color_texture: Some(TextureRef::new(1)),
        metallic_roughness_texture: Some(TextureRef::new(0)),
        occlusion_texture: Some(TextureRef::new(0)),
        occlusion_strength: 0.5,
        emissive_nits: Vec3::new(10.0, 20.0, 30.0),
        ..Material::default()
    });
    scene.instances.push(hikari_scene::Instance {
        mesh: scene.meshes.len() - 1,
        material: scene.materials.len() - 1,
        transform: Mat4::from_rotation_y(0.3),
    });
    scene
}

#[test]
fn resolve_matches_its_cpu_twin() {
    let Some(ctx) = common::gpu() else { return };
    let scene = textured_scene();
    let (w, h) = (128u32, 96u32);
    let camera = scene.cameras[0].clone();
    let mut prev = camera.clone();
    prev.position += Vec3::new(0.3, -0.1, 0.2);
    prev.target += Vec3::new(0.1, 0.05, 0.0);
    let s = FrameSettings {
        width: w,
        height: h,
        camera,
        prev_camera: Some(prev.clone()),
        sun: scene.sun.clone(),
        settings: Settings {
            // The G-buffer does not depend on the sky: skip the atmosphere's table build.
            sky: hikari_render::settings::SkySettings {
                enabled: false,
                ..Default::default()
            },
            ..Settings::default()
        },
    };
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut r = renderer
        .render_reading(&s, |o| {
            let g = &o.gbuffer;
            vec![
                g.visibility.into(),
                g.normal.into(),
                g.albedo.into(),
                g.material.into(),
                g.motion.into(),
                g.emissive.into(),
                g.instance.into(),
            ]
        })
        .unwrap();
    let vis: Vec<u32> = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap()).to_vec();
    let mut img = |n: &str| r.take_image(n).unwrap();
    let (normal, albedo, material, motion, emissive, instance) = (
        img("gbuffer.normal"),
        img("gbuffer.albedo"),
        img("gbuffer.material"),
        img("gbuffer.motion"),
        img("gbuffer.emissive"),
        img("gbuffer.instance"),
    );
    let view = hikari_render::view::View::with_previous(&s.camera, &prev, w, h);
    let cpu = &renderer.scene().cpu;
    let textured_instance = (scene.instances.len() - 1) as u32;
    let (mut checked, mut textured, mut failures) = (0, 0, Vec::new());
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if vis[2 * i + 1] == 0 {
                assert_eq!(
                    instance.pixel(x, y)[0],
                    u32::MAX as f32,
                    "sky has no instance"
                );
                continue;
            }
            let want: ResolvedTexel =
                gbuffer::reference::resolve(&scene, cpu, &view, [x, y], vis[2 * i]).unwrap();
            checked += 1;
            if want.instance == textured_instance {
                textured += 1;
            }
            let nv = normal.pixel(x, y);
            let n = hikari_render::reference::octahedral::decode(Vec2::new(nv[0], nv[1]));
            let a = albedo.pixel(x, y);
            let m = material.pixel(x, y);
            let mv = motion.pixel(x, y);
            let e = emissive.pixel(x, y);
            let close = |got: f32, want: f32, abs: f32, rel: f32| {
                (got - want).abs() <= abs + rel * want.abs()
            };
            let checks = [
                ("normal", n.dot(want.normal) > (0.5f32).to_radians().cos()),
                ("albedo r", close(a[0], want.base_color.x, 2.5 / 255.0, 0.0)),
                ("albedo g", close(a[1], want.base_color.y, 2.5 / 255.0, 0.0)),
                ("albedo b", close(a[2], want.base_color.z, 2.5 / 255.0, 0.0)),
                ("interior", close(a[3], want.interior, 1.0 / 255.0, 0.0)),
                // Ramp texels are quantised to 1/255 before filtering.
                ("roughness", close(m[0], want.roughness, 3.0 / 255.0, 0.0)),
                ("metalness", close(m[1], want.metalness, 3.0 / 255.0, 0.0)),
                ("anisotropy", close(m[2], want.anisotropy, 1.0 / 255.0, 0.0)),
                ("occlusion", close(m[3], want.occlusion, 3.0 / 255.0, 0.0)),
                ("motion x", close(mv[0], want.motion.x, 0.02, 2e-3)),
                ("motion y", close(mv[1], want.motion.y, 0.02, 2e-3)),
                ("view depth", close(mv[2], want.view_depth, 0.0, 2e-3)),
                ("emissive", close(e[2], want.emissive.z, 0.0, 2e-3)),
                ("instance", instance.pixel(x, y)[0] == want.instance as f32),
            ];
            for (what, ok) in checks {
                if !ok {
                    failures.push(format!(
                        "({x}, {y}) {what}: got {a:?} {m:?} {mv:?} {e:?}, want {want:?}"
                    ));
                }
            }
        }
    }
    assert!(
        checked > 4000 && textured > 300,
        "{checked} surface pixels, {textured} textured"
    );
    assert!(
        failures.is_empty(),
        "{} failures, first: {}",
        failures.len(),
        failures[..failures.len().min(3)].join("\n")
    );
}
