//! The compute rasteriser against rays through the same pixel (texel) centres, traced by
//! brute force on the CPU with hikari-bvh's watertight triangle test: the G-buffer's
//! visibility and the sun's shadow maps.

use crate::common;

use glam::{Mat4, Vec3, Vec4};
use hikari_bvh::reference::closest_hit_instances;
use hikari_bvh::{Instance, Mesh, Ray};
use hikari_render::scene::raster::QueueSizes;
use hikari_render::scene::upload::SceneCpu;
use hikari_render::techniques::gbuffer::reference::{decode_id, pixel_ray};
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::Scene;

fn bvh_scene(scene: &Scene) -> (Vec<Mesh>, Vec<Instance>) {
    (
        hikari_render::scene::bvh::meshes(scene),
        hikari_render::scene::bvh::instances(scene),
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
        // Wide enough that the ground's two triangles span more than 256 32x32 tiles and take
        // the large-triangle path, while the boxes take the per-thread and tile passes.
        visibility_agrees_with_rays(&scene, 768, 480);
    }
}

#[test]
fn crowded_tiles_keep_the_nearest_of_hundreds_of_overlapping_triangles() {
    // 160 tilted, interpenetrating quads stacked in front of the camera, in an order unrelated
    // to their depth: each tile gets about 320 entries, drawn by many workgroups at once, and
    // which quad is nearest changes from pixel to pixel.
    let mut m = hikari_scene::Mesh {
        name: "stack".into(),
        ..Default::default()
    };
    let mut seed = 7u32;
    let mut random = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    for _ in 0..160 {
        // Depth order unrelated to the order of the triangles, and so of the entries.
        let z = -10.0 + random() * 8.0;
        let (tx, ty) = (random() * 0.6, random() * 0.6);
        let c = Vec3::new(random(), random(), 0.0);
        let n = Vec3::new(-tx, -ty, 1.0).normalize();
        let first = m.positions.len() as u32;
        for (x, y) in [(-3.0, -2.0), (3.0, -2.0), (3.0, 2.0), (-3.0, 2.0)] {
            let p = c + Vec3::new(x, y, 0.0);
            m.positions
                .push(Vec3::new(p.x, p.y, z + tx * p.x + ty * p.y));
            m.normals.push(n);
        }
        m.indices.extend([0, 1, 2, 0, 2, 3].map(|i| first + i));
    }
    let mut scene = Scene::default();
    scene.meshes.push(m);
    scene
        .materials
        .push(hikari_scene::Material::diffuse("grey", Vec3::splat(0.5)));
    scene.instances.push(hikari_scene::Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::IDENTITY,
    });
    scene.cameras.push(hikari_scene::Camera {
        name: "front".into(),
        position: Vec3::ZERO,
        target: Vec3::new(0.0, 0.0, -1.0),
        vfov_deg: 40.0,
        near: 0.1,
        up: Vec3::Y,
    });
    visibility_agrees_with_rays(&scene, 256, 192);
}

/// What a ray through each pixel centre hits first: instance, triangle within its mesh and
/// reverse-Z depth.
fn rays_through_pixels(scene: &Scene, s: &FrameSettings) -> Vec<Option<(u32, u32, f32)>> {
    let (w, h) = (s.width, s.height);
    let (meshes, instances) = bvh_scene(scene);
    let view = hikari_render::view::View::new(&s.camera, w, h);
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let vp = view.view_proj();
    (0..w * h)
        .map(|i| {
            let dir = pixel_ray(inv, s.camera.position, [i % w, i / w], [w, h]);
            let ray = Ray::new(s.camera.position, dir, s.camera.near, f32::INFINITY);
            closest_hit_instances(&meshes, &instances, None, &ray).map(|hit| {
                let c = vp * (s.camera.position + dir * hit.t).extend(1.0);
                (hit.instance, hit.primitive, c.z / c.w)
            })
        })
        .collect()
}

/// The visibility buffer (id, depth bits per pixel) against the rays.
#[derive(Debug)]
struct Agreement {
    agree: usize,
    differ: usize,
    worst_depth: f32,
}

