//! Lighting at hits: the twin, point lights and their shadow rays, the exposure cap, shadow maps, the reused lit image, lamp shells, clouds.

use super::*;

/// A floor under a glowing ceiling 2 m up, lit only by a point light between them, two
/// coloured area lights lying on the floor facing up, and the ceiling's emission (no sun, no
/// sky): every GI ray from the floor hits the ceiling through the BVH. One frame without
/// accumulation, each pixel against the twin: the same ray from the G-buffer's depth and
/// normal, the ceiling's hit found analytically, the hit word's quantisation, the hit's normal
/// (the ceiling's, from the normal tables; checked in the hit normals' buffer), the light as
/// the shade pass applies it to the hit (the area lights' polygon integration in
/// f64, one of them picked by the same random number; nothing stands between the ceiling and
/// the lights, so their shadow rays all pass), the ceiling's emission, the encoding.
/// Tolerance: the outputs are f16 (2^-11 relative) and the lighting a few f32 roundings, so
/// 2^-9 of the pixel's luminance scale; the distance to an f16 ulp, AO exactly. Up to 0.5 % of
/// the pixels may differ beyond it: where the random number falls within rounding of the
/// boundary between the two lights, GPU and twin may pick different ones.
#[test]
fn hits_are_lit_like_the_twin() {
    use hikari_scene::{Light, LightKind};
    let ceiling_albedo = Vec3::new(0.8, 0.4, 0.2);
    let ceiling_emission = Vec3::new(3.0, 2.0, 1.0);
    let scene = Scene {
        meshes: vec![shapes::plane(400.0)],
        materials: vec![
            Material::diffuse("floor", Vec3::splat(0.5)),
            // Not an area light: GI carries its emission (an area light's is the area-light
            // pass's, and GI leaves it out; `gi_validation.rs` checks that on the Cornell box).
            Material {
                emissive_nits: ceiling_emission,
                area_light: Some(false),
                ..Material::diffuse("ceiling", ceiling_albedo)
            },
            Material {
                emissive_nits: Vec3::new(40.0, 8.0, 4.0),
                area_light: Some(true),
                ..Material::diffuse("red lamp", Vec3::splat(0.5))
            },
            Material {
                emissive_nits: Vec3::new(3.0, 6.0, 30.0),
                area_light: Some(true),
                ..Material::diffuse("blue lamp", Vec3::splat(0.5))
            },
        ],
        instances: vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            },
            Instance {
                mesh: 0,
                material: 1,
                transform: Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))
                    * Mat4::from_rotation_x(std::f32::consts::PI),
            },
            // 2 mm above the floor, under the rays' origins (pushed 2.5 mm off the floor), so
            // that no GI ray hits them.
            Instance {
                mesh: 0,
                material: 2,
                transform: Mat4::from_translation(Vec3::new(-0.5, 0.002, 0.1))
                    * Mat4::from_scale(Vec3::splat(0.4 / 400.0)),
            },
            Instance {
                mesh: 0,
                material: 3,
                transform: Mat4::from_translation(Vec3::new(0.6, 0.002, -0.3))
                    * Mat4::from_scale(Vec3::new(0.3 / 400.0, 1.0, 0.6 / 400.0)),
            },
        ],
        lights: vec![Light {
            name: "bulb".into(),
            kind: LightKind::Point,
            position: Vec3::new(0.3, 1.0, 0.2),
            direction: Vec3::NEG_Y,
            intensity_cd: 50.0,
            color: Vec3::ONE,
            range: None,
            radius_m: None,
        }],
        cameras: vec![Camera {
            name: "down".into(),
            position: Vec3::new(0.0, 1.5, 0.0),
            target: Vec3::ZERO,
            up: Vec3::Z,
            ..Camera::default()
        }],
        sun: None,
        ..Default::default()
    };
    let (w, h) = (64u32, 64u32);
    let s = twin_settings(&scene, w, h);
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let light = renderer.scene().cpu.lights[0];
    let area = renderer.area_lights().lights.clone();
    assert_eq!(area.lights.len(), 2, "both lamps are area lights");
    let min_flux = s.settings.area_lights.min_flux_lm;
    // The ceiling's normal as the BVH trace gives it: its triangle's in object space through
    // the normal tables, turned into world space, packed.
    let (inst_n, tri_n) = reference::normal_tables(&scene);
    let ceiling_normal = {
        let row = |k: usize| Vec3::from_slice(&inst_n[3 + k][..3]);
        let first = inst_n[3][3].to_bits() as usize;
        let no = reference::oct_decode(reference::unpack_normal(tri_n[first]).unwrap());
        let nw = Vec3::new(row(0).dot(no), row(1).dot(no), row(2).dot(no)).normalize();
        let w = reference::pack_normal(reference::oct_encode(nw));
        reference::oct_decode(reference::unpack_normal(w).unwrap())
    };
    assert!(ceiling_normal.dot(Vec3::NEG_Y) > 0.9999, "{ceiling_normal}");
    let Read {
        y: gy,
        cocg: gc,
        ao: ga,
        distance: gd,
        depth,
        normal,
        normals: hit_normals,
        ..
    } = render(&mut renderer, &s);
    let view = View::new(&s.camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let cutoff = s.context().unwrap().light_cutoff_lux;
    let mut lit = 0;
    let mut off = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let d = depth[i][0];
            assert!(d > 0.0, "pixel ({x}, {y}) sees the floor");
            let n = reference::oct_decode(Vec2::new(normal[i][0], normal[i][1]));
            let world = reference::world_from_depth(inv_vp, [w, h], [x, y], d);
            let o = reference::ray_origin(world, n, s.camera.position);
            let (dir, weight) = reference::ray([x, y], 0, n);
            let t = (2.0 - o.y) / dir.y;
            let (radiance, t_q) = match unpack_hit(pack_hit(Some(t), ceiling_albedo)) {
                HitWord::Hit { distance, albedo } if t < 250.0 => {
                    // The BVH's t and the analytic one may round to neighbouring f16 values
                    // (checked below); light the GPU's, so that the lighting is compared alone.
                    let gpu_t = gd.rgba[i][0];
                    let used = if (gpu_t - distance).abs() <= distance * 2f32.powi(-10) * 1.001 {
                        gpu_t
                    } else {
                        distance
                    };
                    let eps = 1e-3 + 1e-3 * used;
                    let hn = if ceiling_normal.dot(dir) > 0.0 {
                        -ceiling_normal
                    } else {
                        ceiling_normal
                    };
                    let got = reference::oct_decode(
                        reference::unpack_normal(hit_normals[i]).expect("a BVH hit has a normal"),
                    );
                    assert!(
                        got.dot(ceiling_normal) > 1.0 - 1e-6,
                        "pixel ({x}, {y}): hit normal {got}, the ceiling's {ceiling_normal}"
                    );
                    let p = o + dir * (used - eps) + hn * eps;
                    let mut e = reference::punctual_irradiance(p, hn, &light, cutoff);
                    let scores = (0..area.lights.len())
                        .map(|k| reference::area_light_score(&area, k, p, hn, min_flux, cutoff));
                    if let Some((k, sk, total)) =
                        reference::pick_weighted(scores, reference::random([x, y], 0, 0))
                    {
                        let ek =
                            reference::area_light_irradiance(&area, k, p, hn, min_flux, cutoff);
                        e += ek * (total / sk);
                    }
                    (
                        albedo / std::f32::consts::PI * e + ceiling_emission,
                        distance,
                    )
                }
                _ => (Vec3::ZERO, 0.0),
            };
            lit += (radiance.max_element() > 0.0) as u32;
            let want = reference::to_floats(&reference::encode_sample(radiance, dir, weight));
            let got = sample_at(&gy, &gc, i);
            let scale = (want[0].abs() / C0 as f32).max(1e-6);
            if (0..6).any(|k| (got[k] - want[k]).abs() > scale * 2f32.powi(-9)) {
                off += 1;
                if off <= 5 {
                    eprintln!("pixel ({x}, {y}): GPU {got:?}, twin {want:?} (t {t})");
                }
            }
            // The BVH's t and the analytic one may round to neighbouring f16 values.
            assert!(
                (gd.rgba[i][0] - t_q).abs() <= t_q * 2f32.powi(-10) * 1.001,
                "pixel ({x}, {y}) distance: GPU {}, twin {t_q} (t {t})",
                gd.rgba[i][0]
            );
            assert_eq!(
                ga.rgba[i][0],
                if t_q > 0.0 && t_q < 50.0 { 0.0 } else { 1.0 }
            );
        }
    }
    assert!(lit > 3000, "only {lit} pixels' rays were lit");
    assert!(
        off <= (w * h) as usize / 200,
        "{off} pixels differ from the twin"
    );
}

