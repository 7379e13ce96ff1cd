//! The `terrain` and `cornell` built-in scenes against their definitions.

use glam::{DVec3, Vec3};
use hikari_scene::builtin::{self, CORNELL_LIGHT_NITS};
use hikari_scene::{Camera, Scene, Sun};

fn height(x: f64, z: f64) -> f64 {
    5.0 * (0.1 * x).sin() * (0.13 * z).cos() + 2.0 * (0.7 * x + 0.3 * z).sin()
}

fn normal(x: f64, z: f64) -> DVec3 {
    let dx = 0.5 * (0.1 * x).cos() * (0.13 * z).cos() + 1.4 * (0.7 * x + 0.3 * z).cos();
    let dz = -0.65 * (0.1 * x).sin() * (0.13 * z).sin() + 0.6 * (0.7 * x + 0.3 * z).cos();
    DVec3::new(-dx, 1.0, -dz).normalize()
}

#[test]
fn terrain_is_exactly_the_benchmark_height_field() {
    let scene = builtin::by_name("terrain").unwrap();
    scene.validate().unwrap();
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 1);
    let m = &scene.meshes[0];
    assert_eq!(m.positions.len(), 708 * 708);
    assert_eq!(m.indices.len() / 3, 2 * 707 * 707);
    assert_eq!(scene.triangle_count(), 2 * 707 * 707);
    assert_eq!(m.uvs.len(), m.positions.len());
    assert_eq!(m.tangents.len(), m.positions.len());

    let (lo, hi) = m.bounds().unwrap();
    assert_eq!((lo.x, lo.z, hi.x, hi.z), (-100.0, -100.0, 100.0, 100.0));
    let step = 200.0 / 707.0;
    for (k, (p, n)) in m.positions.iter().zip(&m.normals).enumerate() {
        let (i, j) = (k % 708, k / 708);
        let (x, z) = (-100.0 + i as f64 * step, -100.0 + j as f64 * step);
        assert!(
            (p.x as f64 - x).abs() < 1e-4 && (p.z as f64 - z).abs() < 1e-4,
            "vertex {k} at {p}"
        );
        // The height from the vertex's own (f32) coordinates, evaluated in f64.
        let y = height(p.x as f64, p.z as f64);
        assert!(
            (p.y as f64 - y).abs() < 1e-5,
            "vertex {k}: height {} vs {y}",
            p.y
        );
        let want = normal(p.x as f64, p.z as f64);
        assert!(
            (n.as_dvec3() - want).length() < 1e-6,
            "vertex {k}: normal {n} vs {want}"
        );
        assert!((n.length() - 1.0).abs() < 1e-5);
    }
    // Two triangles per cell, facing up (counter-clockwise seen from +y), and each corner's
    // analytic normal within a few degrees of its triangle's.
    for t in m.indices.chunks(3) {
        let [a, b, c] = [0, 1, 2].map(|i| m.positions[t[i] as usize]);
        let g = (b - a).cross(c - a).normalize();
        assert!(g.y > 0.0, "triangle {t:?} faces down");
        assert!(g.dot(m.normals[t[0] as usize]) > 0.95);
    }

    let c = scene.camera("main").unwrap();
    assert_eq!(c.position, Vec3::new(0.0, 40.0, -120.0));
    assert!((c.forward() - Vec3::new(0.0, -0.5, 1.0).normalize()).length() < 1e-6);
    // An image plane at distance 1 spanning ±0.4 vertically.
    assert!(((c.vfov_deg.to_radians() * 0.5).tan() - 0.4).abs() < 1e-6);
    let sun = scene.sun.as_ref().unwrap();
    assert_eq!(
        (sun.direction, sun.illuminance_lux),
        (Sun::default().direction, 100_000.0)
    );
}

