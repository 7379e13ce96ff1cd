//! Alpha cut-outs (glTF MASK) in the compute rasteriser, in the G-buffer's visibility and in the
//! sun's shadow maps, against rays traced analytically through the `cutout` scene on the CPU:
//! its ground square and its two double-sided quads in the plane z = 0, covered where
//! `builtin::cutout_checker_covered` and `builtin::cutout_ramp_alpha` (against the ramp's
//! cut-off) say, at the exact texture coordinate where the ray crosses the quad.
//!
//! Tolerance: a pixel (or shadow texel) may disagree only when its ray crosses a quad within a
//! quarter of a texel (1/256 in UV) of a cut-out edge (a checker cell edge, or the ramp's u =
//! 0.25), or within 1 mm of a quad's or the ground's outline. The GPU reads alpha bilinearly
//! at mip 0, whose 0.5 contour between the checker's 0 and 1 texels lies exactly on the cell
//! edges (also where four cells meet), and whose contour at the ramp's cut-off lies within
//! 0.06 texel of u = 0.25 (8-bit alpha); the band holds filtering's fixed-point weights and
//! float rounding. Everything outside the band must agree exactly.

use crate::common;

use common::cutout::{self, CHECKER, RAMP, Traced};

use glam::{Mat4, Vec3, Vec4};
use hikari_render::techniques::gbuffer::reference::pixel_ray;
use hikari_render::techniques::sun_shadows;
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::builtin;
use hikari_scene::{AlphaMode, Scene};

/// The analytic reference seen by the rasteriser, which culls the ground's back.
fn trace(o: Vec3, d: Vec3, t_min: f32, t_max: f32, alpha_test: bool) -> Traced {
    cutout::trace(o, d, t_min, t_max, alpha_test, false)
}

/// How the GPU's answers compare with the reference's.
#[derive(Debug, Default)]
struct Tally {
    agree: u32,
    /// Disagreements outside the tolerance band: must be none.
    differ: u32,
    /// Within the band, either way.
    ambiguous: u32,
    /// Agreeing answers, by what they saw: sky or nothing, ground, checker, ramp.
    seen: [u32; 4],
    /// Agreeing rays that crossed a quad's outline inside a cut-out hole.
    through_holes: u32,
    /// Agreeing pixels that see the checker in the left half of the image.
    checker_left: u32,
}

impl Tally {
    fn add(&mut self, want: Traced, want_whole: Traced, got: Option<u32>, left: bool) {
        let w = want.hit.map(|(i, _)| i);
        if want.ambiguous {
            self.ambiguous += 1;
        } else if w == got {
            self.agree += 1;
            self.seen[w.map_or(0, |i| i as usize + 1)] += 1;
            if want_whole.hit.map(|(i, _)| i) != w {
                self.through_holes += 1;
            }
            if left && w == Some(CHECKER) {
                self.checker_left += 1;
            }
        } else {
            self.differ += 1;
        }
    }
}

fn settings(scene: &Scene, camera: &str, w: u32, h: u32) -> FrameSettings {
    let mut s = common::small_frame_settings(scene, w, h);
    s.camera = scene
        .cameras
        .iter()
        .find(|c| c.name == camera)
        .unwrap()
        .clone();
    s
}

/// The G-buffer's visibility of `drawn` (the `cutout` scene, or a variant of it) from
/// `camera`, pixel by pixel against rays through the pixel centres into the `cutout` scene.
fn visibility_tally(drawn: &Scene, camera: &str) -> Tally {
    let ctx = common::gpu_context();
    let (w, h) = (160u32, 120u32);
    let s = settings(drawn, camera, w, h);
    let mut renderer = Renderer::new(ctx, drawn).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
        .unwrap();
    let vis: &[u32] = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap());
    let cpu = &renderer.scene().cpu;
    let view = hikari_render::view::View::new(&s.camera, w, h);
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let mut tally = Tally::default();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (id, depth_bits) = (vis[2 * i], vis[2 * i + 1]);
            let got = (depth_bits != 0).then(|| cpu.chunks[(id / 64) as usize].instance);
            let d = pixel_ray(inv, s.camera.position, [x, y], [w, h]);
            let o = s.camera.position;
            let want = trace(o, d, s.camera.near, f32::INFINITY, true);
            let whole = trace(o, d, s.camera.near, f32::INFINITY, false);
            tally.add(want, whole, got, x < w / 2);
        }
    }
    tally
}

