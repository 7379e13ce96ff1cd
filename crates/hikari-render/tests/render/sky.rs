//! The sky on the GPU against its CPU twin (`sky::reference`, built on hikari-atmosphere's own
//! table mapping and sampling and on hikari-math's SH projection and deringing): the sky's
//! pixels, its L2 SH, and the deringed SH's non-negativity. Small tables (quality 0) and a
//! 96x64 frame keep the CPU driver fast.

use crate::common;

use glam::Vec3;

use hikari_math::sh::dering::{dering, dering_window, find_minimum};
use hikari_math::sh::{Sh, ShL2Rgb, basis, zonal};
use hikari_render::Renderer;
use hikari_render::checks::math_check::{Kernel, MathCheck};
use hikari_render::graph::GraphRuntime;
use hikari_render::pipeline::ComputePipeline;
use hikari_render::shader;
use hikari_render::techniques::gbuffer;
use hikari_render::techniques::sky::{self, SkyParams, reference::SkyTwin};
use hikari_render::wgpu::{self, util::DeviceExt};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

fn frame(time: &str, w: u32, h: u32) -> (hikari_scene::Scene, hikari_render::FrameSettings) {
    let scene = hikari_scene::builtin::by_name("boxes").unwrap();
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.sky.enabled = true;
    s.settings.sky.table_quality = 0;
    s.settings.sky.time = time.into();
    s.sun = hikari_render::SunSource::Sky;
    // Look up and across, so most of the image is sky.
    let c = &mut s.camera;
    c.target = c.position + Vec3::new(0.3, 0.35, 1.0).normalize();
    c.up = Vec3::Y;
    (scene, s)
}

struct Rendered {
    params: SkyParams,
    depth: hikari_render::graph::ImageRgba32,
    hdr: hikari_render::graph::ImageRgba32,
    sh: Vec<[f32; 4]>,
}

fn render(scene: &hikari_scene::Scene, s: &hikari_render::FrameSettings) -> Rendered {
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let mut params = None;
    let mut r = renderer
        .render_reading(s, |o| {
            params = Some(o.sky.params);
            vec![o.gbuffer.depth.into(), o.lit.into(), o.sky.sh.into()]
        })
        .unwrap();
    let sh = bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec();
    Rendered {
        params: params.unwrap(),
        depth: r.take_image("gbuffer.depth").unwrap(),
        hdr: r.take_image("direct_lighting.radiance").unwrap(),
        sh,
    }
}

fn sh_of(v: &[[f32; 4]]) -> Sh<Vec3, 9> {
    let mut sh = Sh::<Vec3, 9>::zero();
    for (c, x) in sh.coeffs.iter_mut().zip(v) {
        *c = Vec3::new(x[0], x[1], x[2]);
    }
    sh
}