#[test]
fn builtin_scenes_are_deterministic() {
    for name in builtin::NAMES {
        let (a, b) = (
            builtin::by_name(name).unwrap(),
            builtin::by_name(name).unwrap(),
        );
        assert_eq!(a.meshes.len(), b.meshes.len());
        for (ma, mb) in a.meshes.iter().zip(&b.meshes) {
            assert_eq!(ma.positions, mb.positions, "{name}");
            assert_eq!(ma.indices, mb.indices, "{name}");
        }
    }
}

fn cornell() -> Scene {
    let s = builtin::by_name("cornell").unwrap();
    s.validate().unwrap();
    s
}

fn mesh<'a>(s: &'a Scene, name: &str) -> &'a hikari_scene::Mesh {
    s.meshes
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no mesh {name}"))
}

#[test]
fn cornell_box_has_the_published_dimensions() {
    let s = cornell();
    // Published extents, mm: x 0..556, y 0..548.8, z 0..559.2.
    let (lo, hi) = s.bounds().unwrap();
    assert!(lo.abs_diff_eq(Vec3::ZERO, 1e-6), "{lo}");
    assert!(
        hi.abs_diff_eq(Vec3::new(0.556, 0.5488, 0.5592), 1e-6),
        "{hi}"
    );

    // Light: 130 mm x 105 mm, centred at (278, 279.5) mm, just under the ceiling.
    let (llo, lhi) = mesh(&s, "cornell light").bounds().unwrap();
    assert!(
        (lhi - llo - Vec3::new(0.130, 0.0, 0.105))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!(
        (0.5 * (llo + lhi) - Vec3::new(0.278, 0.5483, 0.2795))
            .abs()
            .max_element()
            < 1e-6
    );
    let light = &s.materials[s
        .instances
        .iter()
        .find(|i| s.meshes[i.mesh].name == "cornell light")
        .unwrap()
        .material];
    let l = light.emissive_nits.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    assert!(
        (l - CORNELL_LIGHT_NITS).abs() < 1e-2 * CORNELL_LIGHT_NITS,
        "{l}"
    );
    assert!(
        light.emissive_nits.x > light.emissive_nits.y
            && light.emissive_nits.y > light.emissive_nits.z
    );

    // Blocks: heights 165 and 330 mm.
    let blocks = mesh(&s, "cornell blocks");
    let mut tops: Vec<f32> = blocks
        .positions
        .iter()
        .map(|p| p.y)
        .filter(|&y| y > 0.0)
        .collect();
    tops.dedup();
    tops.sort_by(f32::total_cmp);
    tops.dedup();
    assert_eq!(tops, vec![0.165, 0.33]);

    // Every surface faces into the room (walls) or out of its block (blocks), and the light down.
    let centre = Vec3::new(0.278, 0.274, 0.28);
    for name in [
        "cornell white walls",
        "cornell red wall",
        "cornell green wall",
    ] {
        let m = mesh(&s, name);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(
                (centre - p).dot(*n) > 0.0,
                "{name}: normal {n} at {p} faces out"
            );
        }
    }
    for t in blocks.indices.chunks(3) {
        let [a, b, c] = [0, 1, 2].map(|i| blocks.positions[t[i] as usize]);
        let g = (b - a).cross(c - a).normalize();
        assert!(
            g.dot(blocks.normals[t[0] as usize]) > 0.999,
            "winding disagrees with the normal"
        );
    }
    assert_eq!(mesh(&s, "cornell light").normals[0], Vec3::NEG_Y);

    // Colours: red wall reddest, green wall greenest, all albedos below 1.
    let mat = |mesh_name: &str| {
        let i = s
            .instances
            .iter()
            .find(|i| s.meshes[i.mesh].name == mesh_name)
            .unwrap();
        s.materials[i.material].base_color
    };
    let (red, green, white) = (
        mat("cornell red wall"),
        mat("cornell green wall"),
        mat("cornell white walls"),
    );
    assert!(red.x > 5.0 * red.y && green.y > 3.0 * green.x);
    assert!(white.min_element() > 0.6 && [red, green, white].iter().all(|c| c.max_element() < 1.0));
    assert!(s.materials.iter().all(|m| m.interior == Some(1.0)));
}

