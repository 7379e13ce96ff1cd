//! Relit reflection probes: the twin's cube and box math against definitions, and the frame's
//! mirrors and rough metals in emissive rooms against the walls they must reflect, computed
//! here from the room's geometry.

use crate::common;

use glam::{Mat4, Quat, Vec3, Vec4};
use hikari_bake::reflection_probes::ReflectionProbeBox;
use hikari_render::techniques::reflection_probes::ReflectionProbeGpu;
use hikari_render::techniques::reflection_probes::reference as twin;
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::{Camera, Instance, Material, Scene, shapes};

#[test]
fn every_cube_texel_direction_falls_back_on_its_texel() {
    let n = 16;
    for face in 0..6 {
        for y in 0..n {
            for x in 0..n {
                let d = twin::texel_direction(face, x, y, n);
                assert!((d.length() - 1.0).abs() < 1e-5);
                let (f, uv) = twin::face_uv(d * 3.7);
                assert_eq!(f, face, "texel ({x}, {y}) of face {face}");
                let back = [uv[0] * n as f32 - 0.5, uv[1] * n as f32 - 0.5];
                assert!((back[0] - x as f32).abs() < 1e-3 && (back[1] - y as f32).abs() < 1e-3);
            }
        }
    }
    // The faces' centres are the axes in the order +X, -X, +Y, -Y, +Z, -Z, and the first
    // texel of +X lies towards +Y and +Z (the Vulkan / D3D orientation: s = -z, t = -y).
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (face, axis) in axes.iter().enumerate() {
        assert!(twin::texel_direction(face, 8, 8, 16).dot(*axis) > 0.99);
    }
    let corner = twin::texel_direction(0, 0, 0, 16);
    assert!(corner.y > 0.0 && corner.z > 0.0, "{corner}");
}

fn probe(lo: Vec3, hi: Vec3, capture: Vec3, blend: f32) -> ReflectionProbeBox {
    ReflectionProbeBox::aabb("room", lo, hi, capture, blend)
}

#[test]
fn a_ray_leaves_a_rotated_box_where_its_planes_say() {
    // A 4 x 2 x 6 m box turned 30 degrees about y.
    let rot = Quat::from_rotation_y(std::f32::consts::FRAC_PI_6);
    let centre = Vec3::new(1.0, 2.0, -3.0);
    let b = ReflectionProbeBox {
        name: "turned".into(),
        transform: Mat4::from_scale_rotation_translation(Vec3::new(2.0, 1.0, 3.0), rot, centre),
        capture: centre,
        blend_m: 0.5,
    };
    let p = ReflectionProbeGpu::new(&b);
    for d in [Vec3::X, Vec3::Y, Vec3::new(0.3, -0.2, 0.9).normalize()] {
        let x = centre + Vec3::new(0.2, 0.1, -0.4);
        let t = twin::box_exit(&p, x, d);
        // The exit point in the box's own frame lies on a face: one |coordinate| is its half
        // size, the others within theirs.
        let local = rot.inverse() * (x + d * t - centre);
        let q = local / Vec3::new(2.0, 1.0, 3.0);
        assert!((q.abs().max_element() - 1.0).abs() < 1e-4, "{d}: {q}");
    }
    // Weights: 1 deep inside, 0.5 at a quarter metre inside a face (blend 0.5 m), 0 outside.
    assert_eq!(twin::box_weight(&p, centre), 1.0);
    let near_face = centre + rot * Vec3::new(0.0, 0.75, 0.0);
    assert!((twin::box_weight(&p, near_face) - 0.5).abs() < 1e-4);
    assert_eq!(twin::box_weight(&p, centre + Vec3::new(0.0, 5.0, 0.0)), 0.0);
}

#[test]
fn the_cone_holds_its_share_of_the_ggx_lobe() {
    // The talk's tan(theta_c) = alpha sqrt(u / (1 - u)) against the GGX distribution of the
    // half vector's angle integrated numerically: D(h) cos(h) over the cap of half-angle
    // theta_c holds 95 % of it.
    for alpha in [0.05f64, 0.2, 0.5, 0.9] {
        let theta_c = f64::from(twin::cone_tan(alpha as f32)).atan();
        let d = |c: f64| {
            let a2 = alpha * alpha;
            let k = c * c * (a2 - 1.0) + 1.0;
            a2 / (std::f64::consts::PI * k * k)
        };
        let steps = 200_000;
        let integral = |hi: f64| -> f64 {
            (0..steps)
                .map(|i| {
                    let th = (i as f64 + 0.5) / steps as f64 * hi;
                    d(th.cos()) * th.cos() * th.sin() * 2.0 * std::f64::consts::PI * hi
                        / steps as f64
                })
                .sum()
        };
        let share = integral(theta_c) / integral(std::f64::consts::FRAC_PI_2);
        assert!((share - 0.95).abs() < 1e-3, "alpha {alpha}: {share}");
    }
}