#[test]
fn sky_pixels_and_sky_sh_match_the_cpu_twin_morning_and_night() {
    // 09:00: the sun up in the east; 23:30: the full moon lights the sky.
    for time in ["09:00", "23:30"] {
        let (scene, s) = frame(time, 96, 64);
        let got = render(&scene, &s);
        let weather = s.settings.sky.weather().unwrap();
        let atmosphere =
            sky::atmosphere_for(&weather.atmosphere(), s.settings.sky.table_sizes()).unwrap();
        let l = s.context().unwrap().sky.unwrap().lights;
        let want_params = SkyParams::new(&atmosphere, &l, &s.settings.sky, got.params.shell[3]);
        assert_eq!(
            got.params, want_params,
            "{time}: the frame's sky parameters"
        );
        let twin = SkyTwin::new(&atmosphere, got.params);

        // Sky pixels: radiance along each pixel's ray, away from the disks.
        let (w, h) = (s.width, s.height);
        let view = hikari_render::view::View::new(&s.camera, w, h);
        let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);
        let (mut n, mut worst) = (0, 0f32);
        for y in 0..h {
            for x in 0..w {
                if got.depth.pixel(x, y)[0] > 0.0 {
                    continue;
                }
                let dir = gbuffer::reference::pixel_ray(inv, s.camera.position, [x, y], [w, h]);
                let near_disk = [got.params.sun, got.params.moon]
                    .iter()
                    .any(|b| dir.dot(Vec3::new(b[0], b[1], b[2])) > 0.999);
                if near_disk {
                    continue;
                }
                let want = twin.background_no_disks(dir);
                let px = got.hdr.pixel(x, y);
                for c in 0..3 {
                    // f16 output (2^-11 relative); f32 against f64 table arithmetic.
                    let tol = want[c].abs() * 5e-3 + want.max_element() * 1e-3 + 1e-6;
                    worst = worst.max((px[c] - want[c]).abs() / tol);
                }
                n += 1;
            }
        }
        assert!(n > 1000, "{time}: {n} sky pixels");
        assert!(
            worst <= 1.0,
            "{time}: worst sky pixel {worst} of the tolerance"
        );

        // SH: raw and deringed, against the twin's projection and deringing.
        let (raw, deringed) = twin.sh();
        let scale = raw.coeffs[0].max_element();
        assert!(scale > 0.0, "{time}: a lit sky");
        for (name, gpu, cpu) in [
            ("raw", sh_of(&got.sh[..9]), raw),
            ("deringed", sh_of(&got.sh[9..]), deringed),
        ] {
            for k in 0..9 {
                let d = (gpu.coeffs[k] - cpu.coeffs[k]).abs().max_element();
                // Summation order over 4096 samples in f32 against f64.
                assert!(
                    d <= scale * 2e-3,
                    "{time}: {name} coefficient {k}: GPU {} CPU {}",
                    gpu.coeffs[k],
                    cpu.coeffs[k]
                );
            }
        }
        // The deringed SH is non-negative over a dense sphere (20000 directions).
        let gpu = sh_of(&got.sh[9..]);
        for i in 0..20_000 {
            let d = sky::reference::fibonacci_dir(i, 20_000);
            let v = gpu.eval(d);
            assert!(
                v.min_element() >= -scale * 1e-3,
                "{time}: deringed SH {v} at {d}"
            );
        }
    }
}

/// PSNR of `ours` against `reference` (RGB, peak = the reference's largest channel), as
/// hikari-atmosphere's `tests/reference.rs` scores the model.
fn psnr(ours: &[Vec3], reference: &[Vec3]) -> f64 {
    let peak = f64::from(
        reference
            .iter()
            .map(|c| c.max_element())
            .fold(0.0, f32::max),
    );
    let mse = ours
        .iter()
        .zip(reference)
        .map(|(a, b)| (*a - *b).as_dvec3().length_squared())
        .sum::<f64>()
        / (3 * ours.len()) as f64;
    10.0 * (peak * peak / mse).log10()
}