#[test]
fn cornell_camera_is_the_published_one_and_sees_the_whole_box() {
    let s = cornell();
    let c: &Camera = &s.cameras[0];
    assert!(c.position.abs_diff_eq(Vec3::new(0.278, 0.273, -0.8), 1e-6));
    assert!(c.forward().abs_diff_eq(Vec3::Z, 1e-6));
    // 35 mm lens on 25 mm film.
    assert!((c.vfov_deg - 2.0 * (12.5f32 / 35.0).atan().to_degrees()).abs() < 1e-4);
    let (lo, hi) = s.bounds().unwrap();
    let vp = c.projection(1.0) * c.view();
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let clip = vp * p.extend(1.0);
        assert!(
            clip.w > 0.0 && clip.x.abs() <= clip.w && clip.y.abs() <= clip.w,
            "{p} outside the view"
        );
    }
}

/// The cut-out scene's textures and materials against their documented description, checked
/// at hand-picked texels rather than through the helpers that built them.
#[test]
fn cutout_scene_has_the_documented_alpha() {
    use hikari_scene::AlphaMode;
    let s = builtin::by_name("cutout").unwrap();
    s.validate().unwrap();
    let alpha = |t: usize, x: u32, y: u32| s.textures[t].data[((y * 64 + x) * 4 + 3) as usize];
    // Checker: 8 cells of 8 texels; cell (0, 0) opaque, its neighbours empty.
    assert_eq!(
        [
            alpha(0, 0, 0),
            alpha(0, 7, 7),
            alpha(0, 8, 0),
            alpha(0, 0, 8),
            alpha(0, 8, 8)
        ],
        [255, 255, 0, 0, 255]
    );
    assert_eq!(alpha(0, 63, 63), 255);
    assert_eq!(alpha(0, 63, 0), 0);
    // Ramp: column x holds (x + 0.5) / 64, constant down the column.
    assert_eq!(alpha(1, 0, 0), 2); // 0.5 / 64 * 255 = 1.99
    assert_eq!(alpha(1, 63, 40), 253); // 63.5 / 64 * 255 = 253.0
    assert_eq!(alpha(1, 15, 0), alpha(1, 15, 63));
    // With the cut-off 0.25, columns 16 and up are covered (16.5 / 64 = 0.258).
    let cut = (0.25f32 * 255.0) as u8;
    assert!(alpha(1, 15, 0) < cut && alpha(1, 16, 0) > cut);

    let by_name = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    assert_eq!(by_name("ground").alpha_cutoff(), None);
    let checker = by_name("checker cut-out");
    assert_eq!(checker.alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert!(checker.double_sided);
    assert_eq!(by_name("ramp cut-out").alpha_cutoff(), Some(0.25));
    assert!(builtin::cutout_checker_covered(glam::Vec2::new(0.01, 0.01)));
    assert!(!builtin::cutout_checker_covered(glam::Vec2::new(
        0.13, 0.01
    )));
    assert!((builtin::cutout_ramp_alpha(0.5) - 32.5 / 64.0).abs() < 1e-6);

    // The quads face +Z (counter-clockwise seen from there) and UV (0, 0) is the top-left
    // corner seen from the front.
    for name in ["checker quad", "ramp quad"] {
        let m = mesh(&s, name);
        for t in m.indices.chunks_exact(3) {
            let p: Vec<_> = t.iter().map(|&i| m.positions[i as usize]).collect();
            assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0, "{name}");
        }
        let top_left = m.uvs.iter().position(|uv| *uv == glam::Vec2::ZERO).unwrap();
        let others = m.positions.iter().filter(|p| **p != m.positions[top_left]);
        for p in others {
            assert!(p.x >= m.positions[top_left].x && p.y <= m.positions[top_left].y);
        }
    }
}