/// Shadows of point lights at hits: a floor under a ceiling 2 m up, two point lights between
/// them and a small board right above one of them, so that it shades a patch of the ceiling
/// (no sun, sky or area lights). One frame, the pre-trace off, each pixel against the twin: the
/// GI ray's hit found analytically (the ceiling or the board's underside), lit by the light that the same random
/// number picks in proportion to its unshadowed irradiance, times the sum's luminance over
/// its own, and 0 where the segment from the hit to the point the shader aims at on that
/// light's disc (`reference::punctual_shadow_target`, the default radius of 5 cm) crosses the
/// board (found analytically; aimed at the lights' centres instead, 48 pixels differ, and the
/// test fails). Tolerances as `hits_are_lit_like_the_twin`, with up to 0.5 % of the pixels
/// beyond them (a light picked differently within rounding, a segment grazing the board's
/// edge). At least 5 % of the hits must be shadowed from the light picked.
#[test]
fn point_lights_at_hits_cast_shadows_like_the_twin() {
    point_lights_at_hits(0.0);
}

/// As [`point_lights_at_hits_cast_shadows_like_the_twin`], with the shadow ray's Russian
/// roulette at 100 times the metered illuminance (a fixed EV100 of 0: 2.5 lux, so 250 lux, above
/// every light's estimate here): each hit's shadow ray is traced only if the seventh random
/// number of its pixel falls below estimate / 250 lux, and its light is then divided by that
/// chance, so that a traced, unblocked light always has a luminance of 250 lux. At least 5 %
/// of the hits must be skipped by the roulette and 5 % traced.
#[test]
fn point_light_shadow_rays_at_hits_play_russian_roulette_like_the_twin() {
    point_lights_at_hits(100.0);
}