/// The frame's sky against hikari-atmosphere's CPU model (`Atmosphere::sky_radiance`, which
/// applies the Earth's shadow and the azimuth terms) at sunset and in twilight, looking towards
/// and away from the sun, and against what the lookup gave before it applied those terms (the
/// 2D tables of all orders resampled at the sun's angle and multiplied by the phases: the
/// previous `sky_inscatter`, computed here on the CPU as its twin did). The frame's
/// departures from the model that remain are the cubic (not linear) filtering of the multiple
/// scattering along the sun's angle, f32 arithmetic and the f16 output.
#[test]
fn the_frames_twilight_sky_follows_the_cpu_model() {
    let ctx = common::gpu_context();
    let (scene, mut s) = frame("12:00", 96, 64);
    // Quality 0 (small tables) by default; HIKARI_SKY_TEST_QUALITY=2 for the full sizes (slow).
    s.settings.sky.table_quality = std::env::var("HIKARI_SKY_TEST_QUALITY")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let weather = s.settings.sky.weather().unwrap();
    let atmosphere =
        sky::atmosphere_for(&weather.atmosphere(), s.settings.sky.table_sizes()).unwrap();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut report = Vec::new();
    for zenith_deg in [85.0f32, 90.0, 95.0] {
        // A scene's own sun (not the ephemeris's), which the sky follows; the moon goes.
        let z = zenith_deg.to_radians();
        let sun_dir = Vec3::new(0.3 * z.sin(), z.cos(), z.sin()).normalize();
        s.sun = hikari_render::SunSource::Fixed(hikari_scene::Sun {
            direction: sun_dir,
            illuminance_lux: 1000.0,
            color: Vec3::ONE,
        });
        let (mut frame_px, mut model, mut before) = (Vec::new(), Vec::new(), Vec::new());
        let (mut twin_px, mut linear_px) = (Vec::new(), Vec::new());
        for look in [Vec3::new(0.25, 0.35, 1.0), Vec3::new(-0.25, 0.35, -1.0)] {
            let c = &mut s.camera;
            c.target = c.position + look.normalize();
            c.up = Vec3::Y;
            let mut params = None;
            let mut r = renderer
                .render_reading(&s, |o| {
                    params = Some(o.sky.params);
                    vec![o.gbuffer.depth.into(), o.lit.into()]
                })
                .unwrap();
            let params = params.unwrap();
            let depth = r.take_image("gbuffer.depth").unwrap();
            let hdr = r.take_image("direct_lighting.radiance").unwrap();
            assert_eq!(params.moon[3], 0.0, "the scene's sun replaces the moon");
            let lux = params.sun[3];
            let brightness = params.light_coords[2];
            let sun = Vec3::new(params.sun[0], params.sun[1], params.sun[2]);
            assert!(
                (sun - sun_dir).length() < 1e-5,
                "the sky follows the scene's sun"
            );
            assert!(lux > 0.0 && brightness > 0.0);
            let altitude = params.shell[3];
            let twin = SkyTwin::new(&atmosphere, params);
            let linear = twin_with_linear_multiple(&atmosphere, params);

            // The lookup before the azimuth terms, for the comparison.
            let t = &atmosphere.tables;
            let old = [
                sky::reference::resample(&t.rayleigh, None, params.light_coords[0]),
                sky::reference::resample(&t.mie, None, params.light_coords[0]),
            ];
            let p = &atmosphere.params;
            let shell =
                hikari_atmosphere::geometry::Shell::new(p.bottom_radius_km, p.top_radius_km);
            let r_cam = p.bottom_radius_km + f64::from(altitude);
            let white = atmosphere.to_working(Vec3::ONE);

            let (w, h) = (s.width, s.height);
            let view = hikari_render::view::View::new(&s.camera, w, h);
            let inv = glam::Mat4::from_cols_array_2d(&view.inv_view_proj);
            for y in 0..h {
                for x in 0..w {
                    if depth.pixel(x, y)[0] > 0.0 {
                        continue;
                    }
                    let dir = gbuffer::reference::pixel_ray(inv, s.camera.position, [x, y], [w, h]);
                    // Above the horizon (the model has no ground) and away from the sun's disk.
                    if dir.y < 0.01 || dir.dot(sun) > 0.999 {
                        continue;
                    }
                    let px = hdr.pixel(x, y);
                    frame_px.push(Vec3::new(px[0], px[1], px[2]) / brightness);
                    twin_px.push(twin.inscatter(dir) / brightness);
                    linear_px.push(linear.inscatter(dir) / brightness);
                    model.push(atmosphere.sky_radiance(altitude, dir, sun, Vec3::splat(lux)));
                    let d = dir.as_dvec3().normalize();
                    let mu = d.y;
                    let sizes = t.sizes.scattering;
                    let (u_mu, _, u_r) =
                        shell.scattering_uvw(r_cam, mu, 0.0, shell.hits_ground(r_cam, mu), sizes);
                    let nu = d.dot(sun.as_dvec3());
                    let (ray, mie) = (old[0].sample(u_mu, u_r, 0.5), old[1].sample(u_mu, u_r, 0.5));
                    let (pr, pm) = (
                        hikari_atmosphere::phase::rayleigh(nu),
                        hikari_atmosphere::phase::cornette_shanks(nu, p.mie_g),
                    );
                    let working: [f64; 3] = std::array::from_fn(|c| {
                        (ray[c] * pr + mie[c] * pm) * white[c] * f64::from(lux)
                    });
                    before.push(atmosphere.to_rec709(working).max(Vec3::ZERO));
                }
            }
        }
        assert!(
            frame_px.len() > 2000,
            "{zenith_deg}°: {} sky pixels",
            frame_px.len()
        );
        let (now, was) = (psnr(&frame_px, &model), psnr(&before, &model));
        let twin_vs_frame = psnr(&frame_px, &twin_px);
        let exact = psnr(&linear_px, &model);
        println!(
            "sun at {zenith_deg}°: frame vs CPU model {now:.1} dB (before the azimuth terms \
             {was:.1} dB); frame vs twin {twin_vs_frame:.1} dB; twin with linear multiple \
             scattering vs model {exact:.1} dB; {} pixels",
            frame_px.len()
        );
        report.push((zenith_deg, now, was, twin_vs_frame, exact));
    }
    for (zenith_deg, now, was, twin_vs_frame, exact) in report {
        // The terms as the model applies them: with the model's linear filter along the sun's
        // angle the twin is the model to rounding.
        assert!(
            exact >= 100.0,
            "{zenith_deg}°: linear twin vs model {exact:.1} dB"
        );
        // GPU-built tables, f32 and f16 against the CPU build (`gpu_tables_match_the_cpu_model`
        // allows 5e-3 per texel: about 46 dB).
        assert!(
            twin_vs_frame >= 45.0,
            "{zenith_deg}°: frame vs twin {twin_vs_frame:.1} dB"
        );
        // The 40 dB for sky images where the cubic filter of the multiple scattering
        // agrees with the linear one; in deep twilight (95°: the multiple scattering is most of
        // the sky and falls steeply with the sun's angle across the few texels of the test's
        // small tables) the cubic departs from the model's linear filter by more.
        let floor = if zenith_deg < 92.0 { 40.0 } else { 30.0 };
        assert!(now >= floor, "{zenith_deg}°: frame vs model {now:.1} dB");
        // The terms were worth 16 dB at 90° and 18 dB at 95° against the reference
        // (docs/atmosphere.md); at 85° they matter less.
        let gain = if zenith_deg < 88.0 { 1.0 } else { 10.0 };
        assert!(
            now >= was + gain,
            "{zenith_deg}°: {now:.1} dB, not {gain} dB better than before ({was:.1} dB)"
        );
    }
}

