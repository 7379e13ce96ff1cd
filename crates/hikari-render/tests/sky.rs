//! The sky on the GPU against its CPU twin (`sky::reference`, built on hikari-atmosphere's own
//! table mapping and sampling and on hikari-math's SH projection and deringing): the sky's
//! pixels, its L2 SH, and the deringed SH's non-negativity. Small tables (quality 0) and a
//! 96x64 frame keep the CPU driver fast.

mod common;

use glam::Vec3;

use hikari_math::sh::Sh;
use hikari_render::Renderer;
use hikari_render::techniques::gbuffer;
use hikari_render::techniques::sky::{self, SkyParams, lights, reference::SkyTwin};

fn frame(time: &str, w: u32, h: u32) -> (hikari_scene::Scene, hikari_render::FrameSettings) {
    let scene = hikari_scene::builtin::by_name("boxes").unwrap();
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.sky.enabled = true;
    s.settings.sky.table_quality = 0;
    s.settings.sky.time = time.into();
    s.sun = lights::directional_light(&s.settings.sky).unwrap();
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
    let ctx = common::gpu().unwrap();
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let mut params = None;
    let mut r = renderer
        .render_reading(s, |o| {
            params = Some(o.sky.params);
            vec![o.gbuffer.depth.into(), o.hdr.into(), o.sky.sh.into()]
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
    if common::gpu().is_none() {
        return;
    }
    // 09:00: the sun up in the east; 23:30: the full moon lights the sky.
    for time in ["09:00", "23:30"] {
        let (scene, s) = frame(time, 96, 64);
        let got = render(&scene, &s);
        let weather = s.settings.sky.weather().unwrap();
        let atmosphere =
            sky::atmosphere_for(&weather.atmosphere(), s.settings.sky.table_sizes()).unwrap();
        let l = sky::frame_lights(&s.settings.sky, s.sun.as_ref()).unwrap();
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

#[test]
fn a_disabled_sky_leaves_the_placeholders_and_a_zero_sh() {
    if common::gpu().is_none() {
        return;
    }
    let (scene, mut s) = frame("12:00", 32, 24);
    s.settings.sky.enabled = false;
    let got = render(&scene, &s);
    assert!(got.sh.iter().all(|c| *c == [0.0; 4]));
    assert_eq!(got.params, <SkyParams as bytemuck::Zeroable>::zeroed());
}
