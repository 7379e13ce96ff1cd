//! Clouds: the twin's pieces against independent facts (the paraboloid mapping's round trip,
//! the sphere intersection, the noise's lattice values and range, a uniform slab's
//! transmittance in closed form), and `clouds.march` on the GPU against the twin.

use crate::common;

use glam::{Vec2, Vec3, Vec4};
use hikari_render::graph::GraphRuntime;
use hikari_render::shader;
use hikari_render::techniques::clouds::reference as twin;
use hikari_render::techniques::clouds::settings::CloudsSettings;
use hikari_render::techniques::clouds::{CLOUDS_ON, CloudParams, Clouds};
use hikari_render::techniques::gbuffer;
use hikari_scene::Sun;

fn sun() -> Sun {
    Sun {
        direction: Vec3::new(0.3, 0.6, -0.5).normalize(),
        illuminance_lux: 100_000.0,
        color: Vec3::ONE,
    }
}

#[test]
fn paraboloid_mapping_round_trips_over_the_hemisphere() {
    assert!((twin::cloud_map_dir(Vec2::splat(0.5)) - Vec3::Y).length() < 1e-6);
    for i in 0..200 {
        let a = i as f32 * 0.731;
        let elevation = (i as f32 / 200.0) * 1.5;
        let d = Vec3::new(
            elevation.cos() * a.cos(),
            elevation.sin(),
            elevation.cos() * a.sin(),
        );
        let uv = twin::cloud_map_uv(d);
        assert!((uv - 0.5).length() <= 0.5 + 1e-6, "{d} -> {uv}");
        let back = twin::cloud_map_dir(uv);
        assert!((back - d).length() < 1e-5, "{d} -> {uv} -> {back}");
    }
    // The horizon lies on the disc's edge.
    let uv = twin::cloud_map_uv(Vec3::X);
    assert!(((uv - 0.5).length() - 0.5).abs() < 1e-6);
}

#[test]
fn sphere_exit_lands_on_the_sphere() {
    let re = 6_360_000.0f32;
    for (alt, mu, h) in [
        (0.0, 1.0, 1500.0),
        (0.0, 0.01, 4000.0),
        (500.0, -0.2, 1500.0),
    ] {
        let r0 = re + alt;
        let t = twin::cloud_sphere_exit(r0, mu, re + h);
        assert!(t > 0.0);
        // In f64: the point t along the ray from (0, r0) at zenith cosine mu.
        let (r0, mu, t) = (f64::from(r0), f64::from(mu), f64::from(t));
        let x = t * (1.0 - mu * mu).sqrt();
        let y = r0 + t * mu;
        let r = (x * x + y * y).sqrt();
        assert!(
            (r - f64::from(re + h)).abs() < 2.0,
            "alt {alt} mu {mu}: r {r}"
        );
    }
    // Straight down through a smaller sphere: its far side; sideways past it: a miss.
    assert_eq!(twin::cloud_sphere_exit(10.0, -1.0, 5.0), 15.0);
    assert_eq!(twin::cloud_sphere_exit(10.0, 0.0, 5.0), -1.0);
}

#[test]
fn value_noise_is_the_hash_on_the_lattice_and_stays_in_range() {
    for c in [[0, 0, 0], [3, -7, 11], [-100, 5, 2]] {
        let p = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
        assert_eq!(twin::cloud_value_noise(p), twin::cloud_hash(c));
    }
    let mut lo = 1.0f32;
    let mut hi = 0.0f32;
    let mut mean = 0.0f64;
    let n = 20_000;
    for i in 0..n {
        let p = Vec3::new(
            i as f32 * 0.137,
            (i % 97) as f32 * 0.31,
            (i % 13) as f32 * 1.7,
        );
        let v = twin::cloud_value_noise(p);
        lo = lo.min(v);
        hi = hi.max(v);
        mean += f64::from(v);
    }
    mean /= n as f64;
    assert!(lo >= 0.0 && hi < 1.0, "{lo} {hi}");
    assert!((mean - 0.5).abs() < 0.03, "mean {mean}");
}