fn point_lights_at_hits(roulette: f32) {
    use hikari_scene::{Light, LightKind};
    let (board_y, board_half) = (1.3f32, 0.2f32);
    let board_at = Vec3::new(0.3, board_y, 0.2);
    let (ceiling_albedo, board_albedo) = (Vec3::new(0.8, 0.7, 0.6), Vec3::new(0.3, 0.6, 0.3));
    let light = |name: &str, position: Vec3, intensity_cd: f32, color: Vec3| Light {
        name: name.into(),
        kind: LightKind::Point,
        position,
        direction: Vec3::NEG_Y,
        intensity_cd,
        color,
        range: None,
        radius_m: None,
    };
    let scene = Scene {
        meshes: vec![shapes::plane(400.0)],
        materials: vec![
            Material::diffuse("floor", Vec3::splat(0.5)),
            Material::diffuse("ceiling", ceiling_albedo),
            Material::diffuse("board", board_albedo),
        ],
        instances: vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            },
            Instance {
                mesh: 0,
                material: 1,
                transform: Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))
                    * Mat4::from_rotation_x(std::f32::consts::PI),
            },
            Instance {
                mesh: 0,
                material: 2,
                transform: Mat4::from_translation(board_at)
                    * Mat4::from_scale(Vec3::new(
                        2.0 * board_half / 400.0,
                        1.0,
                        2.0 * board_half / 400.0,
                    )),
            },
        ],
        lights: vec![
            light("under the board", Vec3::new(0.3, 0.9, 0.2), 60.0, Vec3::ONE),
            light(
                "aside",
                Vec3::new(-0.6, 0.8, -0.4),
                20.0,
                Vec3::new(1.0, 0.5, 0.2),
            ),
        ],
        cameras: vec![Camera {
            name: "down".into(),
            position: Vec3::new(0.0, 1.9, 0.0),
            target: Vec3::ZERO,
            up: Vec3::Z,
            ..Camera::default()
        }],
        sun: None,
        ..Default::default()
    };
    let (w, h) = (64u32, 64u32);
    let mut s = twin_settings(&scene, w, h);
    // Every ray through the BVH: the pre-trace's screen-space hits near the board's edges are
    // its own approximation (`pretrace_hits_agree_with_the_bvh`).
    s.settings.ray_traced_gi.pretrace = false;
    s.settings.ray_traced_gi.hit_shadow_roulette = roulette;
    s.settings.exposure.ev100 = Some(0.0);
    let level = roulette * s.context().unwrap().metered_lux;
    let (mut skipped, mut traced) = (0, 0);
    assert!(s.settings.area_lights.enabled && s.settings.area_lights.punctual_shadows);
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let lights = renderer.scene().cpu.lights.clone();
    let Read {
        y: gy,
        cocg: gc,
        distance: gd,
        depth,
        normal,
        ..
    } = render(&mut renderer, &s);

    let view = View::new(&s.camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let cutoff = s.context().unwrap().light_cutoff_lux;
    let in_board =
        |q: Vec3| (q.x - board_at.x).abs() < board_half && (q.z - board_at.z).abs() < board_half;
    // The hits' normal face the rays, which all go up here.
    let down = reference::oct_decode(
        reference::unpack_normal(reference::pack_normal(reference::oct_encode(Vec3::NEG_Y)))
            .unwrap(),
    );
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let (mut off, mut shadowed, mut hits) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let d = depth[i][0];
            assert!(d > 0.0, "pixel ({x}, {y}) sees a surface");
            let n = reference::oct_decode(Vec2::new(normal[i][0], normal[i][1]));
            let world = reference::world_from_depth(inv_vp, [w, h], [x, y], d);
            let o = reference::ray_origin(world, n, s.camera.position);
            let (dir, weight) = reference::ray([x, y], 0, n);
            assert!(dir.y > 0.0);
            let mut t = (2.0 - o.y) / dir.y;
            let mut albedo = ceiling_albedo;
            let tb = (board_y - o.y) / dir.y;
            if o.y < board_y && in_board(o + dir * tb) {
                (t, albedo) = (tb, board_albedo);
            }
            let mut dbg_pick = None;
            let (radiance, unshadowed) = match unpack_hit(pack_hit(Some(t), albedo)) {
                HitWord::Hit { distance, albedo } if t < 250.0 => {
                    hits += 1;
                    let gpu_t = gd.rgba[i][0];
                    let used = if (gpu_t - distance).abs() <= distance * 2f32.powi(-10) * 1.001 {
                        gpu_t
                    } else {
                        distance
                    };
                    let eps = 1e-3 + 1e-3 * used;
                    let p = o + dir * (used - eps) + down * eps;
                    let each: Vec<Vec3> = lights
                        .iter()
                        .map(|l| reference::punctual_irradiance(p, down, l, cutoff))
                        .collect();
                    let mut e = Vec3::ZERO;
                    if let Some((k, ek, total)) =
                        reference::pick_light(each.iter().copied(), reference::random([x, y], 0, 3))
                    {
                        let at = reference::punctual_shadow_target(
                            &lights[k],
                            p,
                            s.settings.area_lights.punctual_radius_m,
                            [x, y],
                            0,
                        );
                        let sb = (board_y - p.y) / (at.y - p.y);
                        let blocked =
                            (p.y - board_y) * (at.y - board_y) < 0.0 && in_board(p + (at - p) * sb);
                        // The roulette (off at level 0): the estimate's luminance is `total`.
                        let q = if level > 0.0 {
                            (total / level).clamp(1e-6, 1.0)
                        } else {
                            1.0
                        };
                        if reference::random([x, y], 0, 5) >= q {
                            skipped += 1;
                        } else if blocked {
                            traced += 1;
                            shadowed += 1;
                        } else {
                            traced += 1;
                            e = ek * (total / lum(ek)) / q;
                        }
                        dbg_pick = Some((k, blocked, p));
                    }
                    let k = albedo / std::f32::consts::PI;
                    (k * e, k * each.iter().sum::<Vec3>())
                }
                _ => (Vec3::ZERO, Vec3::ZERO),
            };
            let want = reference::to_floats(&reference::encode_sample(radiance, dir, weight));
            let plain = reference::to_floats(&reference::encode_sample(unshadowed, dir, weight));
            let got = sample_at(&gy, &gc, i);
            let scale = (want[0].abs() / C0 as f32)
                .max(plain[0].abs() / C0 as f32)
                .max(1e-6);
            let tol = scale * 2f32.powi(-9);
            if (0..6).any(|k| (got[k] - want[k]).abs() > tol) {
                off += 1;
                if off <= 5 {
                    eprintln!(
                        "pixel ({x}, {y}): GPU {got:?} (t {}), twin {want:?} (t {t}; light, blocked, hit: {dbg_pick:?})",
                        gd.rgba[i][0]
                    );
                }
            }
        }
    }
    eprintln!("{hits} hits, {off} pixels off the twin, {shadowed} shadowed");
    assert!(hits > 4000, "only {hits} hits");
    assert!(
        off <= (w * h) as usize / 200,
        "{off} pixels differ from the twin"
    );
    if roulette > 0.0 {
        eprintln!("roulette: {skipped} hits skipped, {traced} traced");
        assert!(skipped >= hits / 20 && traced >= hits / 20);
    } else {
        assert_eq!(skipped, 0);
        assert!(
            shadowed >= (w * h) as usize / 20,
            "only {shadowed} pixels' hits are shadowed"
        );
    }
}

