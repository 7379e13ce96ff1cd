//! The frame's scene BVH (`scene_rt`), on the CPU: the culled per-frame TLAS finds what brute
//! force over every instance finds for rays inside the kept region; a refitted swaying tree
//! gives the hits of its deformed mesh (brute force and a fresh build); the refit scheduler
//! keeps to its budget and leaves nothing stale for ever; lamp shells stay out of shadows.

use glam::{Mat4, Vec2, Vec3};
use hikari_bvh::reference::{closest_hit_instances, closest_hit_mesh, random_dir, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Ray};
use hikari_render::scene_bvh;
use hikari_render::scene_rt::{FrameBvh, SceneRtSettings, kept_instances};
use hikari_scene::{Deformation, Instance, Light, Material, Mesh, Scene, shapes};

/// A tapered column, vertically subdivided so that a sway bends it.
fn tree(height: f32, phase: f32) -> Mesh {
    let profile: Vec<Vec2> = (0..=8)
        .map(|k| {
            let y = height * k as f32 / 8.0;
            Vec2::new(0.6 - 0.05 * k as f32, y)
        })
        .collect();
    let mut m = shapes::lathe(&profile, 12).expect("a valid profile");
    m.deformation = Some(Deformation::Sway {
        amplitude_m: 0.8,
        frequency_hz: 0.4,
        phase,
        direction: Vec3::new(1.0, 0.0, 0.3),
        base_y: 0.0,
        height_m: height,
    });
    m
}

/// A 16 x 16 grid of boxes 8 m apart, and `trees` swaying trees (each its own mesh) among
/// them.
fn grid_scene(trees: usize) -> Scene {
    let mut scene = Scene {
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        meshes: vec![shapes::cube()],
        ..Default::default()
    };
    for i in 0..16 {
        for j in 0..16 {
            let p = Vec3::new(i as f32 * 8.0 - 60.0, 1.0, j as f32 * 8.0 - 60.0);
            scene.instances.push(Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_translation(p) * Mat4::from_scale(Vec3::new(3.0, 2.0, 3.0)),
            });
        }
    }
    for t in 0..trees {
        scene.meshes.push(tree(5.0 + t as f32 * 0.5, t as f32));
        let p = Vec3::new(
            t as f32 * 8.0 - 56.0,
            0.0,
            4.0 - 60.0 + 8.0 * (t % 3) as f32,
        );
        scene.instances.push(Instance {
            mesh: scene.meshes.len() - 1,
            material: 0,
            transform: Mat4::from_translation(p),
        });
    }
    scene
}

fn view_proj(camera: Vec3, target: Vec3) -> Mat4 {
    let cam = hikari_scene::Camera {
        position: camera,
        target,
        vfov_deg: 50.0,
        near: 0.1,
        ..Default::default()
    };
    cam.projection(1.5) * cam.view()
}