/// A layer whose every octave is faded by the density anti-aliasing (features far smaller than
/// a texel): uniform cover, so the zenith's transmittance is exp(-sigma * 0.7 * thickness), 0.7
/// being the integral of the height profile (a ramp over the lowest fifth, 1, a ramp over the
/// top 40 %).
fn uniform_slab(steps: u32) -> CloudParams {
    let s = CloudsSettings {
        coverage: 0.8,
        density: 2e-4,
        feature_m: 10.0,
        map_size: 15,
        steps,
        light_steps: 4,
        ..CloudsSettings::default()
    };
    CloudParams::new(&s, "clear", Some(&sun()), 0.0, true)
}

#[test]
fn a_uniform_slab_has_the_closed_form_transmittance_at_the_zenith() {
    let p = uniform_slab(500);
    let t = twin::march_texel(&p, 7, 7);
    let want = (-2e-4f32 * 0.7 * 2500.0).exp();
    assert!((t.z - want).abs() < 1e-3, "{} vs {want}", t.z);
    // No cover at all: clear sky.
    let mut clear = p;
    clear.shape[0] = 0.0;
    assert_eq!(
        twin::march_texel(&clear, 7, 7),
        Vec4::new(0.0, 0.0, 1.0, 1.0)
    );
}

#[test]
fn cloud_shadow_follows_coverage() {
    let s = CloudsSettings {
        coverage: 1.0,
        ..CloudsSettings::default()
    };
    let p = CloudParams::new(&s, "clear", Some(&sun()), 0.0, true);
    let shadow = twin::cloud_shadow_at(&p, Vec3::ZERO);
    // Full cover: the layer's optical depth is hundreds; the sun is blocked.
    assert!(shadow < 1e-3, "{shadow}");
    let mut none = p;
    none.shape[0] = 0.0;
    assert_eq!(twin::cloud_shadow_at(&none, Vec3::ZERO), 1.0);
    let off = CloudParams::new(&s, "clear", Some(&sun()), 0.0, false);
    assert_eq!(off.march[3] & CLOUDS_ON, 0);
    assert_eq!(twin::cloud_shadow_at(&off, Vec3::ZERO), 1.0);
}

fn gpu_map(ctx: &hikari_render::GpuContext, s: &CloudsSettings, p: CloudParams) -> Vec<Vec4> {
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let clouds = Clouds::new(ctx, &mut lib).unwrap();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(ctx);
    let f = clouds
        .record(&mut g, &mut Default::default(), s, p, Vec3::ZERO)
        .unwrap();
    g.readback(f.map);
    let r = g.execute().unwrap();
    r.image("clouds.map")
        .unwrap()
        .rgba
        .iter()
        .map(|v| Vec4::from_array(*v))
        .collect()
}

#[test]
fn gpu_march_matches_its_cpu_twin() {
    let ctx = common::gpu_context();
    let s = CloudsSettings {
        coverage: 0.6,
        feature_m: 3000.0,
        map_size: 32,
        steps: 24,
        light_steps: 4,
        ..CloudsSettings::default()
    };
    let p = CloudParams::new(&s, "clear", Some(&sun()), 0.0, true);
    let got = gpu_map(&ctx, &s, p);
    let want = twin::march_map(&p);
    let mut bad = 0;
    let mut cloudy = 0;
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(g.is_finite(), "texel {i}: {g}");
        if w.z < 0.99 {
            cloudy += 1;
        }
        // f16 storage, and exp / sqrt rounding: within 1 % or 2e-3.
        let err = ((*g - *w).abs() - w.abs() * 1e-2).max_element();
        if err > 2e-3 {
            bad += 1;
            if bad < 5 {
                eprintln!("texel {i}: gpu {g} twin {w}");
            }
        }
    }
    assert!(
        cloudy > 50,
        "the test map should hold clouds: {cloudy} texels"
    );
    // A sample at the edge of a cloud may fall either side of zero density on the two.
    assert!(
        bad <= got.len() / 100,
        "{bad} of {} texels differ",
        got.len()
    );
    // The zenith of a uniform slab on the GPU.
    let slab_s = CloudsSettings {
        coverage: 0.8,
        density: 2e-4,
        feature_m: 10.0,
        map_size: 15,
        steps: 500,
        light_steps: 4,
        ..CloudsSettings::default()
    };
    let slab = gpu_map(&ctx, &slab_s, uniform_slab(500));
    let want = (-2e-4f32 * 0.7 * 2500.0).exp();
    assert!(
        (slab[7 * 15 + 7].z - want).abs() < 2e-3,
        "{}",
        slab[7 * 15 + 7].z
    );
}

