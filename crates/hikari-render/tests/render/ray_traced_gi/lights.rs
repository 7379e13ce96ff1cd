//! The light grid that hits pick their lights from, and many lights at hits.

use super::*;

/// The light grid lists every light that can reach a point of a cell: against the shade
/// pass's own reach tests (the twins `area_light_reaches` and `punctual_irradiance`) at random
/// points, many on a reach's boundary, and against each light's sphere overlapping each cell's
/// box. A hit picks from its cell's lists exactly as from all lights (the running choice, the
/// sums), bit for bit.
#[test]
fn light_grid_lists_every_light_that_reaches_a_cell() {
    use hikari_render::lights::grid::{
        HEADER_RECORDS, LightGrid, area_reach, grid_cutoff, punctual_reach,
    };
    let mut rng = SmallRng::seed_from_u64(18);
    let (lights, area) = scattered_lights(&mut rng, 200, 50);
    let (min_flux, cutoff) = (0.3f32, 0.013f32);
    let gc = grid_cutoff(cutoff);
    assert!(gc <= cutoff && gc > cutoff * 0.5, "grid cut-off {gc}");
    let grid = LightGrid::build(&area.lights, &lights, min_flux, gc);
    let [dx, dy, dz] = grid.dims();
    let cells = (dx * dy * dz) as usize;
    assert!(
        cells > 100 && dx <= 64 && dy <= 64 && dz <= 64,
        "{:?}",
        grid.dims()
    );
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    // Sphere/box overlap at the grid's cut-off, lists ascending.
    let mut overlaps = 0usize;
    for c in 0..cells {
        let (lo, hi) = grid.cell_box(c);
        let [first, na, np, _] = grid.cells[HEADER_RECORDS + c];
        let list_a = &grid.indices[first as usize..(first + na) as usize];
        let list_p = &grid.indices[(first + na) as usize..(first + na + np) as usize];
        assert!(list_a.windows(2).all(|w| w[0] < w[1]) && list_p.windows(2).all(|w| w[0] < w[1]));
        let touches = |centre: Vec3, r: f32| (centre.clamp(lo, hi) - centre).length() <= r;
        for (k, l) in area.lights.iter().enumerate() {
            let Some(r) = area_reach(l, min_flux, gc) else {
                assert!(
                    !list_a.contains(&(k as u32)),
                    "skipped area light {k} in cell {c}"
                );
                continue;
            };
            if touches(Vec3::from_slice(&l.centroid_radius[..3]), r) {
                overlaps += 1;
                assert!(
                    list_a.contains(&(k as u32)),
                    "area light {k} not in cell {c}"
                );
            }
        }
        for (k, l) in lights.iter().enumerate() {
            if touches(
                Vec3::from_slice(&l.position_range[..3]),
                punctual_reach(l, gc),
            ) {
                overlaps += 1;
                assert!(list_p.contains(&(k as u32)), "light {k} not in cell {c}");
            }
        }
    }
    // Inflated only by rounding margins: not many more entries than true overlaps.
    assert!(
        grid.entries() >= overlaps && grid.entries() <= overlaps + overlaps / 10,
        "{} entries for {overlaps} overlaps",
        grid.entries()
    );
    // Random points, half of them just inside a light's reach at the frame's cut-off.
    let (mut reached, mut picks) = (0, 0);
    for t in 0..20000 {
        let x = if t % 2 == 0 {
            Vec3::new(
                rng.random_range(-25.0..25.0),
                rng.random_range(-4.0..12.0),
                rng.random_range(-25.0..25.0),
            )
        } else if t % 4 == 1 {
            let l = &lights[rng.random_range(0..lights.len())];
            let r = punctual_reach(l, cutoff);
            Vec3::from_slice(&l.position_range[..3])
                + random_unit(&mut rng) * r * (1.0 - rng.random_range(0.0..1e-5))
        } else {
            let l = &area.lights[rng.random_range(0..area.lights.len())];
            let r = area_reach(l, 0.0, cutoff).unwrap();
            Vec3::from_slice(&l.centroid_radius[..3])
                + random_unit(&mut rng) * r * (1.0 - rng.random_range(0.0..1e-5))
        };
        let n = random_unit(&mut rng);
        let (la, lp) = grid.lights_at(x);
        for k in 0..area.lights.len() {
            if reference::area_light_reaches(&area, k, x, n, min_flux, cutoff) {
                reached += 1;
                assert!(
                    la.contains(&(k as u32)),
                    "area light {k} reaches {x} off the grid"
                );
            }
        }
        let each: Vec<Vec3> = lights
            .iter()
            .map(|l| reference::punctual_irradiance(x, n, l, cutoff))
            .collect();
        for (k, e) in each.iter().enumerate() {
            if lum(*e) > 0.0 {
                reached += 1;
                assert!(
                    lp.contains(&(k as u32)),
                    "light {k} reaches {x} off the grid"
                );
            }
        }
        // The picks over the cell's lists are the picks over all lights.
        let u = rng.random::<f32>();
        let all = reference::pick_weighted(
            (0..area.lights.len())
                .map(|k| reference::area_light_score(&area, k, x, n, min_flux, cutoff)),
            u,
        );
        let listed = reference::pick_weighted(
            la.iter()
                .map(|&k| reference::area_light_score(&area, k as usize, x, n, min_flux, cutoff)),
            u,
        )
        .map(|(i, s, total)| (la[i] as usize, s, total));
        assert_eq!(all, listed, "area pick at {x}");
        let all = reference::pick_light(each.iter().copied(), u);
        let listed = reference::pick_light(lp.iter().map(|&k| each[k as usize]), u)
            .map(|(i, e, total)| (lp[i] as usize, e, total));
        assert_eq!(all, listed, "punctual pick at {x}");
        let sum_all = each.iter().fold(Vec3::ZERO, |a, &e| a + e);
        let sum_listed = lp.iter().fold(Vec3::ZERO, |a, &k| a + each[k as usize]);
        assert_eq!(sum_all, sum_listed, "punctual sum at {x}");
        picks += all.is_some() as u32;
    }
    assert!(
        reached > 10000 && picks > 2000,
        "{reached} reaches, {picks} picks"
    );
}

