//! The frame's scene BVH (`scene_rt`), on the CPU: the culled per-frame TLAS finds what brute
//! force over every instance finds for rays inside the kept region; a refitted swaying tree
//! gives the hits of its deformed mesh (brute force and a fresh build); the refit scheduler
//! keeps to its budget and leaves nothing stale for ever; lamp shells stay out of shadows.

use glam::{Mat4, Vec2, Vec3};
use hikari_bvh::reference::{closest_hit_instances, closest_hit_mesh, random_dir, same_hit};
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Ray};
use hikari_render::scene::bvh;
use hikari_render::scene::rt::{FrameBvh, SceneRtSettings, kept_instances};
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
    let meshes = bvh::meshes(&scene);
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
    let rest = &bvh::meshes(&scene)[tree_mesh];
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

use crate::common;

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
    let instances = bvh::instances(&scene);
    let rest_meshes = bvh::meshes(&scene);
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

/// Barycentrics of `p` (on the triangle's plane) in the triangle `a b c`, from sub-triangle
/// areas.
fn barycentrics(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let n = (b - a).cross(c - a);
    let area = |x: Vec3, y: Vec3, z: Vec3| (y - x).cross(z - x).dot(n);
    let total = area(a, b, c);
    Vec3::new(area(p, b, c), area(a, p, c), area(a, b, p)) / total
}

/// Where `world` projects through `view_proj` (unjittered), in pixels (y down).
fn to_pixel(view_proj: Mat4, world: Vec3, w: u32, h: u32) -> Vec2 {
    let c = view_proj * world.extend(1.0);
    let ndc = Vec2::new(c.x, c.y) / c.w;
    Vec2::new(
        (ndc.x * 0.5 + 0.5) * w as f32,
        (0.5 - ndc.y * 0.5) * h as f32,
    )
}