/// The deferred lighting's use of `hikari::clouds`: a frame with clouds against the same frame
/// without, through the twin. Sky pixels: `clouds_over_sky` of the clouds-off sky with the
/// frame's map and the sky's mean radiance from its SH. Sunlit ground: the sun's share scaled by
/// the twin's `cloud_shadow` (the illuminance minus what the frame without sun receives),
/// through a 2 x 2 shadow map whose bilinear lookup differs from the march at every such
/// pixel, so that a frame that marched instead, or looked the map up at the wrong place, fails.
#[test]
fn the_deferred_lighting_draws_and_shadows_with_the_clouds_as_the_twin() {
    use hikari_render::techniques::sky;
    use hikari_render::{FrameSettings, Renderer};
    let scene = hikari_scene::builtin::boxes();
    // Move the noise until the twin puts a cloud's edge over the boxes: a shadow that the
    // frame must match where it is partial.
    let sun0 = sky::lights::directional_light(&hikari_render::settings::SkySettings {
        time: "10:00".into(),
        ..Default::default()
    })
    .unwrap()
    .unwrap();
    let offset = (0..400)
        .map(|k| k as f32 * 37.0)
        .find(|&o| {
            let c = CloudsSettings {
                coverage: 0.45,
                feature_m: 1500.0,
                offset_x_m: o,
                ..CloudsSettings::default()
            };
            // The frame's clock: 10:00, the wind's offset included.
            let p = CloudParams::new(&c, "clear", Some(&sun0), 36_000.0, true);
            let t = twin::cloud_shadow_at(&p, Vec3::ZERO);
            t > 0.2 && t < 0.8
        })
        .expect("some offset puts a cloud's edge over the origin");
    let frame = |clouds: bool, sun_on: bool| -> FrameSettings {
        let mut s = common::small_frame_settings(&scene, 64, 48);
        s.settings.sky.enabled = true;
        s.settings.sky.table_quality = 0;
        s.settings.sky.time = "10:00".into();
        s.settings.area_lights.enabled = false;
        s.settings.haze.enabled = false;
        // Features small enough that the 64-px view holds cloud edges, and the boxes' shadow.
        s.settings.clouds = CloudsSettings {
            enabled: clouds,
            offset_x_m: offset,
            ..common::small_clouds(0.45, 1500.0)
        };
        // The coarsest shadow map (2 x 2 texels 2 km apart), so that its bilinear lookup
        // differs visibly from the march: the frame must take the map's value where the path
        // enters it.
        s.settings.clouds.shadow_map_size = 2;
        // The clear sky's SH in every frame, so that the frames without clouds or without the
        // sun differ from this one only by what is compared (tests/render/sky.rs holds the SH).
        s.settings.clouds.ambient = false;
        s.settings.direct_lighting.sun = sun_on;
        s.sun = hikari_render::SunSource::Sky;
        // Raise the view so that it holds the sky over the boxes and their ground.
        let f = (s.camera.target - s.camera.position).normalize();
        s.camera.target = s.camera.position + f + Vec3::new(0.0, 0.35, 0.0);
        s
    };
    let run = |s: &FrameSettings| {
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        let mut map = None;
        let mut r = renderer
            .render_reading(s, |o| {
                map = Some(o.clouds.map);
                vec![
                    o.lit.into(),
                    o.illuminance.into(),
                    o.gbuffer.depth.into(),
                    o.clouds.map.into(),
                    o.sky.sh.into(),
                ]
            })
            .unwrap();
        let sh = bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec();
        let img = |r: &mut hikari_render::graph::FrameResult, n: &str| r.take_image(n).unwrap();
        let lit = img(&mut r, "direct_lighting.radiance");
        let lux = img(&mut r, "direct_lighting.illuminance");
        let depth = img(&mut r, "gbuffer.depth");
        let map = r.take_image_of(map.unwrap()).unwrap();
        (lit, lux, depth, map, sh)
    };
    let on = frame(true, true);
    let (lit_on, lux_on, depth, map, sh) = run(&on);
    let (lit_off, lux_off, _, _, _) = run(&frame(false, true));
    let (_, lux_dark, _, _, _) = run(&frame(true, false));
    let sun = on.directional_light().unwrap().unwrap();
    let params = CloudParams::new(&on.settings.clouds, "clear", Some(&sun), 36_000.0, true)
        .with_shadow_map(
            on.settings.clouds.shadow_map_size,
            on.settings.clouds.shadow_map_extent_m,
            on.camera.position,
        );
    let shadow_map = twin::shadow_map(&params);
    let mut map_matters = 0;
    let map: Vec<Vec4> = map.rgba.iter().map(|v| Vec4::from_array(*v)).collect();
    // The sky's mean radiance: band 0 of the deringed SH times Y00.
    let mean = Vec3::from_slice(&sh[9][..3]) * 0.282_094_8;
    let view = hikari_render::view::View::new(&on.camera, 64, 48);
    let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);
    let (mut sky_px, mut clouded, mut ground, mut shaded) = (0, 0, 0, 0);
    for y in 0..48u32 {
        for x in 0..64u32 {
            let i = (y * 64 + x) as usize;
            let d = depth.rgba[i][0];
            if d == 0.0 {
                let dir = gbuffer::reference::pixel_ray(inv, on.camera.position, [x, y], [64, 48]);
                let back = Vec3::from_slice(&lit_off.rgba[i][..3]);
                let sun_lux = sun.color * sun.illuminance_lux;
                let want = twin::clouds_over_sky(&params, &map, dir, back, sun_lux, mean);
                let got = Vec3::from_slice(&lit_on.rgba[i][..3]);
                sky_px += 1;
                if (want - back).length() > 0.05 * back.length() {
                    clouded += 1;
                }
                let err = ((got - want).abs() / want.abs().max(Vec3::splat(1.0))).max_element();
                assert!(
                    err < 1e-2,
                    "sky pixel {x},{y}: {got} vs {want} (clear {back})"
                );
            } else {
                // The sun's share of the illuminance, with and without clouds.
                let sun_on = lux_off.rgba[i][0] - lux_dark.rgba[i][0];
                let sun_clouded = lux_on.rgba[i][0] - lux_dark.rgba[i][0];
                if sun_on > 1000.0 {
                    let world = gbuffer::reference::world_from_depth(inv, [x, y], [64, 48], d);
                    let t = twin::cloud_shadow(&params, &shadow_map, world);
                    map_matters +=
                        ((t - twin::cloud_shadow_at(&params, world)).abs() > 0.05) as u32;
                    let want = sun_on * t;
                    ground += 1;
                    if want < 0.9 * sun_on {
                        shaded += 1;
                    }
                    assert!(
                        (sun_clouded - want).abs() < 2e-2 * sun_on,
                        "ground pixel {x},{y}: sun share {sun_clouded} vs {want} of {sun_on}"
                    );
                }
            }
        }
    }
    eprintln!(
        "{sky_px} sky pixels ({clouded} clouded), {ground} sunlit ({shaded} under cloud, \
         {map_matters} where the map's lookup and the march differ by 0.05)"
    );
    assert!(
        map_matters > 20,
        "{map_matters}: the map's lookup cannot be told from the march"
    );
    assert!(
        clouded > 20 && sky_px - clouded > 20,
        "{clouded} of {sky_px} sky pixels clouded"
    );
    assert!(
        shaded > 20,
        "{shaded} of {ground} sunlit pixels under cloud"
    );
}