#[test]
fn horizon_occlusion_counts_only_the_tilt_of_the_mapped_normal() {
    let nv = Vec3::Y;
    // Untilted: the BRDF already accounts for the horizon.
    for r in [Vec3::new(0.9, 0.1, 0.0).normalize(), Vec3::Y] {
        assert_eq!(twin::horizon_occlusion(nv, nv, r, 0.3), 0.0);
    }
    // A mapped normal tilted away from a grazing reflection loses part of its cone, never more
    // than the cone's 95 %, and more the further the tilt and the rougher the lobe.
    let nm = |deg: f32| Vec3::new(-deg.to_radians().sin(), deg.to_radians().cos(), 0.0);
    let r = Vec3::new(0.95, 0.05, 0.0).normalize();
    let o = |deg: f32, a: f32| twin::horizon_occlusion(nm(deg), nv, r, a);
    assert!(o(5.0, 0.3) > 0.0);
    assert!(o(10.0, 0.3) >= o(5.0, 0.3));
    // The cone and the angles by hand for a 10-degree tilt: theta_p = 10 deg (the tilt lies in
    // the plane of nv and r), theta_r = acos(r.y).
    let theta_c = (0.3f32 * 19f32.sqrt()).atan();
    let theta_o = (r.y.acos() + theta_c - std::f32::consts::FRAC_PI_2).min(20f32.to_radians());
    let t = (theta_o / (2.0 * theta_c)).clamp(0.0, 1.0);
    assert!((o(10.0, 0.3) - 0.95 * t * t * (3.0 - 2.0 * t)).abs() < 1e-5);
    for deg in [1.0, 10.0, 40.0, 80.0] {
        assert!(o(deg, 0.8) <= twin::CONE_ENERGY + 1e-6);
    }
    // theta_o = min(theta_r + theta_c - 90 deg, 2 theta_p) by hand: a mirror-like lobe whose
    // cone stays above the horizon is not occluded however far the normal tilts.
    let r_high = Vec3::new(0.5, 0.866, 0.0);
    assert_eq!(twin::horizon_occlusion(nm(30.0), nv, r_high, 0.01), 0.0);
}

#[test]
fn roughness_compensation_is_the_distance_ratio() {
    assert!((twin::compensated_alpha(0.4, 1.0, 4.0) - 0.1).abs() < 1e-6);
    assert_eq!(twin::compensated_alpha(0.4, 10.0, 1.0), 1.0);
    assert_eq!(twin::compensated_alpha(0.0, 1.0, 1.0), 0.0);
}

// --- The frame: an emissive room with a metal floor --------------------------------------------

const LO: Vec3 = Vec3::new(-2.0, 0.0, -2.0);
const HI: Vec3 = Vec3::new(2.0, 3.0, 2.0);
const CAPTURE: Vec3 = Vec3::new(0.3, 1.4, -0.2);

/// The walls' emission, nits: +X, -X, ceiling, +Z, -Z.
const WALLS: [Vec3; 5] = [
    Vec3::new(8.0, 1.0, 1.0),
    Vec3::new(1.0, 8.0, 1.0),
    Vec3::new(1.0, 6.0, 6.0),
    Vec3::new(1.0, 1.0, 8.0),
    Vec3::new(6.0, 6.0, 1.0),
];

/// Which wall (index into WALLS) a ray from x along d inside the room meets, and where; None
/// for the floor.
fn wall_hit(x: Vec3, d: Vec3) -> Option<(usize, Vec3)> {
    let mut best: Option<(f32, usize)> = None;
    const FLOOR: usize = usize::MAX;
    let planes = [
        (0, HI.x, 0),
        (0, LO.x, 1),
        (1, HI.y, 2),
        (2, HI.z, 3),
        (2, LO.z, 4),
        (1, LO.y, FLOOR),
    ];
    for (axis, at, wall) in planes {
        if d[axis].abs() < 1e-9 {
            continue;
        }
        let t = (at - x[axis]) / d[axis];
        if t > 1e-6 && best.is_none_or(|(b, _)| t < b) {
            best = Some((t, wall));
        }
    }
    let (t, wall) = best?;
    (wall != FLOOR).then_some((wall, x + d * t))
}

/// Distance from a point on a wall to that wall's nearest edge.
fn edge_distance(p: Vec3) -> f32 {
    let inside = (p - LO).min(HI - p);
    // The coordinate on the wall's own plane is 0; the other two bound it.
    let mut v: Vec<f32> = inside.to_array().to_vec();
    v.sort_by(f32::total_cmp);
    v[1]
}