/// The cap on a sample's radiance relative to the exposure (`hit_radiance_cap`), against the
/// twin (`reference::cap_sample_radiance`, `hit_radiance_cap_nits`): a floor under a ceiling
/// 0.5 m up with a 2000 cd point light 1 cm below it, whose rays that hit the ceiling right
/// beside the light bring E = I / d² (up to 2·10⁷ lux, hundreds of times the cap), and the
/// rest a few hundred nits. Metered exposure, no sun. Frame 1 has no last exposure: no cap
/// (the CPU meter's floor, 1e-3 lux, would cap every lit sample). Frame 2's
/// cap is k · 1.2 · 2^EV100 of frame 1's adapted exposure, read back from `exposure.value`
/// (which the adapt pass writes with the same EV100 as `exposure.state`). k = 4, so that the
/// capped disk around the light is some 7 cm wide. Both frames: every pixel's sample as the
/// twin lights and caps it (tolerance as `hits_are_lit_like_the_twin`'s, relative to the
/// capped value); frame 2 must have both capped samples and lit ones left alone, frame 1 none
/// capped. A cap from the wrong exposure is off by orders of magnitude.
#[test]
fn a_hit_beside_a_lamp_is_capped_relative_to_the_last_exposure() {
    use hikari_scene::{Light, LightKind};
    let (ceiling_y, ceiling_albedo) = (0.5f32, Vec3::new(0.8, 0.7, 0.6));
    let k_cap = 4.0f32;
    let scene = Scene {
        meshes: vec![shapes::plane(400.0)],
        materials: vec![
            Material::diffuse("floor", Vec3::splat(0.5)),
            Material::diffuse("ceiling", ceiling_albedo),
        ],
        instances: vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            },
            Instance {
                mesh: 0,
                material: 1,
                transform: Mat4::from_translation(Vec3::new(0.0, ceiling_y, 0.0))
                    * Mat4::from_rotation_x(std::f32::consts::PI),
            },
        ],
        lights: vec![Light {
            name: "against the ceiling".into(),
            kind: LightKind::Point,
            position: Vec3::new(0.05, ceiling_y - 0.01, 0.02),
            direction: Vec3::NEG_Y,
            intensity_cd: 2000.0,
            color: Vec3::new(1.0, 0.8, 0.6),
            range: None,
            // A point: 1 cm under the ceiling, a disc of the default 5 cm would reach above it
            // and shadow half its own rays (the test is of the cap, not of soft shadows).
            radius_m: Some(0.0),
        }],
        cameras: vec![Camera {
            name: "down".into(),
            position: Vec3::new(0.0, 0.4, 0.0),
            target: Vec3::ZERO,
            up: Vec3::Z,
            ..Camera::default()
        }],
        sun: None,
        ..Default::default()
    };
    let (w, h) = (64u32, 64u32);
    let mut s = rtgi_settings(&scene, w, h);
    s.sun = hikari_render::SunSource::Off;
    s.settings.ray_traced_gi.accumulate = false;
    s.settings.ray_traced_gi.pretrace = false;
    s.settings.ray_traced_gi.reuse_lit = false;
    s.settings.ray_traced_gi.hit_shadow_roulette = 0.0;
    s.settings.ray_traced_gi.hit_radiance_cap = k_cap;
    // Frame 2 unjittered, so that its pixels' points are the twin's.
    s.settings.taa.enabled = false;
    assert_eq!(s.settings.exposure.ev100, None, "the metered exposure");
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let light = renderer.scene().cpu.lights[0];
    let view = View::new(&s.camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let cutoff = s.context().unwrap().light_cutoff_lux;
    let down = reference::oct_decode(
        reference::unpack_normal(reference::pack_normal(reference::oct_encode(Vec3::NEG_Y)))
            .unwrap(),
    );
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    // The first frame's EV100: the CPU meter's (`FrameSettings::ev100`), no history.
    let mut ev100 = s.context().unwrap().ev100;
    assert!((ev100 - (1e-3f32 * 0.4).log2()).abs() < 1e-5, "{ev100}");
    for frame in 0..2u32 {
        // No cap without a last exposure (0: none).
        let cap = if frame == 0 {
            0.0
        } else {
            reference::hit_radiance_cap_nits(k_cap, ev100)
        };
        assert!(cap >= 0.0 && cap.is_finite());
        let Read {
            y: gy,
            cocg: gc,
            distance: gd,
            depth,
            normal,
            exposure: value,
            ..
        } = render(&mut renderer, &s);
        let (mut off, mut capped, mut untouched, mut hits) = (0, 0, 0, 0);
        let mut hottest = 0f32;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let d = depth[i][0];
                assert!(d > 0.0, "pixel ({x}, {y}) sees the floor");
                let n = reference::oct_decode(Vec2::new(normal[i][0], normal[i][1]));
                let world = reference::world_from_depth(inv_vp, [w, h], [x, y], d);
                let o = reference::ray_origin(world, n, s.camera.position);
                let (dir, weight) = reference::ray([x, y], frame, n);
                let t = (ceiling_y - o.y) / dir.y;
                let raw = match unpack_hit(pack_hit(Some(t), ceiling_albedo)) {
                    HitWord::Hit { distance, albedo } if t < 250.0 => {
                        hits += 1;
                        let gpu_t = gd.rgba[i][0];
                        let used = if (gpu_t - distance).abs() <= distance * 2f32.powi(-10) * 1.001
                        {
                            gpu_t
                        } else {
                            distance
                        };
                        let eps = 1e-3 + 1e-3 * used;
                        let p = o + dir * (used - eps) + down * eps;
                        albedo / std::f32::consts::PI
                            * reference::punctual_irradiance(p, down, &light, cutoff)
                    }
                    _ => Vec3::ZERO,
                };
                let radiance = reference::cap_sample_radiance(raw, cap);
                hottest = hottest.max(lum(raw) / cap.max(1e-30));
                if cap > 0.0 && lum(raw) > cap * 1.01 {
                    capped += 1;
                    assert!((lum(radiance) - cap).abs() <= cap * 1e-5);
                } else if lum(raw) > 0.0 && lum(raw) < cap * 0.99 {
                    untouched += 1;
                }
                let want = reference::to_floats(&reference::encode_sample(radiance, dir, weight));
                let got = sample_at(&gy, &gc, i);
                let scale = (want[0].abs() / C0 as f32).max(1e-9);
                if (0..6).any(|k| (got[k] - want[k]).abs() > scale * 2f32.powi(-9)) {
                    off += 1;
                    if off <= 5 {
                        eprintln!("frame {frame} pixel ({x}, {y}): GPU {got:?}, twin {want:?}");
                    }
                }
            }
        }
        eprintln!(
            "frame {frame}: EV100 {ev100:.3}, cap {cap:.4} nits; {hits} hits, {capped} capped \
             (hottest {hottest:.0} times the cap), {untouched} below it, {off} off the twin"
        );
        assert!(hits > 4000, "only {hits} hits");
        assert!(
            off <= (w * h) as usize / 200,
            "{off} pixels differ from the twin"
        );
        if frame == 0 {
            assert_eq!(capped, 0, "no cap on a first frame");
        } else {
            assert!(capped >= 20, "only {capped} samples capped");
            assert!(
                hottest > 100.0,
                "the hottest sample is {hottest} times the cap"
            );
            assert!(untouched >= 1000, "only {untouched} samples below the cap");
        }
        // The next frame's cap: this frame's adapted exposure, as `exposure.state` keeps it.
        ev100 = value[1];
        assert!(ev100.is_finite(), "exposure.value {value:?}");
    }
}