#[test]
fn culled_tlas_finds_the_closest_hits_of_every_instance_inside_the_kept_region() {
    let mut scene = grid_scene(4);
    // A ground under everything: rays that miss the boxes end on it, not in the void.
    scene.meshes.push(shapes::plane(140.0));
    scene.instances.push(Instance {
        mesh: scene.meshes.len() - 1,
        material: 0,
        transform: Mat4::IDENTITY,
    });
    let mut bvh = FrameBvh::new(&scene).unwrap();
    let camera = Vec3::new(-55.0, 6.0, -55.0);
    let target = Vec3::new(0.0, 0.0, -40.0);
    let vp = view_proj(camera, target);
    let s = SceneRtSettings {
        cull_margin_m: 12.0,
        keep_radius_m: 20.0,
        ..Default::default()
    };
    let frame = bvh.update(camera, &vp, &s).unwrap();
    // The rule must actually drop instances, or the test proves nothing.
    assert!(
        frame.stats.instances_culled > 50 && frame.stats.instances_kept > 10,
        "{:?}",
        frame.stats
    );
    assert_eq!(
        frame.stats.instances_kept + frame.stats.instances_culled,
        scene.instances.len()
    );
    let meshes = scene_bvh::meshes(&scene);
    let inv = vp.inverse();
    let mut rng = SplitMix64::new(18);
    // What the bare frustum keeps: hits outside it show that the margin is needed and kept.
    let (tight, _) = kept_instances(
        &bvh.instances,
        &bvh.blases,
        camera,
        &vp,
        &SceneRtSettings {
            cull_margin_m: 0.0,
            keep_radius_m: 0.0,
            ..Default::default()
        },
    );
    let mut beyond_frustum = 0;
    let mut hits = 0;
    let ground = (scene.instances.len() - 1) as u32;
    for k in 0..6000 {
        // Half the rays start on screen (a random pixel, a random depth up to 80 m) and travel
        // at most the margin; half start within `keep_radius - length` of the camera, in any
        // direction, behind it too.
        let (origin, len) = if k % 2 == 0 {
            // Every other one near the left or right edge, where neighbours lie just outside.
            let x = if k % 4 == 0 {
                (0.85 + 0.15 * rng.next_f32()) * if rng.next_f32() < 0.5 { -1.0 } else { 1.0 }
            } else {
                rng.next_f32() * 2.0 - 1.0
            };
            let ndc = Vec3::new(x, rng.next_f32() * 2.0 - 1.0, 1.0);
            let far = inv.project_point3(ndc.truncate().extend(0.5));
            let dir = (far - camera).normalize();
            (
                camera + dir * (0.2 + 80.0 * rng.next_f32()),
                s.cull_margin_m,
            )
        } else {
            let len = 8.0;
            let r = (s.keep_radius_m - len) * rng.next_f32();
            (camera + random_dir(&mut rng) * r, len)
        };
        let ray = Ray::new(origin, random_dir(&mut rng), 0.0, len);
        let got = frame.gi.closest_hit(&bvh.blases, &ray);
        let want = closest_hit_instances(&meshes, &bvh.instances, None, &ray);
        hits += usize::from(want.is_some_and(|h| h.instance != ground));
        beyond_frustum +=
            usize::from(k % 2 == 0 && want.is_some_and(|h| !tight.contains(&h.instance)));
        if let Err(e) = same_hit(got, want) {
            panic!("ray {k} {ray:?}: {e}");
        }
    }
    assert!(hits > 300, "only {hits} rays hit a box or a tree");
    assert!(
        beyond_frustum > 20,
        "only {beyond_frustum} on-screen rays hit outside the bare frustum"
    );
}

#[test]
fn refitted_swaying_tree_hits_like_its_deformed_mesh() {
    let scene = grid_scene(1);
    let tree_mesh = scene.meshes.len() - 1;
    let mut bvh = FrameBvh::new(&scene).unwrap();
    let t = 1.3;
    let s = SceneRtSettings {
        time_s: Some(t),
        cull: false,
        ..Default::default()
    };
    let frame = bvh.update(Vec3::ZERO, &Mat4::IDENTITY, &s).unwrap();
    assert_eq!(frame.refitted, vec![tree_mesh]);
    assert_eq!(bvh.shown_time(tree_mesh), Some(t));
    let (positions, _) = scene.meshes[tree_mesh].deformed(t);
    let deformed = hikari_bvh::Mesh::new(
        positions.clone(),
        scene.meshes[tree_mesh]
            .indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    );
    let fresh = Blas::from_mesh("fresh", &deformed, &BuildOptions::default()).unwrap();
    let rest = &scene_bvh::meshes(&scene)[tree_mesh];
    let refitted = &bvh.blases[tree_mesh];
    let mut rng = SplitMix64::new(7);
    let (mut hits, mut moved) = (0, 0);
    for k in 0..4000 {
        // Rays from around the tree's crown towards a random point of its height band.
        let origin = Vec3::new(0.0, 3.0, 0.0) + random_dir(&mut rng) * 4.0;
        let aim = Vec3::new(
            rng.next_f32() * 2.0 - 1.0,
            5.0 * rng.next_f32(),
            rng.next_f32() * 2.0 - 1.0,
        );
        let ray = Ray::new(origin, (aim - origin).normalize(), 0.0, f32::INFINITY);
        let want = closest_hit_mesh(&deformed, &ray);
        hits += usize::from(want.is_some());
        if let Err(e) = same_hit(refitted.intersect(&ray), want) {
            panic!("ray {k}: refitted vs brute force: {e}");
        }
        if let Err(e) = same_hit(fresh.intersect(&ray), want) {
            panic!("ray {k}: fresh build vs brute force: {e}");
        }
        moved += usize::from(same_hit(closest_hit_mesh(rest, &ray), want).is_err());
    }
    assert!(hits > 1000, "only {hits} hits");
    // The rest pose differs: an unrefitted BLAS would fail this test.
    assert!(moved > 100, "only {moved} hits moved with the sway");
}