fn room(floor: Material, walls: &[Vec3; 5]) -> Scene {
    let mut materials = vec![floor];
    for (i, e) in walls.iter().enumerate() {
        materials.push(Material {
            name: format!("wall {i}"),
            base_color: Vec3::ZERO,
            emissive_nits: *e,
            double_sided: true,
            area_light: Some(false),
            ..Default::default()
        });
    }
    let c = 0.5 * (LO + HI);
    let size = HI - LO;
    let q = std::f32::consts::FRAC_PI_2;
    // The unit plane (normal +Y) turned to face into the room at each wall.
    let place =
        |rot: Quat, scale: Vec3, at: Vec3| Mat4::from_scale_rotation_translation(scale, rot, at);
    let transforms = [
        place(
            Quat::IDENTITY,
            Vec3::new(size.x, 1.0, size.z),
            Vec3::new(c.x, LO.y, c.z),
        ),
        place(
            Quat::from_rotation_z(q),
            Vec3::new(size.y, 1.0, size.z),
            Vec3::new(HI.x, c.y, c.z),
        ),
        place(
            Quat::from_rotation_z(-q),
            Vec3::new(size.y, 1.0, size.z),
            Vec3::new(LO.x, c.y, c.z),
        ),
        place(
            Quat::from_rotation_x(2.0 * q),
            Vec3::new(size.x, 1.0, size.z),
            Vec3::new(c.x, HI.y, c.z),
        ),
        place(
            Quat::from_rotation_x(-q),
            Vec3::new(size.x, 1.0, size.y),
            Vec3::new(c.x, c.y, HI.z),
        ),
        place(
            Quat::from_rotation_x(q),
            Vec3::new(size.x, 1.0, size.y),
            Vec3::new(c.x, c.y, LO.z),
        ),
    ];
    Scene {
        meshes: vec![shapes::plane(1.0)],
        instances: transforms
            .iter()
            .enumerate()
            .map(|(i, t)| Instance {
                mesh: 0,
                material: i,
                transform: *t,
            })
            .collect(),
        materials,
        cameras: vec![Camera {
            name: "inside".into(),
            position: Vec3::new(-0.4, 1.7, 1.6),
            target: Vec3::new(0.2, 0.2, -0.8),
            vfov_deg: 60.0,
            near: 0.05,
            up: Vec3::Y,
        }],
        ..Default::default()
    }
}

fn metal_floor(roughness: f32, emission: Vec3) -> Material {
    Material {
        name: "metal floor".into(),
        base_color: Vec3::ONE,
        metalness: 1.0,
        roughness,
        emissive_nits: emission,
        double_sided: true,
        area_light: Some(false),
        ..Default::default()
    }
}

const W: u32 = 64;
const H: u32 = 48;

fn settings(scene: &Scene, samples: u32) -> FrameSettings {
    let mut s = common::small_frame_settings(scene, W, H);
    s.sun = hikari_render::SunSource::Off;
    s.settings.sky.enabled = true;
    s.settings.sky.sky = false;
    s.settings.sky.table_quality = 0;
    s.settings.direct_lighting.sun = false;
    s.settings.area_lights.enabled = false;
    s.settings.taa.enabled = false;
    s.settings.reflection_probes.resolution = 64;
    s.settings.reflection_probes.levels = 6;
    s.settings.reflection_probes.samples = samples;
    s.settings.reflection_probes.normalization = false;
    s.settings.reflection_probes.roughness_parallax = false;
    s
}

/// The lit image (nits) of the room's frame, with the room's probe.
fn render(scene: &Scene, s: &FrameSettings) -> hikari_render::graph::ImageRgba32 {
    let mut r = Renderer::new(common::gpu_context(), scene).unwrap();
    // The box reaches a centimetre below the floor, so that the floor lies inside it.
    r.set_reflection_probes(&[probe(LO - Vec3::Y * 0.01, HI, CAPTURE, 0.0)])
        .unwrap();
    let mut out = r.render_reading(s, |o| vec![o.lit.into()]).unwrap();
    out.take_image("direct_lighting.radiance").unwrap()
}

/// Each floor pixel: where it is, and the unit vector towards the camera.
fn floor_pixels(cam: &Camera) -> Vec<(u32, u32, Vec3, Vec3)> {
    let view = hikari_render::view::View::new(cam, W, H);
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let d = hikari_render::techniques::gbuffer::reference::pixel_ray(
                inv,
                cam.position,
                [x, y],
                [W, H],
            );
            if d.y >= -1e-3 {
                continue;
            }
            let p = cam.position + d * (-cam.position.y / d.y);
            if p.x > LO.x + 0.05 && p.x < HI.x - 0.05 && p.z > LO.z + 0.05 && p.z < HI.z - 0.05 {
                out.push((x, y, p, -d));
            }
        }
    }
    out
}