/// The sun's shadow maps of `drawn` from camera `main`, texel by texel against rays from the
/// sun through the texel centres into the `cutout` scene: a texel agrees when its depth is
/// within `depth_tolerance` of the reference's (NDC depth; the ground lies more than 0.01
/// behind the quads' lowest edge along the sun, so any tolerance well below that names the
/// surface).
fn shadow_tally(drawn: &Scene, depth_tolerance: f32) -> Tally {
    let ctx = common::gpu_context();
    let (w, h) = (64u32, 48u32);
    let s = settings(drawn, "main", w, h);
    let mut renderer = Renderer::new(ctx, drawn).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.shadows.texels.into()])
        .unwrap();
    let texels: &[f32] = bytemuck::cast_slice(r.buffer("sun_shadows.texels").unwrap());
    let sun = drawn.sun.clone().unwrap();
    let cascades = sun_shadows::fit_cascades(
        &s.camera,
        w as f32 / h as f32,
        sun.direction,
        renderer.scene().bounds.unwrap(),
        &s.settings.sun_shadows,
    );
    let res = s.settings.sun_shadows.resolution;
    let mut tally = Tally::default();
    for (c, cascade) in cascades.iter().enumerate() {
        // Texel (x, y) is stored at (x, y) + origin, wrapped (the maps scroll).
        let [ox, oy] = cascade.origin(res);
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
                let length = (to - from).length();
                let dir = (to - from) / length;
                let want = trace(from, dir, 0.0, length, true);
                let whole = trace(from, dir, 0.0, length, false);
                let want_depth = want
                    .hit
                    .map_or(0.0, |(_, t)| (vp * (from + dir * t).extend(1.0)).z);
                let at = ((y + oy) % res) * res + (x + ox) % res;
                let got_depth = texels[(c as u32 * res * res + at) as usize];
                // A depth within rounding of the reference's names the same surface: the
                // reference's surface, else none.
                let got = if (got_depth - want_depth).abs() <= depth_tolerance {
                    want.hit.map(|(i, _)| i)
                } else {
                    Some(u32::MAX)
                };
                tally.add(want, whole, got, false);
            }
        }
    }
    tally
}

/// The `cutout` scene with its cut-outs drawn opaque: what a renderer without the alpha test
/// draws.
fn without_alpha_test() -> Scene {
    let mut scene = builtin::cutout();
    for m in &mut scene.materials {
        m.alpha_mode = AlphaMode::Opaque;
    }
    scene
}

/// The `cutout` scene with each quad cut into `n` x `n` cells of two triangles: small enough
/// that the triangle pass draws them thread by thread (the whole quads take the tile queue).
fn tessellated(n: u32) -> Scene {
    let mut scene = builtin::cutout();
    for instance in [CHECKER, RAMP] {
        let mesh = &mut scene.meshes[scene.instances[instance as usize].mesh];
        // Corners: top left, top right, bottom right, bottom left (see `builtin::cutout`).
        let (p, uv) = (mesh.positions.clone(), mesh.uvs.clone());
        let (normal, tangent) = (mesh.normals[0], mesh.tangents[0]);
        let lerp = |s: f32, t: f32| {
            let top = (p[0].lerp(p[1], s), uv[0].lerp(uv[1], s));
            let bottom = (p[3].lerp(p[2], s), uv[3].lerp(uv[2], s));
            (top.0.lerp(bottom.0, t), top.1.lerp(bottom.1, t))
        };
        mesh.positions.clear();
        mesh.uvs.clear();
        mesh.indices.clear();
        for j in 0..=n {
            for i in 0..=n {
                let (q, t) = lerp(i as f32 / n as f32, j as f32 / n as f32);
                mesh.positions.push(q);
                mesh.uvs.push(t);
            }
        }
        let count = mesh.positions.len();
        mesh.normals = vec![normal; count];
        mesh.tangents = vec![tangent; count];
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let (tl, tr) = (at(i, j), at(i + 1, j));
                let (bl, br) = (at(i, j + 1), at(i + 1, j + 1));
                // The winding of the whole quad's triangles (0, 2, 1) and (0, 3, 2).
                mesh.indices.extend([tl, br, tr, tl, bl, br]);
            }
        }
    }
    scene.validate().unwrap();
    scene
}