#[test]
fn the_wind_carries_the_clouds() {
    // 8 m/s towards the east (-X): after 10 minutes what lay at x lies 4800 m further east.
    let s = CloudsSettings {
        coverage: 0.7,
        wind_mps: 8.0,
        wind_towards_deg: 90.0,
        ..CloudsSettings::default()
    };
    let p0 = CloudParams::new(&s, "clear", Some(&sun()), 0.0, true);
    let p1 = CloudParams::new(&s, "clear", Some(&sun()), 600.0, true);
    let mut differs = 0;
    for i in 0..200 {
        let xz = Vec2::new(i as f32 * 97.0 - 9000.0, (i % 17) as f32 * 311.0);
        let h = 1500.0 + (i % 23) as f32 * 100.0;
        let before = twin::cloud_density(&p0, xz, h, 1.0);
        let after = twin::cloud_density(&p1, xz + Vec2::new(-4800.0, 0.0), h, 1.0);
        assert!(
            (before - after).abs() < 1e-3 * s.density,
            "{xz}: {before} then {after}"
        );
        if (twin::cloud_density(&p1, xz, h, 1.0) - before).abs() > 1e-3 {
            differs += 1;
        }
    }
    assert!(differs > 20, "the clouds moved: {differs} points changed");
}

/// The shadow map: on the GPU against the twin's `cloud_shadow_at` at each texel's centre on
/// the layer's base (a 32² map over 8 km, small features); its lookup against the march at
/// points below the layer, at the default 8 m texels: within 2e-3 where the path enters the
/// map (bilinear between exact texel centres), the march itself outside it or above the base.
/// The map lies where the camera's path to the sun enters the layer, snapped to whole texels.
#[test]
fn shadow_map_and_its_lookup_agree_with_the_march() {
    let s = CloudsSettings {
        coverage: 0.6,
        feature_m: 3000.0,
        map_size: 16,
        shadow_map_size: 32,
        shadow_map_extent_m: 8000.0,
        ..CloudsSettings::default()
    };
    let camera = Vec3::new(120.0, 30.0, -40.0);
    let p = CloudParams::new(&s, "clear", Some(&sun()), 0.0, true).with_shadow_map(
        s.shadow_map_size,
        s.shadow_map_extent_m,
        camera,
    );
    let texel = p.shadow[2];
    assert_eq!((texel, p.shadow[3]), (250.0, 32.0));
    let entry = hikari_render::techniques::clouds::shadow_entry(&p, camera).unwrap();
    let centre = Vec2::new(p.shadow[0], p.shadow[1]) + 4000.0;
    assert!(
        (centre - entry).abs().max_element() <= 0.5 * texel,
        "{centre} {entry}"
    );
    assert_eq!(p.shadow[0] % texel, 0.0, "snapped to whole texels");
    let want = twin::shadow_map(&p);
    assert!(
        want.iter().any(|&t| t < 0.5) && want.iter().any(|&t| t > 0.9),
        "the map holds clouds and gaps"
    );

    {
        let ctx = common::gpu_context();
        let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
        let clouds = Clouds::new(&ctx, &mut lib).unwrap();
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(&ctx);
        let f = clouds
            .record(&mut g, &mut Default::default(), &s, p, camera)
            .unwrap();
        assert_eq!(f.params.shadow, p.shadow);
        g.readback(f.shadow_map);
        let r = g.execute().unwrap();
        let got = &r.image("clouds.shadow_map").unwrap().rgba;
        assert_eq!(got.len(), want.len());
        let off = got
            .iter()
            .zip(&want)
            .filter(|(g, w)| (g[0] - **w).abs() > 0.01 * w.max(0.01))
            .count();
        assert!(
            off <= want.len() / 100,
            "{off} of {} texels off",
            want.len()
        );
    }

    // The lookup at the default resolution, against the march.
    let d = CloudsSettings {
        coverage: 0.6,
        feature_m: 3000.0,
        ..CloudsSettings::default()
    };
    let p = CloudParams::new(&d, "clear", Some(&sun()), 0.0, true).with_shadow_map(
        d.shadow_map_size,
        d.shadow_map_extent_m,
        Vec3::ZERO,
    );
    let map = twin::shadow_map(&p);
    let mut rng = 0x2545_f491_u32;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        rng as f32 / u32::MAX as f32
    };
    let (mut inside, mut worst) = (0, 0.0f32);
    for _ in 0..400 {
        let pos = Vec3::new(
            (next() - 0.5) * 3000.0,
            next() * 200.0,
            (next() - 0.5) * 3000.0,
        );
        let marched = twin::cloud_shadow_at(&p, pos);
        let looked_up = twin::cloud_shadow(&p, &map, pos);
        worst = worst.max((looked_up - marched).abs());
        inside += 1;
    }
    eprintln!("the map's lookup against the march: {worst} at worst");
    assert!(worst < 2e-3, "the map's lookup is {worst} off the march");
    assert_eq!(inside, 400);
    // Outside the map, and above the base: the march.
    for pos in [
        Vec3::new(1.0e5, 10.0, 0.0),
        Vec3::new(0.0, d.bottom_m + 10.0, 0.0),
    ] {
        assert_eq!(
            twin::cloud_shadow(&p, &map, pos),
            twin::cloud_shadow_at(&p, pos)
        );
    }
}