/// The sun's shadow at hits from the shadow maps (inside a cascade) against shadow rays
/// through the BVH, two independent methods, on `boxes` by day: the same rays (frame 0, no
/// accumulation). The maps filter (PCF) and are coarse here (256 texels over 40 m), so pixels
/// whose hit lies near a shadow's edge differ; the image means of c0 agree within 3 % and
/// at least 85 % of pixels within 10 % of the mean. Some pixels must differ, or the maps were
/// not used.
#[test]
fn hit_shadows_from_maps_agree_with_shadow_rays() {
    let scene = hikari_scene::builtin::boxes();
    let mut s = rtgi_settings(&scene, 64, 64);
    s.settings.ray_traced_gi.accumulate = false;
    let mut maps = Renderer::new(common::gpu_context(), &scene).unwrap();
    let a = render(&mut maps, &s);
    s.settings.ray_traced_gi.shadow_maps = false;
    let mut rays = Renderer::new(common::gpu_context(), &scene).unwrap();
    let b = render(&mut rays, &s);
    let n = a.y.rgba.len();
    let mean = |r: &Read| r.y.rgba.iter().map(|p| p[0] as f64).sum::<f64>() as f32 / n as f32;
    let (ma, mb) = (mean(&a), mean(&b));
    let close = (0..n)
        .filter(|&i| (a.y.rgba[i][0] - b.y.rgba[i][0]).abs() <= 0.1 * mb)
        .count();
    let differ = (0..n).filter(|&i| a.y.rgba[i][0] != b.y.rgba[i][0]).count();
    eprintln!("c0 mean: maps {ma}, rays {mb}; {close} of {n} close, {differ} differ");
    assert!(mb > 0.0);
    assert!((ma / mb - 1.0).abs() < 0.03, "maps {ma}, rays {mb}");
    assert!(close as f32 >= 0.85 * n as f32, "{close} of {n}");
    assert!(differ > 0, "the shadow maps were not used");
}