#[test]
fn a_mirror_floor_reflects_the_wall_its_reflected_ray_meets() {
    let scene = room(metal_floor(0.0, Vec3::ZERO), &WALLS);
    let s = settings(&scene, 8);
    let img = render(&scene, &s);
    let mut checked = 0;
    for (x, y, p, v) in floor_pixels(&scene.cameras[0]) {
        let r = Vec3::new(-v.x, v.y, -v.z);
        let Some((wall, hit)) = wall_hit(p, r) else {
            continue;
        };
        // Away from the walls' edges, where a texel's filter would mix two walls.
        if edge_distance(hit) < 0.25 {
            continue;
        }
        let got = Vec4::from(img.pixel(x, y)).truncate();
        let want = WALLS[wall];
        assert!(
            (got - want).abs().max_element() <= 0.01 * want.max_element(),
            "pixel ({x}, {y}) reflects wall {wall} at {hit}: {got} against {want}"
        );
        checked += 1;
    }
    assert!(checked > 200, "only {checked} pixels checked");
}

#[test]
fn a_rough_metal_in_a_uniformly_glowing_room_reflects_that_glow() {
    // Every surface, the floor included, glows the same: any roughness reflects it unchanged,
    // so the prefilter and the lookup must conserve it at every level (a white furnace).
    let glow = Vec3::new(2.0, 3.0, 4.0);
    for roughness in [0.3, 0.75] {
        let scene = room(metal_floor(roughness, glow), &[glow; 5]);
        let img = render(&scene, &settings(&scene, 32));
        for (x, y, _, _) in floor_pixels(&scene.cameras[0]) {
            let got = Vec4::from(img.pixel(x, y)).truncate();
            // Its own glow plus the glow it reflects.
            let want = 2.0 * glow;
            assert!(
                (got - want).abs().max_element() <= 0.01 * want.max_element(),
                "roughness {roughness}, pixel ({x}, {y}): {got} against {want}"
            );
        }
    }
}

#[test]
fn a_rough_metal_reflects_the_ggx_integral_of_the_captured_room() {
    // Roughness 0.6 reads level 3 of 6 exactly (perceptual roughness x 5); the twin integrates
    // the room as the capture point sees it (walls' glow, black floor) over the GGX lobe about
    // the box-projected direction.
    let scene = room(metal_floor(0.6, Vec3::ZERO), &WALLS);
    let img = render(&scene, &settings(&scene, 256));
    let env = |l: Vec3| wall_hit(CAPTURE, l).map_or(Vec3::ZERO, |(w, _)| WALLS[w]);
    let b = ReflectionProbeGpu::new(&probe(LO - Vec3::Y * 0.01, HI, CAPTURE, 0.0));
    let mut worst: f32 = 0.0;
    let mut checked = 0;
    for (i, (x, y, p, v)) in floor_pixels(&scene.cameras[0]).into_iter().enumerate() {
        // Every 7th pixel: the integral is slow.
        if i % 7 != 0 {
            continue;
        }
        let r = Vec3::new(-v.x, v.y, -v.z);
        let t = twin::box_exit(&b, p, r);
        let dir = p + r * t - CAPTURE;
        let want = twin::prefilter_integral(env, dir, 0.36, 96);
        let got = Vec4::from(img.pixel(x, y)).truncate();
        let err = (got - want).abs().max_element() / want.max_element();
        if err > 0.06 {
            println!("({x}, {y}) p {p} dir {dir}: got {got} want {want}");
        }
        worst = worst.max(err);
        checked += 1;
    }
    println!("{checked} pixels, worst relative error {worst:.4}");
    assert!(checked > 30);
    assert!(worst < 0.06, "worst relative error {worst}");
}