/// Many lights at hits: 200 small point lights (each with a range of 0.3 to 1.5 m) under a
/// ceiling and 50 lamps (area lights, some under the minimum flux, some forced) on the floor,
/// scattered over 8 m: the GPU, which visits only the lights of the hit's grid cell, against
/// the twin's loops over all lights. Rays from the floor hit the ceiling, as in
/// `hits_are_lit_like_the_twin`; nothing stands between a hit and the lights, so the shadow
/// rays all pass.
#[test]
fn many_lights_at_hits_are_lit_like_the_all_lights_twin() {
    use hikari_render::lights::grid;
    use hikari_scene::{Light, LightKind};
    let mut rng = SmallRng::seed_from_u64(250);
    let ceiling_albedo = Vec3::new(0.8, 0.7, 0.6);
    let mut materials = vec![
        Material::diffuse("floor", Vec3::splat(0.5)),
        Material::diffuse("ceiling", ceiling_albedo),
    ];
    let mut instances = vec![
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
    ];
    for k in 0..50 {
        materials.push(Material {
            emissive_nits: Vec3::new(1.0, 0.8, 0.6) * rng.random_range(0.5..3.0),
            area_light: if k % 3 == 0 { Some(true) } else { None },
            ..Material::diffuse("lamp", Vec3::splat(0.5))
        });
        // 2 mm above the floor, under the rays' origins: no GI ray hits them.
        let at = Vec3::new(
            rng.random_range(-4.0..4.0),
            0.002,
            rng.random_range(-4.0..4.0),
        );
        instances.push(Instance {
            mesh: 0,
            material: 2 + k,
            transform: Mat4::from_translation(at)
                * Mat4::from_scale(Vec3::new(0.2 / 400.0, 1.0, 0.2 / 400.0)),
        });
    }
    let lights = (0..200)
        .map(|k| Light {
            name: format!("light {k}"),
            kind: if k % 4 == 0 {
                LightKind::Spot {
                    inner_cone: 0.3,
                    outer_cone: 0.8,
                }
            } else {
                LightKind::Point
            },
            position: Vec3::new(
                rng.random_range(-4.0..4.0),
                rng.random_range(1.0..1.9),
                rng.random_range(-4.0..4.0),
            ),
            direction: Vec3::Y,
            intensity_cd: rng.random_range(0.2..3.0),
            color: Vec3::new(1.0, 0.9, 0.7),
            range: Some(rng.random_range(0.3..1.5)),
            radius_m: None,
        })
        .collect();
    let scene = Scene {
        meshes: vec![shapes::plane(400.0)],
        materials,
        instances,
        lights,
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
    let mut s = twin_settings(&scene, w, h);
    s.settings.area_lights.min_flux_lm = 0.25;
    let min_flux = s.settings.area_lights.min_flux_lm;
    let shadows = s.settings.area_lights.punctual_shadows;
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let lights = renderer.scene().cpu.lights.clone();
    let area = renderer.area_lights().lights.clone();
    assert_eq!(area.lights.len(), 50, "every lamp is an area light");
    let Read {
        y: gy,
        cocg: gc,
        distance: gd,
        depth,
        normal,
        ..
    } = render(&mut renderer, &s);
    // The grid the frame used: several cells, each listing a small part of the lights.
    let cutoff = s.context().unwrap().light_cutoff_lux;
    let grid = grid::LightGrid::build(
        &area.lights,
        &grid::punctual_records(&scene),
        min_flux,
        grid::grid_cutoff(cutoff),
    );
    let cells = grid.dims().iter().product::<u32>() as usize;
    eprintln!(
        "light grid: {:?} cells, {} entries",
        grid.dims(),
        grid.entries()
    );
    assert!(
        cells > 8 && grid.entries() < 250 * cells / 4,
        "{:?}, {}",
        grid.dims(),
        grid.entries()
    );
    let view = View::new(&s.camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let down = reference::oct_decode(
        reference::unpack_normal(reference::pack_normal(reference::oct_encode(Vec3::NEG_Y)))
            .unwrap(),
    );
    let (mut off, mut lit_area, mut lit_points) = (0, 0, 0);
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
            let radiance = match unpack_hit(pack_hit(Some(t), ceiling_albedo)) {
                HitWord::Hit { distance, albedo } if t < 250.0 => {
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
                    let mut e = if shadows {
                        reference::pick_light(each.iter().copied(), reference::random([x, y], 0, 3))
                            .map_or(Vec3::ZERO, |(_, ek, total)| {
                                ek * (total / ek.dot(Vec3::new(0.2126, 0.7152, 0.0722)))
                            })
                    } else {
                        each.iter().fold(Vec3::ZERO, |a, &e| a + e)
                    };
                    lit_points += (e.max_element() > 0.0) as u32;
                    let scores = (0..area.lights.len())
                        .map(|k| reference::area_light_score(&area, k, p, down, min_flux, cutoff));
                    if let Some((k, sk, total)) =
                        reference::pick_weighted(scores, reference::random([x, y], 0, 0))
                    {
                        let ek =
                            reference::area_light_irradiance(&area, k, p, down, min_flux, cutoff);
                        e += ek * (total / sk);
                        lit_area += 1;
                    }
                    albedo / std::f32::consts::PI * e
                }
                _ => Vec3::ZERO,
            };
            let want = reference::to_floats(&reference::encode_sample(radiance, dir, weight));
            let got = sample_at(&gy, &gc, i);
            let scale = (want[0].abs() / C0 as f32).max(1e-6);
            if (0..6).any(|k| (got[k] - want[k]).abs() > scale * 2f32.powi(-9)) {
                off += 1;
                if off <= 5 {
                    eprintln!("pixel ({x}, {y}): GPU {got:?}, twin {want:?} (t {t})");
                }
            }
        }
    }
    eprintln!("{lit_points} hits lit by point lights, {lit_area} by area lights, {off} off");
    assert!(
        lit_points > 500 && lit_area > 500,
        "{lit_points} and {lit_area} hits lit"
    );
    assert!(
        off <= (w * h) as usize / 200,
        "{off} pixels differ from the twin"
    );
}