/// The twin with the model's filter for the multiple scattering: trilinear in the 3D table
/// (`rayleigh − rayleigh_single`) at the sun's angle instead of the pass's cubic resample.
fn twin_with_linear_multiple(
    atmosphere: &hikari_atmosphere::Atmosphere,
    params: SkyParams,
) -> SkyTwin<'_> {
    use hikari_atmosphere::table::Table;
    let t = &atmosphere.tables;
    let [nmu, nmus, nr] = t.rayleigh.size;
    let multiple = Table {
        size: t.rayleigh.size,
        data: (t.rayleigh.data.iter().zip(&t.rayleigh_single.data))
            .map(|(a, b)| std::array::from_fn(|c| a[c] - b[c]))
            .collect(),
    };
    let at = |coord: f32| {
        let v = (f64::from(coord) + 0.5) / nmus as f64;
        let mut data = Vec::with_capacity(nmu * nr);
        for r in 0..nr {
            for m in 0..nmu {
                let (u, w) = ((m as f64 + 0.5) / nmu as f64, (r as f64 + 0.5) / nr as f64);
                data.push(multiple.sample(u, v, w).map(|x| x as f32));
            }
        }
        Table {
            size: [nmu, nr, 1],
            data,
        }
    };
    let mut twin = SkyTwin::new(atmosphere, params);
    twin.layers = [at(params.light_coords[0]), at(params.light_coords[1])];
    twin
}