/// What a frame redraws of the paraboloid map: nothing for the parameters it was drawn with (a
/// still view), a share of its rows while only the clock moves it (as few shares as keep every
/// row within 5 % of a feature's drift and a quarter degree of the sun's turn), the whole map
/// for anything else or a clock that jumps.
#[test]
fn the_map_is_redrawn_only_as_much_as_it_changed() {
    use hikari_render::techniques::clouds::{Redraw, redraw};
    let s = CloudsSettings::default();
    let at = |seconds: f64, sun_dir: Vec3| {
        let sun = Sun {
            direction: sun_dir.normalize(),
            ..sun()
        };
        CloudParams::new(&s, "clear", Some(&sun), seconds, true)
    };
    let d0 = sun().direction;
    let p = at(36_000.0, d0);
    let r = |last: &CloudParams, now: &CloudParams| redraw(Some(&p), Some(last), now, 60);
    assert_eq!(redraw(None, None, &p, 60), Redraw::Whole);
    assert_eq!(r(&p, &p), Redraw::Nothing);
    let mut sliced = p;
    sliced.slice = [60, 7, 0, 0];
    sliced.shadow = [1.0, 2.0, 8.0, 512.0];
    assert_eq!(r(&p, &sliced), Redraw::Nothing);
    // The wind at 8 m/s over 6 km features: a second of clock a frame drifts 8 / 6000 of a
    // feature, so 37 frames stay within 5 % (37.5); six seconds a frame (the viewer's
    // default play rate at 60 frames a second) 6 slices; a minute a frame is a jump.
    assert_eq!(r(&p, &at(36_001.0, d0)), Redraw::Slice { slices: 37 });
    assert_eq!(r(&p, &at(36_006.0, d0)), Redraw::Slice { slices: 6 });
    assert_eq!(r(&p, &at(36_060.0, d0)), Redraw::Whole);
    // The step is the frame's, not the drift since the map was drawn whole.
    assert_eq!(
        r(&at(36_300.0, d0), &at(36_301.0, d0)),
        Redraw::Slice { slices: 37 }
    );
    // At most `time_slices`, and a still clock whose rows were drawn in slices all along.
    assert_eq!(
        redraw(Some(&p), Some(&at(36_001.0, d0)), &at(36_001.0, d0), 60),
        Redraw::Slice { slices: 60 }
    );
    // The sun turned by exactly `deg` (about an axis square to it): 0.1° a frame fits two
    // frames in a quarter degree.
    let axis = d0.normalize().any_orthonormal_vector();
    let turn = |deg: f32| glam::Quat::from_axis_angle(axis, deg.to_radians()) * d0;
    assert_eq!(r(&p, &at(36_000.0, turn(0.1))), Redraw::Slice { slices: 2 });
    assert_eq!(r(&p, &at(36_000.0, turn(1.0))), Redraw::Whole);
    let thicker = CloudParams::new(
        &CloudsSettings {
            coverage: 0.5,
            ..s.clone()
        },
        "clear",
        Some(&sun()),
        36_000.0,
        true,
    );
    assert_eq!(r(&p, &thicker), Redraw::Whole);
    assert_eq!(
        r(&thicker, &thicker),
        Redraw::Whole,
        "unlike what every row holds"
    );
}

