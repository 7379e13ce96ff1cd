//! Temporal accumulation: the CPU twin, the analytic open floor, the firefly clamp.

use super::*;

/// Three frames of accumulation on synthetic inputs (a still camera over a slanted plane; raw
/// samples random; NaN and infinity injected into raw samples, motion and depth; pixels whose
/// history lies off screen or at another depth), GPU against the twin, which keeps its history
/// in f16 as the textures do, rounding to nearest. Vulkan lets the GPU's f16 store round
/// either way (lavapipe truncates), so the two may drift apart by an f16 ulp a frame of
/// history, and values blend terms up to 5 in size, so a result near 0 carries the rounding of
/// its terms: tolerance 2^-10 · max(|value|, 1) · frames of history; a wrong speed or a
/// history taken when it should not be is off by 0.1 to 5.
#[test]
fn accumulation_matches_the_cpu_twin_and_rejects_bad_history() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let rtgi = RayTracedGi::new(&ctx, &mut lib).unwrap();
    let (w, h) = (64u32, 64u32);
    let camera = Camera {
        position: Vec3::new(0.0, 3.0, 6.0),
        target: Vec3::ZERO,
        ..Camera::default()
    };
    let view = View::new(&camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let prev_vp = Mat4::from_cols_array_2d(&view.prev_view_proj);
    let forward = camera.forward();
    let settings = RayTracedGiSettings {
        max_history: 3,
        ..RayTracedGiSettings::default()
    };
    let mut base = RtGiParams::new(&settings, 0, None, 0, 1000.0, 0.1, SkySource::None);
    assert_ne!(base.flags() & FLAG_ACCUMULATE, 0);
    // A firefly clamp tight enough to act on these random samples from 2 frames of history
    // on, so that its 3x3 scale is compared too (reprojected, at the image's edges, beside
    // rejected and non-finite history).
    let firefly = FireflyClamp {
        k: 1.5,
        floor: 0.25,
        min_history: 2.0,
    };
    base.firefly = firefly.to_array();
    let mut clamped = 0;
    let mut rng = SmallRng::seed_from_u64(7);
    let mut rt = GraphRuntime::new();
    let mut history: Vec<Accumulated> = vec![Accumulated::default(); (w * h) as usize];
    let mut history_valid = false;
    for frame in 0..5u32 {
        // Depth: reverse-Z of a plane; a corner of sky. Motion: still, except a block moved by
        // (+3, -2) pixels, one block whose history depth is wrong, one whose history is off
        // screen, and the injected non-finite values.
        let mut depth = vec![0f32; (w * h) as usize];
        let mut motion = vec![[0f32; 4]; (w * h) as usize];
        let mut raw_y = vec![[0f32; 4]; (w * h) as usize];
        let mut raw_c = vec![[0f32; 4]; (w * h) as usize];
        let mut worlds = vec![Vec3::ZERO; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let d = if x + y < 6 {
                    0.0
                } else {
                    0.02 + 0.001 * (x as f32) + 0.0005 * y as f32
                };
                depth[i] = d;
                let world = reference::world_from_depth(inv_vp, [w, h], [x, y], d);
                worlds[i] = world;
                let vz = (world - camera.position).dot(forward);
                let mut m = [0.0, 0.0, f16(vz), 0.0];
                if (20..30).contains(&x) && (20..30).contains(&y) && frame == 2 {
                    m[0] = 3.0;
                    m[1] = -2.0;
                }
                if (40..48).contains(&x) && (5..12).contains(&y) && frame >= 1 {
                    m[2] = f16(vz * 1.5); // the history was seen at another depth
                }
                if x == 63 && frame == 3 {
                    m[0] = 4.0; // off screen
                }
                // Bilinear reprojection: a fractional motion; one towards the sky corner, where
                // some taps have no history and the rest are renormalised; one within the snap.
                if (8..16).contains(&x) && (40..48).contains(&y) && frame >= 3 {
                    m[0] = 1.25;
                    m[1] = -0.625;
                }
                if (6..10).contains(&(x + y)) && frame == 4 {
                    m[0] = -0.75;
                    m[1] = -0.5;
                }
                if (50..56).contains(&x) && (50..56).contains(&y) && frame == 4 {
                    m[0] = 0.0078125;
                }
                motion[i] = m;
                let c: [f32; 6] = std::array::from_fn(|_| f16(rng.random_range(-2.0..5.0)));
                raw_y[i] = [c[0], c[1], c[2], c[3]];
                raw_c[i] = [c[4], c[5], f16(rng.random_range(0.0..1.0)), 0.0];
            }
        }
        // Injected non-finite values.
        raw_y[(30 * w + 33) as usize][2] = f32::NAN;
        raw_c[(31 * w + 33) as usize][0] = f32::INFINITY;
        raw_c[(32 * w + 33) as usize][2] = f32::NAN;
        motion[(33 * w + 33) as usize][0] = f32::NAN;
        motion[(34 * w + 33) as usize][2] = f32::INFINITY;
        depth[(35 * w + 33) as usize] = f32::NAN;

        let depth_tex = texture(
            &ctx,
            wgpu::TextureFormat::R32Float,
            w,
            h,
            bytemuck::cast_slice(&depth),
        );
        let motion_tex = texture(
            &ctx,
            wgpu::TextureFormat::Rgba16Float,
            w,
            h,
            &halves(&motion),
        );
        let y_tex = texture(
            &ctx,
            wgpu::TextureFormat::Rgba16Float,
            w,
            h,
            &halves(&raw_y),
        );
        let c_tex = texture(
            &ctx,
            wgpu::TextureFormat::Rgba16Float,
            w,
            h,
            &halves(&raw_c),
        );
        let dist_tex = texture(
            &ctx,
            wgpu::TextureFormat::R16Float,
            w,
            h,
            &vec![0u8; (w * h * 2) as usize],
        );
        let mut params = base;
        params.config[0] = frame;
        let reset = frame == 4;
        params.set_flag(FLAG_RESET, reset);
        let mut g = rt.begin_frame(&ctx);
        let [d, m, y, c, dist] = [
            g.import_texture("test.depth", &depth_tex),
            g.import_texture("test.motion", &motion_tex),
            g.import_texture("test.raw_y", &y_tex),
            g.import_texture("test.raw_cocg_ao", &c_tex),
            g.import_texture("test.hit_distance", &dist_tex),
        ];
        let out = rtgi
            .record_accumulate(&mut g, &view, &params, d, m, y, c, dist)
            .unwrap();
        for t in [out.gi_y, out.gi_cocg, out.ao, out.history_length] {
            g.readback(t);
        }
        let mut r = g.execute().unwrap();
        let gy = r.take_image_of(out.gi_y).unwrap();
        let gc = r.take_image_of(out.gi_cocg).unwrap();
        let ga = r.take_image_of(out.ao).unwrap();
        let gl = r.take_image_of(out.history_length).unwrap();

        // The twin, its history stored in f16 like the textures.
        let prev = history.clone();
        let mut fresh = 0;
        let mut accumulated = 0;
        for yy in 0..h {
            for xx in 0..w {
                let i = (yy * w + xx) as usize;
                let input = AccumulateInput {
                    depth: depth[i],
                    motion: Vec3::new(motion[i][0], motion[i][1], motion[i][2]),
                    raw: reference::from_floats([
                        raw_y[i][0],
                        raw_y[i][1],
                        raw_y[i][2],
                        raw_y[i][3],
                        raw_c[i][0],
                        raw_c[i][1],
                    ]),
                    raw_ao: raw_c[i][2],
                };
                let look = |p: [u32; 2]| prev[(p[1] * w + p[0]) as usize];
                let a = accumulate_pixel(
                    [xx, yy],
                    [w, h],
                    &input,
                    worlds[i],
                    prev_vp,
                    &look,
                    history_valid && !reset,
                    settings.max_history as f32,
                    settings.depth_tolerance,
                    &firefly,
                );
                let unclamped = accumulate_pixel(
                    [xx, yy],
                    [w, h],
                    &input,
                    worlds[i],
                    prev_vp,
                    &look,
                    history_valid && !reset,
                    settings.max_history as f32,
                    settings.depth_tolerance,
                    &FireflyClamp::default(),
                );
                if unclamped.gi != a.gi {
                    clamped += 1;
                }
                let fl = reference::to_floats(&a.gi).map(f16);
                let a = Accumulated {
                    gi: reference::from_floats(fl),
                    ao: f16(a.ao),
                    length: f16(a.length),
                    view_depth: a.view_depth,
                };
                history[i] = a;
                match a.length {
                    1.0 => fresh += 1,
                    l if l > 1.0 => accumulated += 1,
                    _ => {}
                }
                let got = [
                    rgba(&gy)[i][0],
                    rgba(&gy)[i][1],
                    rgba(&gy)[i][2],
                    rgba(&gy)[i][3],
                    rgba(&gc)[i][0],
                    rgba(&gc)[i][1],
                    rgba(&ga)[i][0],
                    rgba(&gl)[i][0],
                ];
                let want = [fl[0], fl[1], fl[2], fl[3], fl[4], fl[5], a.ao, a.length];
                for (k, (g, e)) in got.iter().zip(want).enumerate() {
                    assert!(
                        g.is_finite(),
                        "frame {frame} pixel ({xx}, {yy}) value {k}: {g}"
                    );
                    assert!(
                        (g - e).abs() <= e.abs().max(1.0) * 2f32.powi(-10) * (frame + 1) as f32,
                        "frame {frame} pixel ({xx}, {yy}) value {k}: GPU {g}, twin {e}"
                    );
                }
            }
        }
        eprintln!(
            "frame {frame}: {fresh} fresh, {accumulated} accumulated, {clamped} clamped so far"
        );
        if frame == 0 || reset {
            assert_eq!(
                accumulated, 0,
                "frame {frame}: no history on the first frame or after a cut"
            );
        } else if frame == 1 {
            // Only the injected non-finite values (the wrong depths are stored now, and
            // rejected next frame).
            assert!(
                accumulated > 4000,
                "frame 1: history kept in {accumulated} pixels"
            );
        } else {
            assert!(
                accumulated > 3000,
                "frame {frame}: history kept in {accumulated} pixels"
            );
            // The wrong-depth block's inside, whose 3x3 is all wrong (its rim takes its
            // neighbours' history, the fallback): 6 x 5 pixels at least.
            assert!(
                fresh >= 30,
                "frame {frame}: rejected history in only {fresh} pixels"
            );
        }
        history_valid = true;
    }
    assert!(
        clamped > 200,
        "the firefly clamp acted in {clamped} pixels only"
    );
}