#[test]
fn a_lamp_lit_probe_is_normalised_by_the_lamp_at_the_surface() {
    // Grey walls lit only by a lamp inside the box (no sun, no sky light): the probe's texels
    // hold the lamp's light, so the normalisation must count it at the capture point and at
    // the surface alike. A floor pixel's reflection, with the normalisation over without it, is
    // then the lamp's unshadowed light on the floor there over the capture light for the
    // floor's normal, at most `max_normalization`: near the lamp above 1, out of its reach 0
    // (before, the floor took the lamp-lit room's reflection everywhere at full strength).
    // The direct light of the lamp on the metal floor is the same in both runs and comes out
    // with a third run without the probes.
    let lamp_at = Vec3::new(-1.2, 0.6, 1.0);
    let mut scene = room(metal_floor(0.5, Vec3::ZERO), &[Vec3::ZERO; 5]);
    for m in &mut scene.materials[1..] {
        m.base_color = Vec3::splat(0.6);
    }
    let mut lamp = hikari_scene::Light::point("lamp", lamp_at, 4.0, Vec3::ONE);
    // Out of reach of the far side of the floor, as the village's lanterns are of its fields.
    lamp.range = Some(2.5);
    scene.lights.push(lamp);
    let mut s = settings(&scene, 32);
    s.settings.reflection_probes.normalization = true;
    let with = render(&scene, &s);
    s.settings.reflection_probes.normalization = false;
    let without = render(&scene, &s);
    s.settings.reflection_probes.enabled = false;
    let direct = render(&scene, &s);

    let params = hikari_render::techniques::direct_lighting::LightingParams::new(
        None,
        1,
        s.context().unwrap().light_cutoff_lux,
        &s.settings.direct_lighting,
    );
    let light = hikari_render::scene::upload::LightGpu {
        position_range: lamp_at.extend(2.5).to_array(),
        direction_kind: [0.0, 0.0, -1.0, hikari_render::scene::upload::LIGHT_POINT],
        intensity: [4.0, 4.0, 4.0, 0.0],
        spot: [0.0, 1.0, 0.0, 0.0],
    };
    let b = ReflectionProbeGpu::new(&probe(LO - Vec3::Y * 0.01, HI, CAPTURE, 0.0));
    let luma = |e: Vec3| e.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let capture = twin::capture_light(|n| {
        luma(twin::box_light_irradiance(
            &b,
            &light,
            params.cutoff[0],
            CAPTURE,
            n,
        ))
    });
    let max = s.settings.reflection_probes.max_normalization;
    let (mut checked, mut above, mut below) = (0, 0, 0);
    for (x, y, p, _) in floor_pixels(&scene.cameras[0]) {
        let d = Vec4::from(direct.pixel(x, y)).truncate();
        let on = Vec4::from(with.pixel(x, y)).truncate() - d;
        let off = Vec4::from(without.pixel(x, y)).truncate() - d;
        if luma(off) < 0.05 {
            continue;
        }
        let at_floor = luma(twin::box_light_irradiance(
            &b,
            &light,
            params.cutoff[0],
            p,
            Vec3::Y,
        ));
        let want = (at_floor / (capture.x + capture.z)).clamp(0.0, max);
        let got = luma(on) / luma(off);
        assert!(
            (got - want).abs() <= 0.03 * want + 0.01,
            "pixel ({x}, {y}) at {p}: normalised by {got}, the twin says {want}"
        );
        checked += 1;
        above += usize::from(want > 1.2);
        below += usize::from(want < 0.8);
    }
    println!("{checked} pixels: {above} above 1.2, {below} under 0.8");
    assert!(checked > 150 && above > 20 && below > 20);
}

/// The boxes in the 10:00 sun with the sky on, and a 32-texel probe of 2 levels round them.
fn morning_boxes_with_a_probe() -> (Scene, FrameSettings, ReflectionProbeBox) {
    let scene = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&scene, 32, 24);
    s.settings.sky.enabled = true;
    s.settings.sky.table_quality = 0;
    s.settings.sky.time = "10:00".into();
    s.sun = hikari_render::SunSource::Sky;
    s.settings.area_lights.enabled = false;
    s.settings.reflection_probes.resolution = 32;
    s.settings.reflection_probes.levels = 2;
    s.settings.reflection_probes.samples = 4;
    let b = probe(
        Vec3::new(-6.0, -0.5, -5.0),
        Vec3::new(6.0, 6.0, 6.0),
        Vec3::new(0.5, 1.2, 0.8),
        1.0,
    );
    (scene, s, b)
}