#[test]
fn a_sliced_march_draws_every_row_within_its_slices_and_fills_the_gpu() {
    use hikari_render::techniques::clouds::{MIN_MARCH_THREADS, march_rows};
    for size in [64u32, 256, 768, 1024] {
        for n in [1u32, 2, 3, 6, 7, 16, 60] {
            for start in [0u64, 5, 123] {
                let mut drawn = vec![false; size as usize];
                for f in start..start + u64::from(n) {
                    let Some([every, first]) = march_rows(size, n, f) else {
                        continue;
                    };
                    assert!(
                        every >= 1 && first < every,
                        "{size} {n} {f}: [{every}, {first}]"
                    );
                    let threads = size * size.div_ceil(every);
                    let floor = MIN_MARCH_THREADS.min(size * size.div_ceil(n.max(1)) * n) as f32;
                    assert!(
                        threads as f32 >= 0.9 * floor.min((size * size) as f32 / 2.0),
                        "{size} {n}: a dispatch of {threads} threads"
                    );
                    for r in (first..size).step_by(every as usize) {
                        drawn[r as usize] = true;
                    }
                }
                assert!(
                    drawn.iter().all(|&d| d),
                    "{size} texels, {n} slices from frame {start}: rows left undrawn"
                );
            }
        }
    }
    // The village's map on a playing clock (6 slices of 128 rows): half the map every third
    // frame rather than a sixth every frame.
    assert_eq!(march_rows(768, 6, 0), Some([2, 0]));
    assert_eq!(march_rows(768, 6, 1), None);
    assert_eq!(march_rows(768, 6, 3), Some([2, 1]));
}

#[test]
fn the_map_is_as_fine_as_the_view_needs() {
    use hikari_render::techniques::clouds::map_size_for;
    let s = CloudsSettings::default();
    // 4 h / fov: a texel a pixel at the zenith, where the paraboloid has a quarter of the
    // map's texels a radian.
    assert_eq!(map_size_for(&s, 36, 60.0), 144);
    assert_eq!(map_size_for(&s, 144, 60.0), 560);
    // Large views take the setting, the most it allows.
    assert_eq!(map_size_for(&s, 720, 60.0), s.map_size);
    assert_eq!(map_size_for(&s, 1440, 60.0), s.map_size);
    // A telephoto view needs more texels than a wide one of the same height.
    assert!(map_size_for(&s, 72, 20.0) > map_size_for(&s, 72, 90.0));
    for h in [1u32, 7, 100, 333] {
        let n = map_size_for(&s, h, 50.0);
        assert!(
            n.is_multiple_of(16) && (16..=s.map_size).contains(&n),
            "{h}: {n}"
        );
    }
}