/// The village's light grid at night (the cut-off at its floor, the default minimum flux):
/// cells, list entries and bytes, for docs/ray-traced-gi.md.
#[test]
#[ignore = "a measurement, for the documentation"]
fn village_light_grid_size() {
    use hikari_render::lights::LIGHT_CUTOFF_LUX;
    use hikari_render::lights::grid::{LightGrid, grid_cutoff, punctual_records};
    use hikari_render::techniques::area_lights::PolygonLights;
    let scene = hikari_scene::builtin::village();
    let area = PolygonLights::for_scene(&scene);
    let punctual = punctual_records(&scene);
    let min_flux =
        hikari_render::techniques::area_lights::AreaLightsSettings::default().min_flux_lm;
    let grid = LightGrid::build(
        &area.lights,
        &punctual,
        min_flux,
        grid_cutoff(LIGHT_CUTOFF_LUX),
    );
    let [dx, dy, dz] = grid.dims();
    let cells = (dx * dy * dz) as usize;
    let used = grid.cells[2..].iter().filter(|c| c[1] + c[2] > 0).count();
    let max = grid.cells[2..]
        .iter()
        .map(|c| c[1] + c[2])
        .max()
        .unwrap_or(0);
    let bright = area
        .lights
        .iter()
        .filter(|l| hikari_render::lights::grid::area_reach(l, min_flux, 1.0).is_some())
        .count();
    eprintln!(
        "village: {} area lights ({bright} over {min_flux} lm or forced), {} point/spot lights; \
         grid {dx}x{dy}x{dz} = {cells} cells of {:.2} m ({used} non-empty), {} entries (mean \
         {:.1} a non-empty cell, most {max}), {:.0} KiB",
        area.lights.len(),
        punctual.len(),
        f32::from_bits(grid.cells[0][3]),
        grid.entries(),
        grid.entries() as f64 / used.max(1) as f64,
        grid.bytes() as f64 / 1024.0
    );
}