#[test]
fn a_disabled_sky_leaves_the_placeholders_and_a_zero_sh() {
    let (scene, mut s) = frame("12:00", 32, 24);
    s.settings.sky.enabled = false;
    let got = render(&scene, &s);
    assert!(got.sh.iter().all(|c| *c == [0.0; 4]));
    assert_eq!(got.params, <SkyParams as bytemuck::Zeroable>::zeroed());
}

/// Random unit vector (rejection sampling in the unit ball).
fn unit(rng: &mut SmallRng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length_squared();
        if l > 1e-3 && l <= 1.0 {
            return v.normalize();
        }
    }
}

/// Skies for the deringing: random coefficients (ringing of any shape), projected delta lights
/// on a weak ambient (the strongest ringing), smooth lobes that need no windowing, and a few
/// with a negative mean in one channel (zeroed).
fn dering_skies(rng: &mut SmallRng, n: usize) -> Vec<ShL2Rgb> {
    (0..n)
        .map(|i| {
            let scale = 10f32.powf(rng.random_range(-2.0..2.0));
            match i % 8 {
                0..3 => {
                    let amp = rng.random_range(0.05..1.2);
                    let mut c: [Vec3; 9] = std::array::from_fn(|_| {
                        Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ) * amp
                    });
                    c[0] = Vec3::new(
                        rng.random_range(0.2..2.0),
                        rng.random_range(0.2..2.0),
                        rng.random_range(0.2..2.0),
                    );
                    ShL2Rgb::new(c).scale(scale)
                }
                3..5 => {
                    let colour = Vec3::new(
                        rng.random_range(0.1..1.0),
                        rng.random_range(0.1..1.0),
                        rng.random_range(0.1..1.0),
                    );
                    let mut f = ShL2Rgb::delta(unit(rng), colour * scale);
                    let ambient = rng.random_range(0.0..0.5) * f.coeffs[0];
                    f.coeffs[0] += ambient;
                    f
                }
                5 | 6 => {
                    let b = rng.random_range(0.2..0.9);
                    let mut f = zonal::irradiance(&ShL2Rgb::delta(unit(rng), Vec3::splat(b)));
                    f.coeffs[0] += Vec3::splat((1.0 / basis::C0) as f32);
                    f.scale(scale)
                }
                _ => {
                    let mut f = ShL2Rgb::new(std::array::from_fn(|_| {
                        Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ) * scale
                    }));
                    f.coeffs[0] = Vec3::new(-rng.random_range(0.01..1.0), 0.5, 0.5) * scale;
                    f
                }
            }
        })
        .collect()
}

/// Runs the sky SH pass's `finish` on 64 partial sums (vec4 each, 9 per partial) and returns
/// its 18 coefficients (raw, then deringed).
fn run_finish(
    ctx: &hikari_render::GpuContext,
    pipeline: &ComputePipeline,
    partials: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.sky.sh_partials"),
            contents: bytemuck::cast_slice(partials),
            usage: wgpu::BufferUsages::STORAGE,
        });
    // The module's sky binding set, which `finish` does not read: 1-texel placeholders.
    let texture = |name: &str, layers: u32, dimension: wgpu::TextureDimension| {
        ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some(name),
                size: wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &vec![0u8; 16 * layers as usize],
        )
    };
    use wgpu::TextureDimension::{D2, D3};
    let resampled = texture("sky.resampled", sky::RESAMPLED_LAYERS, D2);
    let transmittance = texture("sky.transmittance", 1, D2);
    let (single, mie) = (
        texture("sky.rayleigh_single", 1, D3),
        texture("sky.mie", 1, D3),
    );
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(ctx);
    let resampled = g.import_texture("sky.resampled", &resampled);
    let transmittance = g.import_texture("sky.transmittance", &transmittance);
    let single = g.import_texture("sky.rayleigh_single", &single);
    let mie = g.import_texture("sky.mie", &mie);
    let lookup = g
        .binding_set("sky")
        .constants(&<SkyParams as bytemuck::Zeroable>::zeroed())
        .read(resampled)
        .read(transmittance)
        .read(single)
        .read(mie)
        .finish();
    let p = g.import_buffer("sky.sh_partials", &buffer);
    let sh = g.buffer("sky.sh", 18 * 16).unwrap();
    // The module's workgroup count of `project_dering`, which `finish` does not use.
    let done = g.buffer("sky.sh_done", 4).unwrap();
    // The clouds' binding set, which the module imports for its CLOUDS variant.
    let clouds = hikari_render::techniques::clouds::disabled_lookup(&mut g).unwrap();
    g.pass("sky.sh")
        .write(p)
        .write(sh)
        .write(done)
        .set(lookup)
        .set(clouds)
        .dispatch(pipeline, [1, 1, 1])
        .unwrap();
    g.readback(sh);
    let r = g.execute().unwrap();
    bytemuck::pod_collect_to_vec(r.buffer("sky.sh").unwrap())
}