#[test]
fn the_relit_cube_maps_are_the_twins_relighting_of_what_was_captured() {
    // The boxes in the morning sun, a probe round them; the sky's light off (its SH has its own
    // tests), so each texel is its emission plus its albedo lit by the sun through the talk's
    // cube-map shadow. Level 0 of the prefiltered maps is the relit map itself.
    let (scene, mut s, b) = morning_boxes_with_a_probe();
    s.settings.sky.sky = false;
    let n = s.settings.reflection_probes.resolution;
    let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
    r.set_reflection_probes(std::slice::from_ref(&b)).unwrap();
    let mut out = r
        .render_reading(&s, |o| {
            let p = &o.reflection_probes;
            let [a, nd, e] = p.capture.unwrap();
            vec![a.into(), nd.into(), e.into(), p.radiance.unwrap().into()]
        })
        .unwrap();
    let mut img = |name: &str| out.take_image(name).unwrap();
    let (albedo, normal_depth, emission, radiance) = (
        img("reflection_probes.albedo"),
        img("reflection_probes.normal_depth"),
        img("reflection_probes.emission"),
        img("reflection_probes.radiance"),
    );
    assert_eq!(radiance.height, 6 * n);
    let depth =
        |layer: usize, x: i32, y: i32| normal_depth.pixel(x as u32, layer as u32 * n + y as u32)[2];
    let sun = s.directional_light().unwrap().unwrap();
    let light = twin::RelightLight {
        sun: Some((sun.direction, sun.color * sun.illuminance_lux)),
        shadow: Some((2, &depth)),
        ambient: &|_, _, _| Vec3::ZERO,
        lights: &|_, _| Vec3::ZERO,
        sky: &|_| Vec3::ZERO,
        cloud_shadow: &|_| 1.0,
    };
    let gpu = ReflectionProbeGpu::new(&b);
    let (mut lit, mut shadowed, mut sky) = (0, 0, 0);
    for face in 0..6 {
        for y in 0..n {
            for x in 0..n {
                let row = face as u32 * n + y;
                let t = twin::CaptureTexel {
                    albedo: Vec4::from(albedo.pixel(x, row)),
                    normal_depth: Vec4::from(normal_depth.pixel(x, row)),
                    emission: Vec4::from(emission.pixel(x, row)).truncate(),
                };
                let want = twin::relight_texel(&gpu, 0, face, [x, y], n, &t, &light);
                let got = Vec4::from(radiance.pixel(x, row)).truncate();
                assert!(
                    (got - want).abs().max_element() <= 0.01 * want.max_element() + 1e-3,
                    "face {face} texel ({x}, {y}): {got} against {want}"
                );
                if t.normal_depth.z <= 0.0 {
                    sky += 1;
                } else if want.max_element() > 100.0 {
                    lit += 1;
                } else {
                    shadowed += 1;
                }
            }
        }
    }
    // The view holds sky, sunlit and shadowed texels, or the comparison proves little.
    println!("sky {sky}, lit {lit}, dark {shadowed}");
    assert!(sky > 100 && lit > 100 && shadowed > 100);
}

#[test]
fn the_wgsl_cube_and_cone_math_is_its_twin() {
    use hikari_render::checks::math_check::{Kernel, MathCheck};
    use rand::rngs::SmallRng;
    use rand::{Rng, SeedableRng};
    let ctx = common::gpu_context();
    let mut lib =
        hikari_render::shader::library(hikari_render::shader::capabilities_for(ctx.features))
            .unwrap();
    let check = MathCheck::new(&ctx, &mut lib, Kernel::ReflectionProbe).unwrap();
    let mut rng = SmallRng::seed_from_u64(7);
    let unit = |rng: &mut SmallRng| {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize()
    };
    let mut cases = Vec::new();
    let mut input = Vec::new();
    for k in 0..400 {
        let nv = unit(&mut rng);
        // Mapped normals tilted up to 40 degrees from the vertex normal.
        let nm = (nv + 0.7 * rng.random::<f32>() * unit(&mut rng)).normalize();
        let v = unit(&mut rng);
        let r = (2.0 * nm.dot(v) * nm - v).normalize();
        let alpha = rng.random_range(0.0..1.0f32);
        let (de, dc) = (
            rng.random_range(0.01..10.0f32),
            rng.random_range(0.01..10.0f32),
        );
        let dir = unit(&mut rng) * rng.random_range(0.1..5.0f32);
        let (face, n) = (k % 6, 1 + (k as u32 % 13));
        let (x, y) = (rng.random_range(0..n), rng.random_range(0..n));
        input.extend_from_slice(&nm.to_array());
        input.extend_from_slice(&nv.to_array());
        input.extend_from_slice(&r.to_array());
        input.extend_from_slice(&[alpha, de, dc]);
        input.extend_from_slice(&dir.to_array());
        input.extend_from_slice(&[face as f32, x as f32, y as f32, n as f32]);
        cases.push((nm, nv, r, alpha, de, dc, dir, face, x, y, n));
    }
    let out = check.run(&ctx, &input).unwrap();
    for (k, (nm, nv, r, alpha, de, dc, dir, face, x, y, n)) in cases.into_iter().enumerate() {
        let o = &out[k * 8..k * 8 + 8];
        let ho = twin::horizon_occlusion(nm, nv, r, alpha);
        // acos near 1 amplifies rounding: a few 1e-3 of the smoothstep's range.
        assert!(
            (o[0] - ho).abs() < 5e-3,
            "case {k}: horizon {} against {ho}",
            o[0]
        );
        assert!((o[1] - twin::compensated_alpha(alpha, de, dc)).abs() < 1e-5);
        let (f, uv) = twin::face_uv(dir);
        assert_eq!(o[4] as usize, f, "case {k}: face of {dir}");
        assert!((o[2] - uv[0]).abs() < 1e-5 && (o[3] - uv[1]).abs() < 1e-5);
        let d = twin::texel_direction(face, x, y, n);
        assert!((Vec3::new(o[5], o[6], o[7]) - d).abs().max_element() < 1e-5);
    }
}