/// Motion vectors of a deforming mesh. A tree swaying 2 m (with a still cube and the floor)
/// is drawn at t0 = 0.1 s, then at t1 = 0.6 s from a camera moved 0.3 m sideways. The
/// reference casts each pixel's centre ray on the CPU against the meshes at t1 (brute force),
/// takes the hit's barycentrics in its triangle, and projects the point of the same
/// barycentrics on the t0 triangle through last frame's view-projection (the still meshes:
/// the hit point itself). The G-buffer's motion (previous minus current position) must match
/// within 0.03 px + 2^-10 of its length (f16 storage; the GPU's barycentrics are f32) where
/// the GPU and the CPU see the same depth (silhouettes excluded). A control checks that the
/// sway moves the tree's reference by more than half a pixel from the camera-only motion in
/// many pixels (the motion before this change), so the test can fail. A third frame at t1
/// from the same camera has no motion anywhere: the previous positions caught up. The
/// G-buffer's CPU twin, given the vertices at both times, agrees on every surface pixel.
#[test]
fn motion_vectors_follow_deforming_vertices() {
    let mut scene = Scene {
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        meshes: vec![shapes::plane(40.0), shapes::cube()],
        instances: vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            },
            Instance {
                mesh: 1,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(-4.0, 1.0, 0.0)),
            },
        ],
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
        mesh: 2,
        material: 0,
        transform: Mat4::IDENTITY,
    });
    let tree_instance = 2u32;
    let (w, h) = (64u32, 48u32);
    let (t0, t1) = (0.1f32, 0.6f32);
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.taa.enabled = false;
    let mut renderer = hikari_render::Renderer::new(common::gpu_context(), &scene).unwrap();
    let read = |renderer: &mut hikari_render::Renderer, s: &hikari_render::FrameSettings| {
        let mut texs = None;
        let mut r = renderer
            .render_reading(s, |o| {
                texs = Some((o.gbuffer.motion, o.gbuffer.depth));
                vec![
                    o.gbuffer.motion.into(),
                    o.gbuffer.depth.into(),
                    o.gbuffer.visibility.into(),
                ]
            })
            .unwrap();
        let vis: Vec<u32> = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap()).to_vec();
        let (m, d) = texs.unwrap();
        let motion = r.take_image_of(m).unwrap();
        let depth = r.take_image_of(d).unwrap();
        (
            motion
                .rgba
                .iter()
                .map(|p| Vec2::new(p[0], p[1]))
                .collect::<Vec<_>>(),
            depth.rgba.iter().map(|p| p[0]).collect::<Vec<_>>(),
            vis,
        )
    };
    let cam_a = scene.cameras[0].clone();
    let mut cam_b = cam_a.clone();
    cam_b.position.x += 0.3;
    cam_b.target.x += 0.3;
    let aspect = w as f32 / h as f32;
    let vp_a = cam_a.projection(aspect) * cam_a.view();

    s.settings.scene_rt.time_s = Some(t0);
    read(&mut renderer, &s);
    s.settings.scene_rt.time_s = Some(t1);
    s.camera = cam_b.clone();
    s.prev_camera = Some(cam_a.clone());
    let (motion, depth, vis) = read(&mut renderer, &s);

    let instances = bvh::instances(&scene);
    let mut meshes = bvh::meshes(&scene);
    meshes[2].positions = scene.meshes[2].deformed(t1).0;
    let before = scene.meshes[2].deformed(t0).0;
    let want_depth = cpu_depth(&cam_b, w, h, &meshes, &instances);
    let inv = (cam_b.projection(aspect) * cam_b.view()).inverse();
    let (mut tree_px, mut compared, mut swayed) = (0, 0, 0);
    let mut bad = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (d, e) = (depth[i], want_depth[i]);
            if e == 0.0 || (d - e).abs() > 1e-3 * e {
                continue;
            }
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ndc = Vec2::new(
                centre.x / w as f32 * 2.0 - 1.0,
                1.0 - centre.y / h as f32 * 2.0,
            );
            let dir = (inv.project_point3(ndc.extend(0.5)) - cam_b.position).normalize();
            let ray = Ray::new(cam_b.position, dir, 0.0, f32::INFINITY);
            let Some(hit) = closest_hit_instances(&meshes, &instances, None, &ray) else {
                continue;
            };
            let p = cam_b.position + dir * hit.t;
            let camera_only = to_pixel(vp_a, p, w, h) - centre;
            let want = if hit.instance == tree_instance {
                tree_px += 1;
                let [a, b, c] = meshes[2].indices[hit.primitive as usize].map(|v| v as usize);
                let pos = &meshes[2].positions;
                let bary = barycentrics(p, pos[a], pos[b], pos[c]);
                let q = before[a] * bary.x + before[b] * bary.y + before[c] * bary.z;
                let m = to_pixel(vp_a, q, w, h) - centre;
                if (m - camera_only).length() > 0.5 {
                    swayed += 1;
                }
                m
            } else {
                camera_only
            };
            compared += 1;
            let err = (motion[i] - want).length();
            if err > 0.03 + want.length() / 1024.0 {
                bad.push(((x, y), hit.instance, motion[i], want));
            }
        }
    }
    eprintln!(
        "{compared} pixels compared, {tree_px} on the tree, {swayed} swayed; {} beyond tolerance",
        bad.len()
    );
    assert!(
        swayed > 60,
        "the sway must move the tree's motion for this test to mean anything: {swayed}"
    );
    assert!(compared > (w * h) as usize / 3, "{compared}");
    assert!(
        bad.is_empty(),
        "first of {}: {:?}",
        bad.len(),
        &bad[..bad.len().min(8)]
    );

    // The G-buffer's twin (`gbuffer::reference::resolve_deformed`) on the GPU's visibility
    // ids, its vertices at t1 and last frame's at t0: every surface pixel within the G-buffer
    // test's motion tolerance (0.02 px + 2e-3 relative).
    let base: usize = scene.meshes[..2].iter().map(|m| m.positions.len()).sum();
    let mut now = renderer.scene().cpu.clone();
    let mut then = now.positions.clone();
    for (k, (p1, p0)) in meshes[2].positions.iter().zip(&before).enumerate() {
        now.positions[base + k] = p1.extend(1.0).to_array();
        then[base + k] = p0.extend(1.0).to_array();
    }
    let view = hikari_render::view::View::with_previous(&cam_b, &cam_a, w, h);
    let (mut twin_tree, mut twin_bad) = (0, Vec::new());
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if vis[2 * i + 1] == 0 {
                continue;
            }
            let want = hikari_render::techniques::gbuffer::reference::resolve_deformed(
                &scene,
                &now,
                &view,
                [x, y],
                vis[2 * i],
                &then,
            )
            .unwrap();
            if want.instance == tree_instance {
                twin_tree += 1;
            }
            let close = |g: f32, e: f32| (g - e).abs() <= 0.02 + 2e-3 * e.abs();
            if !(close(motion[i].x, want.motion.x) && close(motion[i].y, want.motion.y)) {
                twin_bad.push(((x, y), motion[i], want.motion));
            }
        }
    }
    eprintln!("twin: {twin_tree} tree pixels, {} beyond", twin_bad.len());
    assert!(twin_tree > 100, "{twin_tree}");
    assert!(
        twin_bad.is_empty(),
        "first of {}: {:?}",
        twin_bad.len(),
        &twin_bad[..twin_bad.len().min(8)]
    );

    // The same time and camera again: last frame's pose is this frame's, nothing moves.
    s.prev_camera = Some(cam_b.clone());
    let (motion, _, _) = read(&mut renderer, &s);
    let worst = motion.iter().map(|m| m.length()).fold(0f32, f32::max);
    assert!(worst <= 1e-3, "a still frame has motion {worst} px");
}