/// The sky pass's parallel deringing (`finish`: all strengths of the search grid at once) on
/// ringing, smooth and negative-mean skies, against hikari_math::sh::dering of the raw
/// coefficients the pass wrote, and against the one-thread `sh_dering_l2_rgb` it replaces.
/// The partial sums are random shares of the sky, so the reduction is checked too.
#[test]
fn the_sky_pass_derings_as_hikari_math_does() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let pipeline = ComputePipeline::new(&ctx, &mut lib, "sky/sh.wgsl", "finish", &[]).unwrap();
    let serial = MathCheck::new(&ctx, &mut lib, Kernel::ShDering).unwrap();
    let mut rng = SmallRng::seed_from_u64(0x5C7_DE41);
    let skies = dering_skies(&mut rng, 160);
    // The pass multiplies the sum by the solid angle of a sample.
    let w = 4.0 * std::f32::consts::PI / 4096.0;

    let mut results = Vec::new();
    let mut serial_input = Vec::new();
    for f in &skies {
        let shares: Vec<f32> = (0..64).map(|_| rng.random_range(0.0..1.0)).collect();
        let total: f32 = shares.iter().sum();
        let mut partials = vec![[0.0f32; 4]; 64 * 9];
        for (g, s) in shares.iter().enumerate() {
            for k in 0..9 {
                let c = f.coeffs[k] * (s / total / w);
                partials[g * 9 + k] = [c.x, c.y, c.z, 0.0];
            }
        }
        let out = run_finish(&ctx, &pipeline, &partials);
        let raw = ShL2Rgb::new(std::array::from_fn(|k| Vec3::from_slice(&out[k][..3])));
        let got = ShL2Rgb::new(std::array::from_fn(|k| Vec3::from_slice(&out[9 + k][..3])));
        // The reduction: 64 shares of each coefficient, summed in f32 in two different orders.
        for k in 0..9 {
            let d = (raw.coeffs[k] - f.coeffs[k]).abs().max_element();
            let s = f.coeffs[k].abs().max_element();
            assert!(
                d <= s * 1e-5,
                "coefficient {k}: sum {} of {}",
                raw.coeffs[k],
                f.coeffs[k]
            );
        }
        for c in &raw.coeffs {
            serial_input.extend([c.x, c.y, c.z]);
        }
        results.push((raw, got));
    }
    let serial_out = serial.run(&ctx, &serial_input).unwrap();
    let serial_out: Vec<&[f32]> = serial_out.chunks(Kernel::ShDering.out_stride()).collect();

    // The strength of the deringed result: the grid value whose window gives it.
    let grid: Vec<f32> = (0..=8).map(|k| k as f32 / 8.0).collect();
    let strength_of = |raw: &ShL2Rgb, got: &ShL2Rgb| -> Option<f32> {
        grid.iter().copied().find(|&t| {
            let want = raw.scale_bands(dering_window(t));
            (0..9).all(|k| {
                let d = (got.coeffs[k] - want.coeffs[k]).abs().max_element();
                d <= raw.coeffs[k].abs().max_element() * 1e-6
            })
        })
    };
    let (mut ties, mut windowed, mut untouched, mut zeroed) = (0, 0, 0, 0);
    for (i, (raw, got)) in results.iter().enumerate() {
        let cpu = dering(raw);
        if raw.coeffs[0].min_element() < 0.0 {
            assert!(
                got.coeffs.iter().all(|c| *c == Vec3::ZERO),
                "sky {i}: negative mean"
            );
            zeroed += 1;
            continue;
        }
        let Some(t) = strength_of(raw, got) else {
            panic!("sky {i}: {got:?} is no windowing of {raw:?}");
        };
        // As the one-thread GPU deringing (same f32 arithmetic, so the same strength).
        assert_eq!(
            t, serial_out[i][0],
            "sky {i}: strength against sh_dering_l2_rgb"
        );
        if t != cpu.strength {
            // A strength between the two whose estimated minimum is within rounding of zero
            // (1e-5 of the term scale, as in math_twins) may go either way.
            let (lo, hi) = (t.min(cpu.strength), t.max(cpu.strength));
            let scale = (0..3)
                .map(|c| raw.coeffs.iter().map(|v| v[c].abs()).sum::<f32>() * 1.1)
                .fold(0.0, f32::max);
            let tie = grid.iter().filter(|&&s| s >= lo && s < hi).all(|&s| {
                let w = raw.scale_bands(dering_window(s));
                let lowest = (0..3)
                    .map(|c| find_minimum(&w.channel(c)).1)
                    .fold(f32::INFINITY, f32::min);
                lowest.abs() <= 1e-5 * scale
            });
            assert!(tie, "sky {i}: strength {t}, hikari_math {}", cpu.strength);
            ties += 1;
        }
        if t > 0.0 {
            windowed += 1;
        } else {
            untouched += 1;
        }
    }
    eprintln!(
        "sky dering: {windowed} windowed, {untouched} untouched, {zeroed} zeroed, {ties} ties"
    );
    assert!(windowed >= skies.len() / 4 && untouched >= skies.len() / 4);
    assert!(ties * 50 <= skies.len(), "{ties} strength mismatches");
}