/// Reusing last frame's lit image for hits it saw, against lighting every hit: `boxes`, no
/// accumulation, the second frame of a still camera (same rays in both renderers). The lit
/// image holds the full shading seen from the camera (specular, textures, occlusion) where
/// the computed light is diffuse from the hit's quantised albedo facing the ray, so only the
/// image means are compared (within 25 %); pixels must differ, or nothing was reused, and on
/// the first frame (no lit image yet) the two are identical.
#[test]
fn reused_lit_image_agrees_with_computed_light() {
    let scene = hikari_scene::builtin::boxes();
    let mut s = rtgi_settings(&scene, 64, 64);
    s.settings.ray_traced_gi.accumulate = false;
    let mut reuse = Renderer::new(common::gpu_context(), &scene).unwrap();
    let a0 = render(&mut reuse, &s);
    let a1 = render(&mut reuse, &s);
    s.settings.ray_traced_gi.reuse_lit = false;
    let mut compute = Renderer::new(common::gpu_context(), &scene).unwrap();
    let b0 = render(&mut compute, &s);
    let b1 = render(&mut compute, &s);
    assert_eq!(a0.y.rgba, b0.y.rgba, "frame 0 has no lit image to reuse");
    let n = a1.y.rgba.len();
    let mean = |r: &Read| r.y.rgba.iter().map(|p| p[0] as f64).sum::<f64>() as f32 / n as f32;
    let (ma, mb) = (mean(&a1), mean(&b1));
    let differ = (0..n)
        .filter(|&i| a1.y.rgba[i][0] != b1.y.rgba[i][0])
        .count();
    eprintln!("c0 mean: reused {ma}, computed {mb}; {differ} of {n} pixels differ");
    assert!(differ > 50, "only {differ} pixels took the lit image");
    assert!((ma / mb - 1.0).abs() < 0.25, "reused {ma}, computed {mb}");
    assert!(a1.y.rgba.iter().all(|p| p.iter().all(|v| v.is_finite())));
}

