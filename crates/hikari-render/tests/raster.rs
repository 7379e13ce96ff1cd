//! The compute rasteriser against rays through the same pixel (texel) centres, traced by
//! brute force on the CPU with hikari-bvh's watertight triangle test: the G-buffer's
//! visibility and the sun's shadow maps.

mod common;

use glam::{Mat4, Vec3, Vec4};
use hikari_bvh::reference::closest_hit_instances;
use hikari_bvh::{Instance, Mesh, Ray};
use hikari_render::passes::raster::QueueSizes;
use hikari_render::passes::sun_shadows;
use hikari_render::reference::gbuffer::{decode_id, pixel_ray};
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::Scene;

fn bvh_scene(scene: &Scene) -> (Vec<Mesh>, Vec<Instance>) {
    (
        hikari_render::scene_bvh::meshes(scene),
        hikari_render::scene_bvh::instances(scene),
    )
}

fn frame_settings(scene: &Scene, w: u32, h: u32) -> FrameSettings {
    common::small_frame_settings(scene, w, h)
}

fn mesh_first_triangles(scene: &Scene) -> Vec<u32> {
    let mut first = 0;
    scene
        .meshes
        .iter()
        .map(|m| {
            let f = first;
            first += m.indices.len() as u32 / 3;
            f
        })
        .collect()
}

#[test]
fn visibility_matches_rays_through_pixel_centres() {
    for scene in [
        hikari_scene::builtin::boxes(),
        hikari_scene::builtin::cornell(),
    ] {
        let Some(ctx) = common::gpu() else { return };
        // Wide enough that the ground's two triangles span more than 256 32x32 tiles and take
        // the large-triangle pass, while the boxes take the per-thread and tile passes.
        let (w, h) = (768u32, 480u32);
        let s = frame_settings(&scene, w, h);
        let mut renderer = Renderer::new(ctx, &scene).unwrap();
        let r = renderer
            .render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
            .unwrap();
        let vis: &[u32] = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap());
        let (meshes, instances) = bvh_scene(&scene);
        let firsts = mesh_first_triangles(&scene);
        let view = hikari_render::view::View::new(&s.camera, w, h);
        let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
        let vp = view.view_proj();
        let cpu = &renderer.scene().cpu;
        let (mut agree, mut differ, mut worst_depth) = (0, 0, 0f32);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let (id, depth_bits) = (vis[2 * i], vis[2 * i + 1]);
                let dir = pixel_ray(inv, s.camera.position, [x, y], [w, h]);
                let ray = Ray::new(s.camera.position, dir, s.camera.near, f32::INFINITY);
                let want = closest_hit_instances(&meshes, &instances, None, &ray);
                let got = (depth_bits != 0).then(|| {
                    let chunk = &cpu.chunks[(id / 64) as usize];
                    let mesh = scene.instances[chunk.instance as usize].mesh;
                    decode_id(cpu, id, firsts[mesh]).unwrap()
                });
                match (got, want) {
                    (None, None) => agree += 1,
                    (Some((inst, tri)), Some(hit))
                        if inst == hit.instance && tri == hit.primitive =>
                    {
                        agree += 1;
                        let p = s.camera.position + dir * hit.t;
                        let c = vp * p.extend(1.0);
                        let want_depth = c.z / c.w;
                        let got_depth = f32::from_bits(depth_bits);
                        worst_depth = worst_depth.max((got_depth - want_depth).abs() / want_depth);
                    }
                    _ => differ += 1,
                }
            }
        }
        // Pixel centres within rounding of a shared edge may go either way; nothing else.
        assert!(
            differ * 200 <= agree,
            "{differ} pixels differ from the rays, {agree} agree"
        );
        assert!(
            worst_depth < 1e-4,
            "worst relative depth error {worst_depth}"
        );
    }
}