/// `sky.sh` is one dispatch whose last workgroup derings, found by a count that it resets for
/// the next frame: a count left over would leave no workgroup last and the SH unwritten, so
/// morning, afternoon, morning again in one renderer must give two different SH and then the
/// first one again.
#[test]
fn the_sky_sh_follows_the_sky_on_every_frame() {
    let (scene, morning) = frame("09:00", 32, 32);
    let (_, afternoon) = frame("15:00", 32, 32);
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut shs = Vec::new();
    for s in [&morning, &afternoon, &morning] {
        let r = renderer
            .render_reading(s, |o| vec![o.sky.sh.into()])
            .unwrap();
        shs.push(bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec());
    }
    assert!(shs[0][0][1] > 0.0, "no sky in the SH: {:?}", shs[0]);
    assert_ne!(shs[0], shs[1], "the afternoon's SH is the morning's");
    assert_eq!(shs[0], shs[2]);
}

/// The sky's per-frame passes and the table build's first frame, GPU timestamps, as `bench`
/// prints them: `cargo test -p hikari-render --test sky -- --ignored --nocapture` on the
/// machine to measure (full-size tables, a 256x128 frame: the SH pass does not depend on it).
#[test]
#[ignore = "timing: run by hand on real hardware"]
fn sky_pass_timings() {
    let (scene, mut s) = frame("09:00", 256, 128);
    s.settings.sky.table_quality = 2;
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut per_pass: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
    for frame in 0..40 {
        let r = renderer.render_reading(&s, |_| Vec::new()).unwrap();
        let tables: f64 = r
            .timings
            .iter()
            .filter(|t| t.name.starts_with("sky.tables."))
            .filter_map(|t| t.gpu_ms)
            .sum();
        if frame == 0 {
            println!("frame 0: sky.tables.* {tables:.4} ms GPU");
        } else {
            assert_eq!(tables, 0.0, "the tables were rebuilt on frame {frame}");
        }
        assert_eq!(
            r.timings.iter().filter(|t| t.name == "sky.sh").count(),
            1,
            "frame {frame}"
        );
        for t in r.timings.iter().filter(|t| t.name.starts_with("sky.")) {
            if frame >= 10 {
                per_pass.entry(t.name.clone()).or_default().extend(t.gpu_ms);
            }
        }
    }
    println!(
        "{:<24} {:>10} {:>10}",
        "pass (frames 10..40)", "median ms", "min ms"
    );
    for (name, mut v) in per_pass {
        v.sort_by(f64::total_cmp);
        if let (Some(min), Some(med)) = (v.first(), v.get(v.len() / 2)) {
            println!("{name:<24} {med:>10.4} {min:>10.4}");
        }
    }
}