/// A floor open to a sky whose radiance depends on elevation only, L(μ) = mix(horizon,
/// zenith, √μ) (the placeholder sky): every ray misses, and the accumulated SH has analytic
/// means over the uniform hemisphere: c0 = C0 (Y_h + (Y_z − Y_h) · 2/3), the y coefficient
/// C1 (Y_h / 2 + (Y_z − Y_h) · 2/5), x and z 0, Co and Cg like c0 / C0. 16 frames of 4096
/// rays, each weight at most 16 with variance about 0.6: the image mean's standard error is
/// about 0.3 %; tolerances 1.5 % (c0, CoCg) and 3 % (y). AO is 1 and history grows to 16.
/// Then a camera cut and a resize each start the history again.
#[test]
fn open_floor_under_a_sky_accumulates_the_analytic_sh() {
    let scene = floor_scene();
    let s = rtgi_settings(&scene, 64, 64);
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let frames = 16;
    let mut last = None;
    for _ in 0..frames {
        last = Some(render(&mut renderer, &s));
    }
    let r = last.unwrap();
    let n = 64 * 64;
    assert_eq!(
        r.queue[0], n as u32,
        "every ray is left to the BVH (none hits the screen)"
    );
    let ycc = |c: Vec3| rgb_to_ycocg(c);
    let (zen, hor) = (ycc(PLACEHOLDER_SKY_ZENITH), ycc(PLACEHOLDER_SKY_HORIZON));
    let want_c0 = C0 as f32 * (hor.x + (zen.x - hor.x) * 2.0 / 3.0);
    let want_y1 = C1 as f32 * (hor.x / 2.0 + (zen.x - hor.x) * 2.0 / 5.0);
    let want_co = hor.y + (zen.y - hor.y) * 2.0 / 3.0;
    let want_cg = hor.z + (zen.z - hor.z) * 2.0 / 3.0;
    let mean = |img: &ImageRgba32, k: usize| {
        img.rgba.iter().map(|p| p[k] as f64).sum::<f64>() as f32 / n as f32
    };
    let (c0, y1, z1, x1) = (mean(&r.y, 0), mean(&r.y, 1), mean(&r.y, 2), mean(&r.y, 3));
    let (co, cg) = (mean(&r.cocg, 0), mean(&r.cocg, 1));
    eprintln!(
        "c0 {c0} ({want_c0}), y {y1} ({want_y1}), z {z1}, x {x1}, Co {co} ({want_co}), Cg {cg} ({want_cg})"
    );
    assert!(
        (c0 / want_c0 - 1.0).abs() < 0.015,
        "c0 {c0}, analytic {want_c0}"
    );
    assert!(
        (y1 / want_y1 - 1.0).abs() < 0.03,
        "y {y1}, analytic {want_y1}"
    );
    assert!(
        x1.abs() < 0.02 * want_c0 && z1.abs() < 0.02 * want_c0,
        "x {x1}, z {z1}"
    );
    assert!(
        (co - want_co).abs() < 0.015 * want_co.abs().max(0.1 * hor.x),
        "Co {co}, analytic {want_co}"
    );
    assert!(
        (cg - want_cg).abs() < 0.015 * want_cg.abs().max(0.1 * hor.x),
        "Cg {cg}, analytic {want_cg}"
    );
    for i in 0..n {
        assert_eq!(r.ao.rgba[i][0], 1.0);
        assert_eq!(r.distance.rgba[i][0], 0.0);
        assert_eq!(r.length.rgba[i][0], frames as f32);
    }
    // The diffuse resolve of the mean SH against the floor's normal is the sky's radiance
    // seen by a white Lambertian floor, to L1's accuracy: between the darkest and brightest
    // sky radiance.
    let sh = reference::from_floats([c0, y1, z1, x1, co, cg]);
    let lum = ShL1YCoCg::resolve_diffuse(&sh, Vec3::Y);
    let l = rgb_to_ycocg(lum).x;
    assert!(
        l > hor.x.min(zen.x) && l < hor.x.max(zen.x),
        "resolved {lum}"
    );

    renderer.cut_camera();
    let r = render(&mut renderer, &s);
    assert!(
        r.length.rgba.iter().all(|p| p[0] == 1.0),
        "a camera cut starts the history again"
    );
    let r = render(&mut renderer, &s);
    assert!(r.length.rgba.iter().all(|p| p[0] == 2.0));
    let s2 = rtgi_settings(&scene, 48, 40);
    let r = render(&mut renderer, &s2);
    assert!(
        r.length.rgba.iter().all(|p| p[0] == 1.0),
        "a resize starts the history again"
    );
}