/// A lamp's glowing shell around a point light (the village's paper lanterns, left out of the
/// area lights) is marked like an area light in the GI's instance table (w = 1), so that a hit
/// on it does not add its emission: the light inside already lights the hits, and the small,
/// bright paper hit by few rays made white speckle at night. Emissive instances that no light
/// stands for keep w = 0.
#[test]
fn lamp_shells_do_not_add_their_emission_at_hits() {
    use hikari_render::lights::polygon::SKIPPED_LAMP_SHELL;
    use hikari_render::techniques::area_lights::PolygonLights;
    let scene = hikari_scene::builtin::village();
    let table = reference::instance_table(&scene);
    let area = PolygonLights::for_scene(&scene);
    let shells: Vec<usize> = area
        .skipped
        .iter()
        .filter(|(_, why)| *why == SKIPPED_LAMP_SHELL)
        .map(|(k, _)| *k)
        .collect();
    assert!(
        shells.len() >= 10,
        "the village's lanterns: {} shells",
        shells.len()
    );
    for &k in &shells {
        let e = table[2 * k + 1];
        assert!(e[0] + e[1] + e[2] > 0.0, "shell {k} emits");
        assert_eq!(
            e[3], 1.0,
            "shell {k}: its emission must not be added at hits"
        );
    }
    for (k, why) in &area.skipped {
        if *why != SKIPPED_LAMP_SHELL {
            assert_eq!(table[2 * k + 1][3], 0.0, "instance {k}, skipped as {why}");
        }
    }
}