#[test]
fn non_finite_input_stays_out_of_the_reflections() {
    use hikari_render::techniques::gbuffer::overrides::{GBufferTarget, GBufferTexel};
    let scene = room(metal_floor(0.3, Vec3::ZERO), &WALLS);
    let s = settings(&scene, 8);
    let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
    // A probe whose numbers are not finite, or whose capture point lies outside its box, is
    // refused by name.
    let mut bad = probe(LO, HI, CAPTURE, 0.0);
    bad.capture.x = f32::NAN;
    let e = r.set_reflection_probes(&[bad]).unwrap_err().to_string();
    assert!(e.contains("room") && e.contains("finite"), "{e}");
    let outside = probe(LO, HI, HI + Vec3::ONE, 0.0);
    assert!(r.set_reflection_probes(&[outside]).is_err());
    r.set_reflection_probes(&[probe(LO - Vec3::Y * 0.01, HI, CAPTURE, 0.0)])
        .unwrap();
    // NaN and infinity in floor texels' normals and depths.
    let f16 = |v: [f32; 4]| -> Vec<u8> {
        v.iter()
            .flat_map(|x| half::f16::from_f32(*x).to_le_bytes())
            .collect()
    };
    let floor: Vec<(u32, u32)> = floor_pixels(&scene.cameras[0])
        .iter()
        .map(|p| (p.0, p.1))
        .collect();
    let at = |k: usize| [floor[k * 37 % floor.len()].0, floor[k * 37 % floor.len()].1];
    r.override_gbuffer_texels(vec![
        GBufferTexel {
            target: GBufferTarget::Normal,
            pixel: at(1),
            size: [1, 1],
            bytes: f16([f32::NAN, 0.2, 0.0, 0.0]),
        },
        GBufferTexel {
            target: GBufferTarget::Normal,
            pixel: at(2),
            size: [1, 1],
            bytes: f16([0.3, f32::INFINITY, 0.0, 0.0]),
        },
        GBufferTexel {
            target: GBufferTarget::Depth,
            pixel: at(3),
            size: [1, 1],
            bytes: f32::NAN.to_le_bytes().to_vec(),
        },
        GBufferTexel {
            target: GBufferTarget::Depth,
            pixel: at(4),
            size: [1, 1],
            bytes: f32::INFINITY.to_le_bytes().to_vec(),
        },
    ]);
    let mut out = r.render_reading(&s, |o| vec![o.lit.into()]).unwrap();
    let img = out.take_image("direct_lighting.radiance").unwrap();
    assert!(
        img.rgba
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)),
        "a non-finite or negative value reached the lit image"
    );
}

#[test]
fn only_probes_near_the_camera_are_captured_and_relit() {
    let scene = room(metal_floor(0.0, Vec3::ZERO), &WALLS);
    let mut s = settings(&scene, 4);
    s.settings.reflection_probes.stream_distance_m = 100.0;
    let far = probe(
        Vec3::new(500.0, 0.0, 0.0),
        Vec3::new(504.0, 3.0, 4.0),
        Vec3::new(502.0, 1.0, 2.0),
        0.0,
    );
    let near = probe(LO - Vec3::Y * 0.01, HI, CAPTURE, 0.0);
    let relit = |s: &FrameSettings, frames: usize| -> Vec<(u32, bool)> {
        let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
        r.set_reflection_probes(&[far.clone(), near.clone()])
            .unwrap();
        (0..frames)
            .map(|_| {
                let mut seen = None;
                r.render_reading(s, |o| {
                    seen = Some((o.reflection_probes.relit, o.reflection_probes.captured));
                    vec![]
                })
                .unwrap();
                seen.unwrap()
            })
            .collect()
    };
    // The far probe is 496 m away: only the room's is captured and relit, first whole, and
    // captured only once. The light does not change, so the round robin then rests: the
    // probe already holds it (`steady_light`).
    assert_eq!(relit(&s, 3), [(1, true), (0, false), (0, false)]);
    s.settings.reflection_probes.stream_distance_m = 0.0;
    assert_eq!(relit(&s, 2), [(2, true), (0, false)]);
    // A sun that moves more than `relight_all_deg` (2) between frames relights every probe;
    // one that moves less, one a frame.
    let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
    r.set_reflection_probes(&[far.clone(), near.clone()])
        .unwrap();
    let counts: Vec<u32> = [30.0f32, 30.5, 36.0]
        .iter()
        .map(|deg| {
            let a = deg.to_radians();
            let mut f = s.clone();
            f.sun = hikari_render::SunSource::Fixed(hikari_scene::Sun {
                direction: Vec3::new(a.cos(), a.sin(), 0.0),
                illuminance_lux: 1000.0,
                color: Vec3::ONE,
            });
            let mut seen = 0;
            r.render_reading(&f, |o| {
                seen = o.reflection_probes.relit;
                vec![]
            })
            .unwrap();
            seen
        })
        .collect();
    assert_eq!(counts, [2, 1, 2], "sun at 30, 30.5 and 36 degrees");
    // The mirror still shows the walls with the far probe in the list.
    let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
    r.set_reflection_probes(&[far, near]).unwrap();
    let mut out = r
        .render_reading(&settings(&scene, 4), |o| vec![o.lit.into()])
        .unwrap();
    let img = out.take_image("direct_lighting.radiance").unwrap();
    let (x, y, p, v) = floor_pixels(&scene.cameras[0])[200];
    let (wall, _) = wall_hit(p, Vec3::new(-v.x, v.y, -v.z)).unwrap();
    let got = Vec4::from(img.pixel(x, y)).truncate();
    assert!(
        (got - WALLS[wall]).abs().max_element() < 0.05 * WALLS[wall].max_element(),
        "{got}"
    );
}