#[test]
fn a_frame_whose_queues_overflow_is_drawn_again_without_losing_triangles() {
    if common::gpu().is_none() {
        return;
    }
    let scene = hikari_scene::builtin::boxes();
    let s = frame_settings(&scene, 256, 160);
    let visibility = |tiny: bool| {
        let mut renderer = Renderer::new(common::gpu().unwrap(), &scene).unwrap();
        if tiny {
            for t in ["gbuffer", "sun_shadows"] {
                renderer.raster_queues().set(
                    t,
                    QueueSizes {
                        entries: 4,
                        records: 2,
                    },
                );
            }
        }
        let r = renderer
            .render_reading(&s, |out| {
                vec![out.gbuffer.visibility.into(), out.shadows.texels.into()]
            })
            .unwrap();
        let grown = renderer.raster_queues().sizes("gbuffer", 0);
        let bytes = |n: &str| r.buffer(n).unwrap().to_vec();
        (
            bytes("gbuffer.visibility"),
            bytes("sun_shadows.texels"),
            grown,
        )
    };
    let (want_vis, want_shadow, _) = visibility(false);
    let (vis, shadow, grown) = visibility(true);
    assert!(
        grown.entries > 4 && grown.records > 2,
        "queues not grown: {grown:?}"
    );
    assert!(want_vis.iter().any(|&b| b != 0), "nothing drawn");
    assert!(
        vis == want_vis,
        "the G-buffer lost triangles to the overflow"
    );
    assert!(
        shadow == want_shadow,
        "the shadow maps lost triangles to the overflow"
    );
}

/// A unit sphere of `rings` x `segments` quads, outward-facing, sharing its vertices.
fn uv_sphere(segments: u32, rings: u32) -> hikari_scene::Mesh {
    let mut m = hikari_scene::Mesh {
        name: "sphere".into(),
        ..Default::default()
    };
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for k in 0..=segments {
            // The seam column repeats the first one exactly, so the mesh stays closed.
            let phi = std::f32::consts::TAU * (k % segments) as f32 / segments as f32;
            let p = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            m.positions.push(p);
            m.normals.push(p);
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for k in 0..segments {
            let (a, b) = (r * row + k, (r + 1) * row + k);
            m.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
        }
    }
    m
}

#[test]
fn a_closed_mesh_has_no_cracks_or_holes() {
    // A camera inside a closed, finely tessellated sphere: every pixel must see it. A crack
    // between triangles (a pixel centre claimed by neither) shows as sky.
    // Fine tessellation: per-thread and tile passes; coarse: the large-triangle pass.
    for (segments, rings) in [(96, 48), (6, 3), (4, 2)] {
        sphere_has_no_holes(segments, rings);
    }
}

fn sphere_has_no_holes(segments: u32, rings: u32) {
    let Some(ctx) = common::gpu() else { return };
    let mut scene = Scene::default();
    scene.meshes.push(uv_sphere(segments, rings));
    // Seen from inside: the inward faces are back faces of the outward-wound sphere.
    let mut m = hikari_scene::Material::diffuse("inside", Vec3::splat(0.5));
    m.double_sided = true;
    scene.materials.push(m);
    scene.instances.push(hikari_scene::Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::splat(20.0)),
    });
    scene.cameras.push(hikari_scene::Camera {
        name: "inside".into(),
        position: Vec3::new(0.3, 0.2, 0.1),
        target: Vec3::new(5.0, 1.0, 3.0),
        vfov_deg: 100.0,
        near: 0.1,
        up: Vec3::Y,
    });
    let s = frame_settings(&scene, 640, 480);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
        .unwrap();
    let vis: &[u32] = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap());
    let holes = vis.chunks(2).filter(|p| p[1] == 0).count();
    assert_eq!(
        holes, 0,
        "{holes} pixels see through the {segments}x{rings} sphere"
    );
}