/// The clouds in the GI: a miss sees them over the sky as the deferred lighting draws them, and
/// the sun at a hit is shadowed by them. Three frames of the same rays: A with clouds, B without,
/// C without clouds or the GI's sun. The encoding is linear in the radiance and
/// `clouds_over_sky` is affine in the sky behind, so per pixel, against the clouds' twin with
/// the frame's own map: a miss's sample is t · B + encode(clouds' light), with t their
/// transmittance towards the ray; a hit's is C + (B − C) · `cloud_shadow_at` the hit. A wall
/// facing the sun beside the floor gives sunlit hits; the clouds are moved until a cloud's edge
/// lies over it. Tolerance: three f16 samples, 2^-8 of the larger luminance scale, with at most
/// 1 % of pixels beyond (a hit point 1 mm off the surface, a map texel's rounding). The twin
/// takes the shade pass's limits: 65000 nits a channel, and f16's largest value in storage.
#[test]
fn misses_and_hits_see_the_clouds_like_the_twin() {
    use hikari_render::techniques::clouds::CloudParams;
    use hikari_render::techniques::clouds::reference as clouds;
    use hikari_render::techniques::sky;
    let sky_settings = hikari_render::settings::SkySettings {
        time: "10:00".into(),
        ..Default::default()
    };
    let sun = sky::lights::directional_light(&sky_settings)
        .unwrap()
        .expect("the sun is up at 10:00");
    let to_sun = Vec3::new(sun.direction.x, 0.0, sun.direction.z).normalize();
    let mut scene = floor_scene();
    // A 6 m wall 3 m from the origin away from the sun, its lit face towards the floor.
    scene.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_translation(-3.0 * to_sun + Vec3::new(0.0, 3.0, 0.0))
            * Mat4::from_quat(glam::Quat::from_rotation_arc(Vec3::Y, to_sun))
            * Mat4::from_scale(Vec3::splat(6.0 / 400.0)),
    });
    let clouds_settings = |offset: f32| hikari_render::settings::CloudsSettings {
        offset_x_m: offset,
        ..common::small_clouds(0.45, 1500.0)
    };
    // The frame's clock: 10:00 (36 000 s), the wind's offset included.
    let params_of = |c: &hikari_render::settings::CloudsSettings| {
        CloudParams::new(c, "clear", Some(&sun), 36_000.0, true)
    };
    let wall = -3.0 * to_sun + Vec3::new(0.0, 1.5, 0.0);
    let offset = (0..400)
        .map(|k| k as f32 * 37.0)
        .find(|&o| {
            let t = clouds::cloud_shadow_at(&params_of(&clouds_settings(o)), wall);
            t > 0.2 && t < 0.8
        })
        .expect("some offset puts a cloud's edge over the wall");
    let (w, h) = (64u32, 48u32);
    let frame = |clouds_on: bool, gi_sun: bool| {
        let mut s = twin_settings(&scene, w, h);
        s.settings.sky = sky_settings.clone();
        s.settings.sky.enabled = true;
        s.settings.sky.table_quality = 0;
        s.settings.area_lights.enabled = false;
        s.settings.clouds = clouds_settings(offset);
        s.settings.clouds.enabled = clouds_on;
        // The clear sky's SH in all three frames (the hits' sky light): tests/render/sky.rs holds the
        // SH with the clouds.
        s.settings.clouds.ambient = false;
        s.settings.ray_traced_gi.sun = gi_sun;
        s.sun = hikari_render::SunSource::Fixed(sun.clone());
        s
    };
    struct Out {
        y: ImageRgba32,
        cocg: ImageRgba32,
        distance: ImageRgba32,
        depth: Vec<[f32; 4]>,
        normal: Vec<[f32; 4]>,
        map: Vec<glam::Vec4>,
        mean_sky: Vec3,
    }
    let run = |s: &FrameSettings| {
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        let mut picked = None;
        let mut r = renderer
            .render_reading(s, |o| {
                let f = o.ray_traced_gi.expect("the technique is on");
                picked = Some((f, o.clouds.map));
                vec![
                    f.gi_y.into(),
                    f.gi_cocg.into(),
                    f.hit_distance.into(),
                    o.gbuffer.depth.into(),
                    o.gbuffer.normal.into(),
                    o.clouds.map.into(),
                    o.sky.sh.into(),
                ]
            })
            .unwrap();
        let (f, map) = picked.unwrap();
        let sh = bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec();
        Out {
            y: r.take_image_of(f.gi_y).unwrap(),
            cocg: r.take_image_of(f.gi_cocg).unwrap(),
            distance: r.take_image_of(f.hit_distance).unwrap(),
            depth: r.image("gbuffer.depth").unwrap().rgba.clone(),
            normal: r.image("gbuffer.normal").unwrap().rgba.clone(),
            map: r
                .take_image_of(map)
                .unwrap()
                .rgba
                .iter()
                .map(|v| glam::Vec4::from_array(*v))
                .collect(),
            // The sky's mean radiance: band 0 of its SH times Y00.
            mean_sky: Vec3::from_slice(&sh[9][..3]) * 0.282_094_8,
        }
    };
    let s = frame(true, true);
    let a = run(&s);
    let b = run(&frame(false, true));
    let c = run(&frame(false, false));
    let params = params_of(&s.settings.clouds);
    let sun_lux = sun.color * sun.illuminance_lux;
    let view = View::new(&s.camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let (mut misses, mut clouded, mut hits, mut shaded, mut off) = (0, 0, 0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let d = a.depth[i][0];
            assert!(d > 0.0, "pixel ({x}, {y}) sees the floor or the wall");
            let n = reference::oct_decode(Vec2::new(a.normal[i][0], a.normal[i][1]));
            let world = reference::world_from_depth(inv_vp, [w, h], [x, y], d);
            let o = reference::ray_origin(world, n, s.camera.position);
            let (dir, weight) = reference::ray([x, y], 0, n);
            let (ga, gb, gc) = (
                sample_at(&a.y, &a.cocg, i),
                sample_at(&b.y, &b.cocg, i),
                sample_at(&c.y, &c.cocg, i),
            );
            let t_hit = a.distance.rgba[i][0];
            let want: [f32; 6] = if t_hit > 0.0 {
                let t = clouds::cloud_shadow_at(&params, o + dir * t_hit);
                hits += 1;
                shaded += (t < 0.9 && gb[0] > 1.2 * gc[0]) as u32;
                std::array::from_fn(|k| (gc[k] + (gb[k] - gc[k]) * t).clamp(-65504.0, 65504.0))
            } else {
                // The sky behind, from B's sample: c0 = C0 Y w, (Co, Cg) w.
                let back = ycocg_to_rgb(Vec3::new(
                    gb[0] / (C0 as f32 * weight),
                    gb[4] / weight,
                    gb[5] / weight,
                ));
                let l = clouds::clouds_over_sky(&params, &a.map, dir, back, sun_lux, a.mean_sky);
                misses += 1;
                clouded += ((l - back).length() > 0.1 * back.length()) as u32;
                // The shade pass's per-channel limit (f16 storage), which bright cloud edges
                // near the sun reach.
                let l = l.min(Vec3::splat(65000.0));
                reference::to_floats(&reference::encode_sample(l, dir, weight))
                    .map(|v| v.clamp(-65504.0, 65504.0))
            };
            let scale = ga[0].abs().max(gb[0].abs()) + 1e-6;
            if (0..6).any(|k| (ga[k] - want[k]).abs() > scale * 2f32.powi(-8)) {
                off += 1;
                if off <= 5 {
                    eprintln!("pixel ({x}, {y}) (hit {t_hit}): GPU {ga:?}, twin {want:?}");
                }
            }
        }
    }
    eprintln!(
        "{misses} misses ({clouded} under cloud), {hits} hits ({shaded} sunlit under cloud), {off} off"
    );
    assert!(
        clouded > 100 && misses - clouded > 100,
        "{clouded} of {misses} misses under cloud"
    );
    assert!(shaded > 20, "{shaded} of {hits} sunlit hits under cloud");
    assert!(
        off <= (w * h) as usize / 100,
        "{off} pixels differ from the twin"
    );
}