fn assert_matches(what: &str, t: &Tally) {
    eprintln!("{what}: {t:?}");
    // Outside the band: no pixel differs. The band is thin: most pixels are outside it.
    assert_eq!(t.differ, 0, "{what}: {t:?}");
    assert!(t.ambiguous * 8 < t.agree, "{what}: band too wide: {t:?}");
}

#[test]
fn the_gbuffer_sees_through_the_cut_outs_from_both_sides() {
    let scene = builtin::cutout();
    for camera in ["main", "behind"] {
        let t = visibility_tally(&scene, camera);
        assert_matches(&format!("camera {camera}"), &t);
        // Both quads seen, double-sided from behind too, and the ground through their holes.
        assert!(
            t.seen[1 + CHECKER as usize] > 200 && t.seen[1 + RAMP as usize] > 200,
            "camera {camera}: {t:?}"
        );
        assert!(t.through_holes > 300, "camera {camera}: {t:?}");
        // The checker (x < 0) is on the left from the front, on the right from behind.
        let left = t.checker_left * 2 > t.seen[1 + CHECKER as usize];
        assert_eq!(left, camera == "main", "camera {camera}: {t:?}");
    }
}

#[test]
fn the_sun_casts_the_cut_outs_shadows() {
    let t = shadow_tally(&builtin::cutout(), 1e-5);
    assert_matches("shadow maps", &t);
    // The maps see the quads, and the ground through their holes: a checkered shadow.
    assert!(
        t.seen[1 + CHECKER as usize] > 200 && t.seen[1 + RAMP as usize] > 200,
        "{t:?}"
    );
    assert!(t.through_holes > 300, "{t:?}");
}

#[test]
fn small_cut_out_triangles_are_tested_too() {
    // 24 x 24 cells: about 2 pixels (texels) a side, drawn by the triangle pass's threads.
    let scene = tessellated(24);
    let t = visibility_tally(&scene, "main");
    assert_matches("tessellated, G-buffer", &t);
    assert!(t.through_holes > 300, "{t:?}");
    // Triangles a texel across, seen by the sun at 22 degrees: their depth planes, from
    // vertices so close together, are good to about 1e-4 at the texel centres.
    let t = shadow_tally(&scene, 2e-4);
    assert_matches("tessellated, shadow maps", &t);
    assert!(t.through_holes > 300, "{t:?}");
}

#[test]
fn without_the_alpha_test_both_comparisons_fail() {
    // The same scene with its cut-outs drawn opaque: the holes are filled, so the comparisons
    // above must find many differences (they can fail).
    let scene = without_alpha_test();
    let t = visibility_tally(&scene, "main");
    eprintln!("opaque G-buffer: {t:?}");
    assert!(t.differ > 300, "G-buffer: {t:?}");
    let t = shadow_tally(&scene, 1e-5);
    eprintln!("opaque shadows: {t:?}");
    assert!(t.differ > 300, "shadow maps: {t:?}");
}

#[test]
fn opaque_chunks_come_first_and_cut_outs_carry_their_cut_off() {
    // No GPU needed: what the scene upload tells the rasteriser.
    use hikari_render::scene::textures::LayerMap;
    use hikari_render::scene::upload::{INSTANCE_ALPHA_TESTED, SceneCpu};
    let scene = builtin::cutout();
    let cpu = SceneCpu::build(&scene, &LayerMap::for_scene(&scene));
    let first = cpu.first_alpha_chunk as usize;
    assert!(first > 0 && first < cpu.chunks.len());
    for (k, c) in cpu.chunks.iter().enumerate() {
        let inst = &cpu.instances[c.instance as usize];
        let tested = inst.flags & INSTANCE_ALPHA_TESTED != 0;
        assert_eq!(tested, k >= first, "chunk {k} of instance {}", c.instance);
        let cutoff = cpu.materials[inst.material as usize].extra[2];
        let want = scene.materials[inst.material as usize]
            .alpha_cutoff()
            .unwrap_or(0.0);
        assert_eq!(cutoff, want, "chunk {k}");
    }
    // Without cut-outs nothing is alpha-tested.
    let opaque = without_alpha_test();
    let cpu = SceneCpu::build(&opaque, &LayerMap::for_scene(&opaque));
    assert_eq!(cpu.first_alpha_chunk as usize, cpu.chunks.len());
}