impl Agreement {
    fn of(scene: &Scene, cpu: &SceneCpu, vis: &[u32], rays: &[Option<(u32, u32, f32)>]) -> Self {
        let firsts = mesh_first_triangles(scene);
        let (mut agree, mut differ, mut worst_depth) = (0, 0, 0f32);
        for (i, want) in rays.iter().enumerate() {
            let (id, depth_bits) = (vis[2 * i], vis[2 * i + 1]);
            let got = (depth_bits != 0).then(|| {
                let chunk = &cpu.chunks[(id / 64) as usize];
                let mesh = scene.instances[chunk.instance as usize].mesh;
                decode_id(cpu, id, firsts[mesh]).unwrap()
            });
            match (got, want) {
                (None, None) => agree += 1,
                (Some((inst, tri)), Some((want_inst, want_tri, want_depth)))
                    if inst == *want_inst && tri == *want_tri =>
                {
                    agree += 1;
                    let got_depth = f32::from_bits(depth_bits);
                    worst_depth = worst_depth.max((got_depth - want_depth).abs() / want_depth);
                }
                _ => differ += 1,
            }
        }
        Self {
            agree,
            differ,
            worst_depth,
        }
    }

    fn check(&self) -> Result<(), String> {
        let allowed = common::allowed_differences(self.agree + self.differ);
        if self.differ > allowed {
            return Err(format!(
                "{} pixels differ from the rays (allowed {allowed}), {} agree",
                self.differ, self.agree
            ));
        }
        if self.worst_depth >= 1e-4 {
            return Err(format!("worst relative depth error {}", self.worst_depth));
        }
        Ok(())
    }
}

/// The first 32x32 tile (`[x, y]` in tiles) whose every pixel the rays see a surface through.
fn covered_tile(rays: &[Option<(u32, u32, f32)>], w: u32, h: u32) -> [u32; 2] {
    (0..h / 32)
        .rev()
        .flat_map(|ty| (0..w / 32).map(move |tx| [tx, ty]))
        .find(|[tx, ty]| {
            (0..32 * 32)
                .all(|k| rays[((ty * 32 + k / 32) * w + tx * 32 + k % 32) as usize].is_some())
        })
        .expect("a 32x32 tile the scene covers")
}

/// Every pixel's triangle and depth in the G-buffer's visibility against a ray through its
/// centre; and the same comparison fails once a covered 32x32 tile is dropped from the result.
fn visibility_agrees_with_rays(scene: &Scene, w: u32, h: u32) {
    let ctx = common::gpu_context();
    let s = frame_settings(scene, w, h);
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
        .unwrap();
    let vis: &[u32] = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap());
    let rays = rays_through_pixels(scene, &s);
    let cpu = &renderer.scene().cpu;
    let agreement = Agreement::of(scene, cpu, vis, &rays);
    eprintln!("{w}x{h}: {agreement:?}");
    agreement.check().unwrap();

    // The same frame with one tile lost, as a rasteriser that dropped its entries draws it.
    let [tx, ty] = covered_tile(&rays, w, h);
    let mut damaged = vis.to_vec();
    for k in 0..32 * 32 {
        let i = ((ty * 32 + k / 32) * w + tx * 32 + k % 32) as usize;
        damaged[2 * i..2 * i + 2].fill(0);
    }
    let lost = Agreement::of(scene, cpu, &damaged, &rays);
    assert!(
        lost.check().is_err(),
        "{w}x{h}: tile ({tx}, {ty}) dropped, yet the comparison passes: {lost:?}"
    );
}