#[test]
fn shadow_maps_match_rays_from_the_sun() {
    let Some(ctx) = common::gpu() else { return };
    let scene = hikari_scene::builtin::boxes();
    let s = frame_settings(&scene, 64, 48);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.shadows.texels.into()])
        .unwrap();
    let texels: &[f32] = bytemuck::cast_slice(r.buffer("sun_shadows.texels").unwrap());
    let sun = scene.sun.clone().unwrap();
    let cascades = sun_shadows::fit_cascades(
        &s.camera,
        64.0 / 48.0,
        sun.direction,
        renderer.scene().bounds.unwrap(),
        &s.settings.shadows,
    );
    let (meshes, instances) = bvh_scene(&scene);
    let res = s.settings.shadows.resolution;
    let (mut agree, mut differ, mut covered) = (0, 0, 0);
    for (c, cascade) in cascades.iter().enumerate() {
        let inv = cascade.view_proj.inverse();
        let vp = cascade.view_proj;
        for y in 0..res {
            for x in 0..res {
                let ndc = |z: f32| {
                    let u = (x as f32 + 0.5) / res as f32;
                    let v = (y as f32 + 0.5) / res as f32;
                    let p = inv * Vec4::new(u * 2.0 - 1.0, 1.0 - v * 2.0, z, 1.0);
                    p.truncate() / p.w
                };
                let (from, to) = (ndc(1.0), ndc(0.0));
                let dir = (to - from).normalize();
                let ray = Ray::new(from, dir, 0.0, (to - from).length());
                let want = closest_hit_instances(&meshes, &instances, None, &ray)
                    .map(|h| (vp * (from + dir * h.t).extend(1.0)).z)
                    .unwrap_or(0.0);
                let got = texels[(c as u32 * res * res + y * res + x) as usize];
                if want > 0.0 {
                    covered += 1;
                }
                if (got - want).abs() <= 1e-5 {
                    agree += 1;
                } else {
                    differ += 1;
                }
            }
        }
    }
    assert!(covered > 1000, "the maps see the scene ({covered} texels)");
    assert!(
        differ * 200 <= agree,
        "{differ} texels differ from the rays, {agree} agree"
    );
}

#[test]
fn cached_shadow_maps_give_the_image_a_full_redraw_gives() {
    let scene = hikari_scene::builtin::boxes();
    let first = frame_settings(&scene, 96, 64);
    let mut moved = first.clone();
    moved.camera.position += Vec3::new(0.37, 0.05, -0.21);
    moved.camera.target += Vec3::new(0.3, 0.0, 0.1);
    let hdr_bits = |f: &hikari_render::RenderedFrame| -> Vec<u32> {
        f.hdr
            .as_ref()
            .unwrap()
            .rgba
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    let drew_shadows = |f: &hikari_render::RenderedFrame| {
        f.result
            .timings
            .iter()
            .any(|t| t.name == "sun_shadows.rasterize")
    };

    let Some(ctx) = common::gpu() else { return };
    let mut cached = Renderer::new(ctx, &scene).unwrap();
    let a = cached.render(&first, true).unwrap();
    let b = cached.render(&moved, true).unwrap();
    assert!(
        drew_shadows(&a) && drew_shadows(&b),
        "new and moved views draw their maps"
    );
    // Cascades left behind by the per-frame limit catch up in the next frames.
    let mut c = cached.render(&moved, true).unwrap();
    let mut catch_up = 0;
    while drew_shadows(&c) {
        catch_up += 1;
        assert!(catch_up < 4, "a still view keeps drawing its maps");
        c = cached.render(&moved, true).unwrap();
    }

    let mut uncached_settings = moved.clone();
    uncached_settings.settings.shadows.cache = false;
    let mut fresh = Renderer::new(common::gpu().unwrap(), &scene).unwrap();
    let d = fresh.render(&uncached_settings, true).unwrap();
    let e = fresh.render(&uncached_settings, true).unwrap();
    assert!(
        drew_shadows(&e),
        "without the cache every frame draws its maps"
    );
    assert!(
        hdr_bits(&c) == hdr_bits(&d),
        "still view: cache and full redraw differ"
    );
}