#[test]
fn refits_keep_to_the_scheduler_budget_and_all_catch_up() {
    let trees = 10;
    let scene = grid_scene(trees);
    let tree_vertices = scene.meshes[1].positions.len();
    let mut bvh = FrameBvh::new(&scene).unwrap();
    let s = SceneRtSettings {
        time_s: Some(2.0),
        refits_per_frame: 2,
        random_refits_per_frame: 1,
        ..Default::default()
    };
    let camera = Vec3::new(-55.0, 6.0, -55.0);
    let vp = view_proj(camera, Vec3::new(0.0, 0.0, -40.0));
    let mut pending = trees;
    let mut frames = 0;
    while pending > 0 {
        let f = bvh.update(camera, &vp, &s).unwrap();
        assert!(f.stats.refits_done <= 3, "{:?}", f.stats);
        assert!(f.stats.refits_done >= 1, "frame {frames} refitted nothing");
        assert_eq!(f.stats.refits_pending, pending - f.stats.refits_done);
        pending = f.stats.refits_pending;
        frames += 1;
        assert!(
            frames <= trees,
            "still {pending} stale after {frames} frames"
        );
    }
    // The vertex budget: room for one tree a frame (trees differ by a few vertices at most).
    let mut bvh = FrameBvh::new(&scene).unwrap();
    let s = SceneRtSettings {
        time_s: Some(3.0),
        refit_vertex_budget: (tree_vertices + tree_vertices / 2) as u32,
        ..Default::default()
    };
    for _ in 0..trees {
        let f = bvh.update(camera, &vp, &s).unwrap();
        assert_eq!(f.stats.refits_done, 1, "{:?}", f.stats);
        assert!(f.stats.refit_vertices <= s.refit_vertex_budget as usize);
    }
    let f = bvh.update(camera, &vp, &s).unwrap();
    assert_eq!((f.stats.refits_done, f.stats.refits_pending), (0, 0));
    // Back to the rest pose: every tree is stale again.
    let rest = SceneRtSettings {
        time_s: None,
        ..s.clone()
    };
    let f = bvh.update(camera, &vp, &rest).unwrap();
    assert_eq!(f.stats.refits_done + f.stats.refits_pending, trees);
}

#[test]
fn lamp_shells_stay_out_of_the_shadow_tlas_only() {
    let mut scene = grid_scene(0);
    scene
        .materials
        .push(Material::emissive("lamp", Vec3::splat(100.0)));
    let at = Vec3::new(-52.0, 2.0, -52.0);
    scene.instances.push(Instance {
        mesh: 0,
        material: 1,
        transform: Mat4::from_translation(at) * Mat4::from_scale(Vec3::splat(0.3)),
    });
    scene
        .lights
        .push(Light::point("lamp", at, 100.0, Vec3::ONE));
    let mut bvh = FrameBvh::new(&scene).unwrap();
    let camera = Vec3::new(-55.0, 6.0, -55.0);
    let vp = view_proj(camera, Vec3::new(0.0, 0.0, -40.0));
    let f = bvh
        .update(camera, &vp, &SceneRtSettings::default())
        .unwrap();
    let shell = (scene.instances.len() - 1) as u32;
    assert!(f.kept.contains(&shell));
    assert_eq!(f.stats.shadow_excluded, 1);
    let has = |t: &hikari_bvh::Tlas| t.instances.iter().any(|r| r.instance_index == shell);
    assert!(has(&f.gi));
    assert!(!has(&f.shadow));
    assert_eq!(f.gi.instances.len(), f.shadow.instances.len() + 1);
}

mod common;

/// The reverse-Z depth the G-buffer holds where the pixel-centre ray of `cam` first meets
/// `meshes` placed by `instances` (brute force), 0 for the sky.
fn cpu_depth(
    cam: &hikari_scene::Camera,
    w: u32,
    h: u32,
    meshes: &[hikari_bvh::Mesh],
    instances: &[hikari_bvh::Instance],
) -> Vec<f32> {
    let inv = (cam.projection(w as f32 / h as f32) * cam.view()).inverse();
    let fwd = cam.forward();
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let ndc = Vec2::new(
                (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
            );
            let p = inv.project_point3(ndc.extend(0.5));
            let dir = (p - cam.position).normalize();
            let ray = Ray::new(cam.position, dir, 0.0, f32::INFINITY);
            out.push(
                closest_hit_instances(meshes, instances, None, &ray)
                    .map_or(0.0, |hit| cam.near / (hit.t * dir.dot(fwd))),
            );
        }
    }
    out
}