#[test]
fn a_frame_whose_queues_overflow_is_drawn_again_without_losing_triangles() {
    let scene = hikari_scene::builtin::boxes();
    let s = frame_settings(&scene, 256, 160);
    let visibility = |tiny: bool| {
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
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

#[test]
fn any_number_of_tile_and_large_workgroups_draws_the_same() {
    // The tile and large passes get as many workgroups as the last frame's counts suggest;
    // counts that call for the fewest (256 each: no large triangle last frame) and the most
    // must draw what the first frame draws with its defaults. At 768x480 the boxes queue
    // more tile entries than 256 workgroups; at 1024x640 the ground's large triangles span
    // more tiles than that.
    for (w, h) in [(768, 480), (1024, 640)] {
        workgroup_counts_draw_the_same(w, h);
    }
}

fn workgroup_counts_draw_the_same(w: u32, h: u32) {
    let scene = hikari_scene::builtin::boxes();
    let s = frame_settings(&scene, w, h);
    let draw = |last: Option<[u32; 2]>| {
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        if let Some([entries, large]) = last {
            for t in ["gbuffer", "sun_shadows"] {
                renderer.raster_queues().sizes(t, 0);
                let counts = hikari_render::graph::FrameResult {
                    buffers: vec![(
                        format!("{t}.tile_count"),
                        bytemuck::cast_slice(&[entries, large, 0, 0]).to_vec(),
                    )],
                    ..Default::default()
                };
                renderer.raster_queues().grow(&counts, u64::MAX).unwrap();
            }
        }
        let r = renderer
            .render_reading(&s, |out| {
                vec![out.gbuffer.visibility.into(), out.shadows.texels.into()]
            })
            .unwrap();
        ["gbuffer.visibility", "sun_shadows.texels"].map(|n| r.buffer(n).unwrap().to_vec())
    };
    let want = draw(None);
    assert!(want[0].chunks(8).any(|p| p[4..] != [0; 4]), "nothing drawn");
    for last in [[1, 0], [1 << 17, 1]] {
        assert!(
            draw(Some(last)) == want,
            "{w}x{h} drawn differently after a frame that queued {last:?} (entries, large \
             triangles)"
        );
    }
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
    // Fine tessellation: per-thread and tile passes; coarse: the large-triangle pass too (at
    // 1024x768 their faces span more than 256 tiles).
    for (segments, rings) in [(96, 48), (6, 3), (4, 2)] {
        sphere_has_no_holes(segments, rings);
    }
}

fn sphere_has_no_holes(segments: u32, rings: u32) {
    let ctx = common::gpu_context();
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
    let s = frame_settings(&scene, 1024, 768);
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
fn views_with_non_finite_or_huge_matrices_stay_inside_their_target() {
    // The raster kernels run without wgpu's index checks. A view given NaN, infinite or huge
    // matrices through the library must end (no endless loop) and write nothing outside its
    // slice, beside a sane view drawing into the next slice. (On lavapipe a NaN corner also
    // fails every depth test; the integer clamp in `poly_rect` is what bounds the loops on
    // drivers that turn NaN into other integers.)
    use hikari_render::graph::GraphRuntime;
    use hikari_render::scene::raster::{
        RasterJob, RasterQueues, RasterTarget, RasterView, Rasterizer,
    };
    use hikari_render::scene::upload::SceneGpu;
    use hikari_render::shader;
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let raster = Rasterizer::new(&ctx, &mut lib).unwrap();
    let scene = hikari_scene::builtin::boxes();
    let scene_gpu = SceneGpu::upload(&ctx, &scene).unwrap();
    let size = [64u32, 48];
    let slice = (size[0] * size[1]) as u64 * 8;
    let sane = frame_settings(&scene, size[0], size[1]);
    let sane = hikari_render::view::View::new(&sane.camera, size[0], size[1]).view_proj();
    for bad in [
        Mat4::from_cols_array(&[f32::NAN; 16]),
        Mat4::from_cols_array(&[f32::INFINITY; 16]),
        sane * Mat4::from_scale(Vec3::splat(1e30)),
        Mat4::from_cols(Vec4::ONE, Vec4::NEG_ONE, Vec4::ONE, Vec4::splat(1e-30)),
    ] {
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(&ctx);
        let scene_in = scene_gpu.import(&mut g);
        // Slice 0: the bad view; slice 1: the sane one; slice 2: a guard that must stay zero.
        let target = g.buffer("t.target", 3 * slice).unwrap();
        let views = [
            RasterView::full(bad, 0, size),
            RasterView::full(sane, 1, size),
        ];
        let job = RasterJob {
            technique: "t",
            views: &views,
            size,
            cull_back_faces: false,
        };
        let mut queues = RasterQueues::default();
        raster
            .record(
                &mut g,
                &scene_in,
                &job,
                RasterTarget::Visibility,
                target,
                &mut queues,
            )
            .unwrap();
        g.readback(target);
        let r = g.execute().unwrap();
        let bytes = r.buffer("t.target").unwrap();
        let [_, drawn, guard] =
            [0, 1, 2].map(|k| &bytes[k * slice as usize..(k + 1) * slice as usize]);
        assert!(
            guard.iter().all(|&b| b == 0),
            "a view with matrix {bad:?} wrote outside the target's slices"
        );
        let seen = drawn.chunks(8).filter(|p| p[4..] != [0; 4]).count();
        assert!(
            seen * 2 > (size[0] * size[1]) as usize,
            "the sane view beside it drew {seen} pixels"
        );
    }
}