/// GI hits on a deforming mesh carry the normal of the triangle the ray met in the pose its
/// BLAS was refitted to, not its rest pose: a tree swaying by 2 m beside a floor, GI on
/// without the pre-trace (every hit comes from the BVH trace and its normal tables), at
/// t = 0.6 s. Every hit on the tree must carry (within the normal word's precision) the world
/// normal of one of the tree's triangles in that pose, and many of those normals must match no
/// triangle of the rest pose (so the rest pose's tables, the code before, fail the test).
#[test]
fn gi_hit_normals_follow_a_deforming_mesh() {
    use hikari_render::techniques::ray_traced_gi::reference::{oct_encode, unpack_normal};
    let mut scene = Scene {
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        meshes: vec![shapes::plane(40.0)],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        cameras: vec![hikari_scene::Camera {
            position: Vec3::new(0.0, 2.0, 7.0),
            target: Vec3::new(0.0, 1.0, 0.0),
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
    for x in [-1.5f32, 1.5] {
        scene.instances.push(Instance {
            mesh: 1,
            material: 0,
            transform: Mat4::from_translation(Vec3::new(x, 0.0, 0.0)),
        });
    }
    let time = 0.6f32;
    let mut s = common::small_frame_settings(&scene, 96, 64);
    s.settings.ray_traced_gi.enabled = true;
    s.settings.ray_traced_gi.pretrace = false;
    s.settings.scene_rt.time_s = Some(time);
    let mut renderer = hikari_render::Renderer::new(common::gpu_context(), &scene).unwrap();
    let r = renderer
        .render_reading(&s, |o| {
            let rays = o.ray_traced_gi_rays.expect("GI is on");
            vec![rays.hit_normals.into(), rays.hit_instances.into()]
        })
        .unwrap();
    let normals: Vec<u32> =
        bytemuck::pod_collect_to_vec(r.buffer("ray_traced_gi.hit_normals").unwrap());
    let instances: Vec<u32> =
        bytemuck::pod_collect_to_vec(r.buffer("ray_traced_gi.hit_instances").unwrap());
    // The tree's instances are translations: world normals are the mesh's.
    let words = |positions: &[Vec3]| -> Vec<Vec2> {
        scene.meshes[1]
            .indices
            .chunks_exact(3)
            .filter_map(|t| {
                let p = |k: usize| positions[t[k] as usize];
                let n = (p(1) - p(0)).cross(p(2) - p(0));
                (n.length_squared() > 0.0).then(|| oct_encode(n.normalize()))
            })
            .collect()
    };
    let (deformed, _) = scene.meshes[1].deformed(time);
    let posed = words(&deformed);
    let rest = words(&scene.meshes[1].positions);
    let near = |set: &[Vec2], e: Vec2| set.iter().any(|q| (*q - e).abs().max_element() < 1e-4);
    let (mut hits, mut off_rest) = (0, 0);
    for (w, &inst) in normals.iter().zip(&instances) {
        if inst != 1 && inst != 2 {
            continue;
        }
        let e = unpack_normal(*w).expect("a BVH hit on the tree has a normal");
        hits += 1;
        assert!(
            near(&posed, e),
            "hit normal {e} is no triangle's of the swayed tree"
        );
        off_rest += usize::from(!near(&rest, e));
    }
    println!("{hits} GI hits on the trees, {off_rest} with a normal the rest pose lacks");
    assert!(hits >= 50, "only {hits} GI rays hit the trees");
    assert!(
        off_rest * 2 >= hits,
        "only {off_rest} of {hits} hit normals moved with the sway"
    );
}