/// A tree swaying 2 m seen from the side: the G-buffer's depth matches a brute-force cast of
/// the deformed mesh at t (and of the rest pose with no time, and again after going back),
/// the frame's stats say the tree was refitted once, and the depth at t differs from the rest
/// pose's, so the raster really moved.
#[test]
fn the_raster_and_the_bvh_draw_the_deformed_tree() {
    let mut scene = Scene {
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        meshes: vec![shapes::plane(40.0)],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        cameras: vec![hikari_scene::Camera {
            position: Vec3::new(0.0, 3.0, 12.0),
            target: Vec3::new(0.0, 3.0, 0.0),
            ..Default::default()
        }],
        sun: Some(hikari_scene::Sun::default()),
        ..Default::default()
    };
    let mut t = tree(6.0, 0.0);
    if let Some(Deformation::Sway { amplitude_m, .. }) = &mut t.deformation {
        *amplitude_m = 2.0;
    }
    scene.meshes.push(t);
    scene.instances.push(Instance {
        mesh: 1,
        material: 0,
        transform: Mat4::IDENTITY,
    });
    let (w, h) = (64, 48);
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.taa.enabled = false;
    s.settings.ray_traced_gi.enabled = true;
    let mut renderer = hikari_render::Renderer::new(common::gpu_context(), &scene).unwrap();
    let depth = |renderer: &mut hikari_render::Renderer, s: &hikari_render::FrameSettings| {
        let mut tex = None;
        let mut r = renderer
            .render_reading(s, |o| {
                tex = Some(o.gbuffer.depth);
                vec![o.gbuffer.depth.into()]
            })
            .unwrap();
        let img = r.take_image_of(tex.unwrap()).unwrap();
        img.rgba.iter().map(|p| p[0]).collect::<Vec<f32>>()
    };
    let instances = scene_bvh::instances(&scene);
    let rest_meshes = scene_bvh::meshes(&scene);
    let time = 0.6; // a quarter period at 0.4 Hz: the full 2 m
    let mut moved_meshes = rest_meshes.clone();
    moved_meshes[1].positions = scene.meshes[1].deformed(time).0;
    let cam = &scene.cameras[0];
    let want_rest = cpu_depth(cam, w, h, &rest_meshes, &instances);
    let want_moved = cpu_depth(cam, w, h, &moved_meshes, &instances);
    let differ = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .filter(|(x, y)| (*x - *y).abs() > 1e-3 * x.abs().max(1e-3))
            .count()
    };
    let pixels = (w * h) as usize;
    let allowed = common::allowed_differences(pixels).max(pixels / 100);
    assert!(
        differ(&want_rest, &want_moved) > 100,
        "the sway must move many pixels for this test to mean anything"
    );

    let rest = depth(&mut renderer, &s);
    let stats = renderer.scene_rt_stats().unwrap();
    assert_eq!((stats.refits_done, stats.refits_pending), (0, 0));
    assert!(
        differ(&rest, &want_rest) <= allowed,
        "rest pose: {}",
        differ(&rest, &want_rest)
    );

    s.settings.scene_rt.time_s = Some(time);
    let moved = depth(&mut renderer, &s);
    let stats = renderer.scene_rt_stats().unwrap();
    assert_eq!(
        (stats.refits_done, stats.refits_pending),
        (1, 0),
        "{stats:?}"
    );
    assert!(stats.raster_ms > 0.0 && stats.upload_bytes > 0, "{stats:?}");
    let n = differ(&moved, &want_moved);
    assert!(
        n <= allowed,
        "at t = {time} s: {n} pixels off the deformed mesh's depth"
    );
    assert_eq!(renderer.scene_rt().cpu.shown_time(1), Some(time));

    // Same time again: nothing to refit; then back to the rest pose.
    depth(&mut renderer, &s);
    assert_eq!(renderer.scene_rt_stats().unwrap().refits_done, 0);
    s.settings.scene_rt.time_s = None;
    let back = depth(&mut renderer, &s);
    assert!(differ(&back, &want_rest) <= allowed);
}