/// The clouds in the sky's SH (`sky.sh_clouds`): the frame's final SH against the twin's
/// projection of the twin's sky seen through the frame's cloud map (`clouds_over_sky`, lit by
/// the directional light and the clear sky's mean radiance), raw and deringed, within the
/// clear-sky test's 2e-3 of the largest coefficient. The clouds must move band 0 by more than
/// 5 % (so that a frame that left them out fails), and with `clouds.ambient` off the SH is the
/// clear sky's.
#[test]
fn the_sky_sh_sees_the_clouds_like_the_twin() {
    use hikari_render::techniques::clouds::{CloudParams, reference as clouds};
    let (scene, mut s) = frame("10:00", 64, 48);
    s.settings.clouds = common::small_clouds(0.55, 3000.0);
    let read = |s: &hikari_render::FrameSettings| {
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        let mut picked = None;
        let mut r = renderer
            .render_reading(s, |o| {
                picked = Some((o.sky.params, o.clouds.map));
                vec![o.sky.sh.into(), o.clouds.map.into()]
            })
            .unwrap();
        let (params, map) = picked.unwrap();
        let sh = bytemuck::cast_slice::<u8, [f32; 4]>(r.buffer("sky.sh").unwrap()).to_vec();
        let map: Vec<glam::Vec4> = r
            .take_image_of(map)
            .unwrap()
            .rgba
            .iter()
            .map(|v| glam::Vec4::from_array(*v))
            .collect();
        (params, sh, map)
    };
    let (params, got, map) = read(&s);
    let weather = s.settings.sky.weather().unwrap();
    let atmosphere =
        sky::atmosphere_for(&weather.atmosphere(), s.settings.sky.table_sizes()).unwrap();
    let twin = SkyTwin::new(&atmosphere, params);
    let (clear_raw, clear) = twin.sh();
    let sun = s.directional_light().unwrap().unwrap();
    let cp = CloudParams::new(&s.settings.clouds, "clear", Some(&sun), 36_000.0, true);
    let mean = clear.coeffs[0] * hikari_math::sh::basis::C0 as f32;
    let sun_lux = sun.color * sun.illuminance_lux;
    let (raw, deringed) = twin.sh_with(|d| {
        clouds::clouds_over_sky(&cp, &map, d, twin.background_no_disks(d), sun_lux, mean)
    });
    let scale = raw.coeffs[0].max_element();
    for (name, gpu, cpu) in [
        ("raw", sh_of(&got[..9]), raw),
        ("deringed", sh_of(&got[9..]), deringed),
    ] {
        for k in 0..9 {
            let d = (gpu.coeffs[k] - cpu.coeffs[k]).abs().max_element();
            assert!(
                d <= scale * 2e-3,
                "{name} coefficient {k}: GPU {} twin {}",
                gpu.coeffs[k],
                cpu.coeffs[k]
            );
        }
    }
    let moved = ((raw.coeffs[0] - clear_raw.coeffs[0]).abs() / clear_raw.coeffs[0]).max_element();
    eprintln!("the clouds move band 0 by {moved}");
    assert!(moved > 0.05, "the clouds move band 0 by only {moved}");

    s.settings.clouds.ambient = false;
    let (_, got, _) = read(&s);
    for k in 0..9 {
        let d = (sh_of(&got[..9]).coeffs[k] - clear_raw.coeffs[k])
            .abs()
            .max_element();
        assert!(d <= scale * 2e-3, "clouds.ambient off: coefficient {k}");
    }
}