/// With `compress`, each relit probe's prefiltered levels are encoded to BC6H on the GPU as
/// the CPU twin encodes the same texels (block for block), and the lighting read through the
/// compressed maps stays within BC6H's error of the uncompressed lighting.
#[test]
fn the_compressed_maps_are_the_twins_blocks_of_the_prefiltered_maps() {
    use hikari_render::bc6h::{Quality, reference as bc6h};
    let (scene, mut s, b) = morning_boxes_with_a_probe();
    s.settings.taa.enabled = false;
    let n = s.settings.reflection_probes.resolution;
    let ctx = common::gpu_context();
    assert!(
        hikari_render::techniques::reflection_probes::compresses(
            &ctx,
            &s.settings.reflection_probes
        ),
        "the CPU driver samples BC formats: the compressed path runs in CI"
    );
    let mut r = Renderer::new(ctx.clone(), &scene).unwrap();
    r.set_reflection_probes(std::slice::from_ref(&b)).unwrap();
    r.runtime.set_dumps(vec!["reflection_probes.bc6h0".into()]);
    let mut out = r
        .render_reading(&s, |o| {
            vec![o.reflection_probes.radiance.unwrap().into(), o.lit.into()]
        })
        .unwrap();
    let radiance = out.take_image("reflection_probes.radiance").unwrap();
    // The encoder pads each row of blocks to a 256-byte copy row: keep the image's blocks.
    let layout = hikari_render::bc6h::BlockLayout::for_copy([n, n]);
    let padded = out.buffer("reflection_probes.bc6h0").unwrap();
    let (bx, by) = (n as usize / 4, n as usize / 4);
    let mut blocks = Vec::new();
    for face in 0..6 {
        for row in 0..by {
            let at = 16 * (face * layout.layer_stride as usize + row * layout.row_stride as usize);
            blocks.extend_from_slice(&padded[at..at + 16 * bx]);
        }
    }
    let compressed_lit = out.take_image("direct_lighting.radiance").unwrap();
    // Level 0 of the six faces, as the twin sees them: the faces are stacked in the image.
    let rgb: Vec<[f32; 3]> = radiance.rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let face_texels = (n * n) as usize;
    let mut want = Vec::new();
    for face in 0..6 {
        let texels = &rgb[face * face_texels..(face + 1) * face_texels];
        want.extend(bc6h::encode_image(texels, n, n, Quality::Fast));
    }
    assert_eq!(blocks.len(), want.len());
    let differ = blocks
        .chunks(16)
        .zip(want.chunks(16))
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differ, 0, "{differ} of {} blocks differ", want.len() / 16);

    // The same frame with the maps uncompressed.
    s.settings.reflection_probes.compress = false;
    let mut r = Renderer::new(ctx, &scene).unwrap();
    r.set_reflection_probes(std::slice::from_ref(&b)).unwrap();
    let mut out = r.render_reading(&s, |o| vec![o.lit.into()]).unwrap();
    let plain_lit = out.take_image("direct_lighting.radiance").unwrap();
    let (mut diff, mut total) = (0.0f64, 0.0f64);
    for (a, b) in compressed_lit.rgba.iter().zip(&plain_lit.rgba) {
        for c in 0..3 {
            diff += f64::from((a[c] - b[c]).abs());
            total += f64::from(b[c].abs());
        }
    }
    assert!(total > 0.0);
    // BC6H's endpoints step about 3 %; the specular share of the lighting is a fraction of it.
    assert!(
        diff / total < 0.03,
        "the lighting through BC6H differs by {:.2} %",
        100.0 * diff / total
    );
    assert!(diff > 0.0, "the lookup read the compressed maps");
}