/// The firefly clamp (`ray_traced_gi.firefly_clamp`): a still 16 x 16 plane takes one constant
/// sample S (c0 = 50) for 10 frames (history capped at 8), then a firefly F = 200 S at a few
/// pixels. Stated bound: a firefly moves a converged history's c0 by at most
/// ((k - 1) · h + floor) / L (k = 8, h = 50, floor = C0 · 1000 lux / π, L = 8: 55, where the
/// unclamped sample moves it by 1244), and the whole sample is scaled alike, so Y SH and CoCg
/// follow c0. Checked against the analytic value of S + (F · limit / c0(F) - S) / L and the CPU
/// twin; pixels without the firefly keep S; a pixel whose own samples were all 0 takes the
/// limit of its neighbours' scale (F · limit / c0(F) / L); a firefly while the history is 2
/// frames long (below `FIREFLY_MIN_HISTORY`) is not clamped; with `firefly_clamp = 0` the same
/// firefly breaks the bound (the control). Tolerance: f16 storage, 2^-9 · max(|v|, 1).
#[test]
fn a_firefly_in_a_converged_history_moves_it_by_at_most_the_clamp() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let rtgi = RayTracedGi::new(&ctx, &mut lib).unwrap();
    let (w, h) = (16u32, 16u32);
    let n = (w * h) as usize;
    let camera = Camera {
        position: Vec3::new(0.0, 3.0, 6.0),
        target: Vec3::ZERO,
        ..Camera::default()
    };
    let view = View::new(&camera, w, h);
    let inv_vp = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let prev_vp = Mat4::from_cols_array_2d(&view.prev_view_proj);
    let metered_lux = 1000.0;
    let s_y = [50.0f32, 10.0, -5.0, 3.0];
    let s_c = [4.0f32, -2.0];
    let firefly = 200.0f32;
    let late = [(3u32, 4u32), (9, 9), (12, 2)];
    let young = (6u32, 13u32);
    let dark = (13u32, 12u32);
    let close = |g: f32, e: f32| (g - e).abs() <= e.abs().max(1.0) * 2f32.powi(-9);
    for k in [8.0f32, 0.0] {
        let settings = RayTracedGiSettings {
            max_history: 8,
            firefly_clamp: k,
            ..RayTracedGiSettings::default()
        };
        let base = RtGiParams::new(&settings, 0, None, 0, metered_lux, 0.1, SkySource::None);
        let mut rt = GraphRuntime::new();
        let mut depth = vec![0f32; n];
        let mut motion = vec![[0f32; 4]; n];
        let mut worlds = vec![Vec3::ZERO; n];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                depth[i] = 0.02 + 0.001 * x as f32 + 0.0005 * y as f32;
                worlds[i] = reference::world_from_depth(inv_vp, [w, h], [x, y], depth[i]);
                let vz = (worlds[i] - camera.position).dot(camera.forward());
                motion[i] = [0.0, 0.0, f16(vz), 0.0];
            }
        }
        let depth_tex = texture(
            &ctx,
            wgpu::TextureFormat::R32Float,
            w,
            h,
            bytemuck::cast_slice(&depth),
        );
        let motion_tex = texture(
            &ctx,
            wgpu::TextureFormat::Rgba16Float,
            w,
            h,
            &halves(&motion),
        );
        let dist_tex = texture(&ctx, wgpu::TextureFormat::R16Float, w, h, &vec![0u8; n * 2]);
        for frame in 0..=10u32 {
            let mut raw_y = vec![s_y; n];
            let mut raw_c = vec![[s_c[0], s_c[1], 0.5, 0.0]; n];
            let mut hot: Vec<(u32, u32)> = Vec::new();
            if frame == 10 {
                hot.extend(late);
                hot.push(dark);
            } else {
                let i = (dark.1 * w + dark.0) as usize;
                raw_y[i] = [0.0; 4];
                raw_c[i] = [0.0, 0.0, 0.5, 0.0];
            }
            if frame == 2 {
                hot.push(young);
            }
            for &(x, y) in &hot {
                let i = (y * w + x) as usize;
                raw_y[i] = s_y.map(|v| v * firefly);
                raw_c[i][0] = s_c[0] * firefly;
                raw_c[i][1] = s_c[1] * firefly;
            }
            let y_tex = texture(
                &ctx,
                wgpu::TextureFormat::Rgba16Float,
                w,
                h,
                &halves(&raw_y),
            );
            let c_tex = texture(
                &ctx,
                wgpu::TextureFormat::Rgba16Float,
                w,
                h,
                &halves(&raw_c),
            );
            let mut params = base;
            params.config[0] = frame;
            let mut g = rt.begin_frame(&ctx);
            let [d, m, y, c, dist] = [
                g.import_texture("test.depth", &depth_tex),
                g.import_texture("test.motion", &motion_tex),
                g.import_texture("test.raw_y", &y_tex),
                g.import_texture("test.raw_cocg_ao", &c_tex),
                g.import_texture("test.hit_distance", &dist_tex),
            ];
            let out = rtgi
                .record_accumulate(&mut g, &view, &params, d, m, y, c, dist)
                .unwrap();
            for t in [out.gi_y, out.gi_cocg, out.history_length] {
                g.readback(t);
            }
            let mut r = g.execute().unwrap();
            let gy = r.take_image_of(out.gi_y).unwrap();
            let gc = r.take_image_of(out.gi_cocg).unwrap();
            let gl = r.take_image_of(out.history_length).unwrap();
            let got = |x: u32, y: u32| {
                let i = (y * w + x) as usize;
                let (a, b) = (rgba(&gy)[i], rgba(&gc)[i]);
                [a[0], a[1], a[2], a[3], b[0], b[1]]
            };
            let s6 = [s_y[0], s_y[1], s_y[2], s_y[3], s_c[0], s_c[1]];
            if frame == 2 {
                // History of 2 frames: the firefly enters unclamped at speed 1/3.
                let (x, y) = young;
                let want = s6.map(|v| v + (v * firefly - v) / 3.0);
                for (g, e) in got(x, y).into_iter().zip(want) {
                    assert!(close(g, e), "k {k}: young pixel got {g}, want {e}");
                }
            }
            if frame < 10 {
                continue;
            }
            let length = 8.0f32;
            // Analytic: the limit on c0 and the whole sample scaled to it.
            let limit = k * s_y[0] + C0 as f32 * metered_lux / std::f32::consts::PI;
            let scale = if k > 0.0 {
                (limit / (s_y[0] * firefly)).min(1.0)
            } else {
                1.0
            };
            let want = s6.map(|v| v + (v * firefly * scale - v) / length);
            let bound =
                ((k - 1.0) * s_y[0] + C0 as f32 * metered_lux / std::f32::consts::PI) / length;
            let clamp = FireflyClamp::new(k, metered_lux);
            let want_dark = s6.map(|v| v * firefly * scale / length);
            for &(x, y) in late.iter().chain([&dark]) {
                let i = (y * w + x) as usize;
                assert_eq!(rgba(&gl)[i][0], length);
                let g = got(x, y);
                let (want, s_hist) = if (x, y) == dark {
                    (want_dark, [0.0; 6])
                } else {
                    (want, s6)
                };
                // The twin, from a converged history of S at full length (0 at the dark
                // pixel).
                let history = |p: [u32; 2]| Accumulated {
                    gi: reference::from_floats(if (p[0], p[1]) == (x, y) { s_hist } else { s6 }),
                    ao: 0.5,
                    length,
                    view_depth: motion[(p[1] * w + p[0]) as usize][2],
                };
                let input = AccumulateInput {
                    depth: depth[i],
                    motion: Vec3::new(0.0, 0.0, motion[i][2]),
                    raw: reference::from_floats(s6.map(|v| v * firefly)),
                    raw_ao: 0.5,
                };
                let twin = accumulate_pixel(
                    [x, y],
                    [w, h],
                    &input,
                    worlds[i],
                    prev_vp,
                    &history,
                    true,
                    length,
                    settings.depth_tolerance,
                    &clamp,
                );
                let twin = reference::to_floats(&twin.gi);
                for c in 0..6 {
                    assert!(
                        close(g[c], want[c]) && close(twin[c], want[c]),
                        "k {k} pixel ({x}, {y}) value {c}: GPU {}, twin {}, analytic {}",
                        g[c],
                        twin[c],
                        want[c]
                    );
                }
                if (x, y) == dark {
                    continue;
                }
                let moved = g[0] - s_y[0];
                eprintln!("k {k}: the firefly moved c0 by {moved} (bound {bound})");
                if k > 0.0 {
                    assert!(moved <= bound * (1.0 + 2f32.powi(-9)), "{moved} > {bound}");
                } else {
                    assert!(
                        moved > 10.0 * (7.0 * s_y[0] + 100.0) / length,
                        "the control must break the bound: {moved}"
                    );
                }
            }
            for y in 0..h {
                for x in 0..w {
                    if late.contains(&(x, y)) || (x, y) == young || (x, y) == dark {
                        continue;
                    }
                    for (g, e) in got(x, y).into_iter().zip(s6) {
                        assert!(close(g, e), "k {k} pixel ({x}, {y}): {g} against S {e}");
                    }
                }
            }
        }
    }
}
