//! The local tonemap: the bilateral grid against a brute-force bilateral filter by
//! scikit-image (`tools/bilateral_reference.py`), every GPU pass against its CPU twin, and the
//! talk's contrast formula on images whose answer is known.

use crate::common;

use hikari_render::graph::GraphRuntime;
use hikari_render::shader;
use hikari_render::techniques::local_tonemap::reference::{self, Twin};
use hikari_render::techniques::local_tonemap::{
    GRID_SIZE, LocalTonemap, LocalTonemapParams, LocalTonemapSettings, Look,
};
use hikari_render::techniques::tonemap::settings::TonemapSettings;
use hikari_render::techniques::tonemap::{self, LocalGain, Tonemap, TonemapInputs, TonemapParams};
use wgpu::util::DeviceExt;

struct Fixture {
    size: [usize; 2],
    sigma_s: f32,
    sigma_r: f32,
    image: Vec<f32>,
    filtered: Vec<f32>,
}

fn fixture() -> Fixture {
    let bytes = include_bytes!("../fixtures/bilateral_128x64.bin");
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    let f32_at = |i: usize| f32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    let (w, h) = (u32_at(0) as usize, u32_at(4) as usize);
    let n = w * h;
    let floats = |from: usize| (0..n).map(|i| f32_at(from + 4 * i)).collect::<Vec<_>>();
    Fixture {
        size: [w, h],
        sigma_s: f32_at(8),
        sigma_r: f32_at(12),
        image: floats(16),
        filtered: floats(16 + 4 * n),
    }
}

/// Grey radiance whose luminance is 2^v, as f16 (what the renderer's radiance holds).
fn radiance_of(log2: &[f32]) -> (Vec<[f32; 3]>, Vec<half::f16>) {
    let halves: Vec<half::f16> = log2
        .iter()
        .flat_map(|&v| {
            let c = half::f16::from_f32(v.exp2());
            [c, c, c, half::f16::ONE]
        })
        .collect();
    let rgb = halves
        .chunks(4)
        .map(|p| [p[0].to_f32(), p[1].to_f32(), p[2].to_f32()])
        .collect();
    (rgb, halves)
}

fn look(contrast: f32, shadow_contrast: f32, detail: f32) -> Look {
    Look {
        contrast,
        shadow_contrast,
        detail,
    }
}

/// The exposure buffer of these tests: scale 1, and no highlight metered (as with a fixed
/// exposure), so that the look's contrast holds.
const NO_FIT: f32 = hikari_render::techniques::exposure::NO_HIGHLIGHT;

fn twin(rgb: &[[f32; 3]], size: [usize; 2], s: &LocalTonemapSettings, l: Look) -> Twin {
    reference::run(
        rgb,
        size,
        1.0,
        NO_FIT,
        &LocalTonemapParams::new(s, l),
        s.blur_sigma_xy,
        s.blur_sigma_z,
        s.wide_sigma,
    )
}

/// The grid (alone: the wide Gaussian's share 0) against scikit-image's brute-force bilateral
/// filter of the same image at the grid's effective sigmas: the mean error is at most 1 % of
/// the image's log-luminance range (the bound), and the grid does most of what the
/// filter does (its error is under a third of the filter's mean change to the image).
#[test]
fn grid_matches_a_brute_force_bilateral_filter() {
    let f = fixture();
    let s = LocalTonemapSettings::default();
    let p = LocalTonemapParams::new(&s, look(1.0, 1.0, 0.0));
    let (sigma_s, sigma_r) =
        reference::effective_sigmas(f.size, &p, s.blur_sigma_xy, s.blur_sigma_z);
    assert!(
        (sigma_s - f.sigma_s).abs() < 1e-5,
        "{sigma_s} vs fixture {}",
        f.sigma_s
    );
    assert!(
        (sigma_r - f.sigma_r).abs() < 1e-5,
        "{sigma_r} vs fixture {}",
        f.sigma_r
    );

    let (rgb, _) = radiance_of(&f.image);
    let t = twin(&rgb, f.size, &s, look(1.0, 1.0, 0.0));
    let n = f.image.len() as f32;
    let err: f32 = t
        .bilateral
        .iter()
        .zip(&f.filtered)
        .map(|(a, b)| (a - b).abs())
        .sum::<f32>()
        / n;
    let change: f32 = f
        .image
        .iter()
        .zip(&f.filtered)
        .map(|(a, b)| (a - b).abs())
        .sum::<f32>()
        / n;
    let (lo, hi) = f
        .image
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    let relative = err / (hi - lo);
    println!(
        "grid vs bilateral: mean error {err:.4} EV ({:.2} % of {:.2} EV), filter's change {change:.4} EV",
        100.0 * relative,
        hi - lo
    );
    assert!(
        relative <= 0.01,
        "mean error {err} EV is {:.2} % of the range",
        100.0 * relative
    );
    assert!(
        err < change / 3.0,
        "mean error {err} EV, the filter changes the image by {change} EV"
    );
}

/// Runs the technique on the GPU over grey radiance of log2 luminance `log2` (exposure scale 1).
fn run_gpu(
    log2: &[f32],
    size: [usize; 2],
    s: &LocalTonemapSettings,
    l: Look,
) -> hikari_render::graph::FrameResult {
    run_gpu_with_highlight(log2, size, s, l, NO_FIT)
}

/// As [`run_gpu`], with `exposure.value.w` (the frame's exposed highlight) = `highlight`.
fn run_gpu_with_highlight(
    log2: &[f32],
    size: [usize; 2],
    s: &LocalTonemapSettings,
    l: Look,
    highlight: f32,
) -> hikari_render::graph::FrameResult {
    let ctx = common::gpu_context();
    let (_, halves) = radiance_of(log2);
    let (w, h) = (size[0] as u32, size[1] as u32);
    let input = common::texture_with_data(
        &ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&halves),
    );
    let exposure = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test exposure"),
            contents: bytemuck::cast_slice(&[1.0f32, 0.0, 1.0, highlight]),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
        });
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let tm = LocalTonemap::new(&ctx, &mut lib).unwrap();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let hdr = g.import_texture("test.hdr", &input);
    let e = g.import_buffer("test.exposure", &exposure);
    let out = tm.record(&mut g, hdr, e, [w, h], s, l).unwrap();
    let gain = tm.gain_image(&mut g, hdr, e, [w, h], &out).unwrap();
    g.readback(gain);
    if let (Some(grid), Some(wide)) = (out.grid, out.wide) {
        g.readback(grid);
        g.readback(wide);
    }
    g.execute().unwrap()
}

/// Every pass against the twin on the fixture's image with the default settings and a clear
/// day's look. Tolerances: the blurred grid within 1e-4 of its cell's weight (the fill's
/// fixed-point sums are exact; a pixel whose log2 rounds differently on the GPU moves one
/// 1/1024 step), the wide Gaussian within 1e-3 EV, the gain within the f16 store's rounding
/// (2^-10 relative) plus 2e-3 EV.
#[test]
fn every_pass_matches_its_cpu_twin() {
    let f = fixture();
    let s = LocalTonemapSettings::default();
    let l = look(0.6, 0.85, 1.2);
    let (rgb, _) = radiance_of(&f.image);
    let t = twin(&rgb, f.size, &s, l);
    let mut r = run_gpu(&f.image, f.size, &s, l);

    let grid = r.take_image("local_tonemap.grid_blurred").unwrap();
    let [gw, gh, gd] = GRID_SIZE.map(|v| v as usize);
    assert_eq!((grid.width as usize, grid.height as usize), (gw, gh * gd));
    let mut worst_grid = 0f32;
    for z in 0..gd {
        for y in 0..gh {
            for x in 0..gw {
                let got = grid.rgba[(z * gh + y) * gw + x];
                let want = t.blurred.at(x, y, z);
                let tol = 1e-4 * want[1].max(1.0);
                worst_grid = worst_grid
                    .max((got[0] - want[0]).abs() / (tol * 24.0))
                    .max((got[1] - want[1]).abs() / tol);
            }
        }
    }
    assert!(
        worst_grid <= 1.0,
        "grid: worst error {worst_grid} of its tolerance"
    );

    let wide = r.take_image("local_tonemap.wide").unwrap();
    let worst_wide = wide
        .rgba
        .iter()
        .zip(&t.wide)
        .map(|(g, w)| (g[0] - w).abs())
        .fold(0f32, f32::max);
    assert!(worst_wide <= 1e-3, "wide: worst error {worst_wide} EV");

    let gain = r.take_image("local_tonemap.log2_gain").unwrap();
    let mut worst = 0f32;
    for (g, w) in gain.rgba.iter().zip(&t.gain) {
        let tol = 2e-3 + w.abs() * 2f32.powi(-10);
        worst = worst.max((g[0] - w).abs() / tol);
    }
    assert!(worst <= 1.0, "gain: worst error {worst} of its tolerance");
    // The talk's purpose: the window is pulled down, the room lifted.
    let at = |x: usize, y: usize| t.gain[y * f.size[0] + x];
    assert!(
        at(100, 25) < -0.5 && at(30, 50) > 0.0,
        "window {} room {}",
        at(100, 25),
        at(30, 50)
    );
}

/// A flat image has no detail and B = I: the gain is (c - 1)(I - M), with c of its side of
/// the midpoint; with d = 1 and c = 1 nothing changes.
#[test]
fn flat_images_follow_the_contrast_formula() {
    let size = [64usize, 64];
    let s = LocalTonemapSettings::default();
    for (v, l) in [
        (s.midpoint + 3.0, look(0.5, 0.9, 1.3)),
        (s.midpoint - 2.0, look(0.5, 0.75, 1.3)),
        (s.midpoint + 3.0, look(1.0, 1.0, 1.0)),
    ] {
        let img = vec![v; size[0] * size[1]];
        let c = if v > s.midpoint {
            l.contrast
        } else {
            l.shadow_contrast
        };
        let want = (c - 1.0) * (v - s.midpoint);
        let mut r = run_gpu(&img, size, &s, l);
        let gain = r.take_image("local_tonemap.log2_gain").unwrap();
        for g in &gain.rgba {
            // f16 of 2^v and the store: a few thousandths of an EV.
            assert!(
                (g[0] - want).abs() < 5e-3,
                "at {v}: gain {} want {want}",
                g[0]
            );
        }
    }
}

/// The highlight fit on flat images: with the frame's highlight H above the target T, the
/// contrast above the midpoint becomes (T − M) / (H − M) (bounded by the least contrast and
/// the look's), so the gain is (c − 1)(I − M) with that c; below the midpoint, and with H
/// under T, the look's contrasts hold.
#[test]
fn the_highlight_fit_lowers_the_contrast_as_its_formula_says() {
    let size = [64usize, 64];
    let s = LocalTonemapSettings::default();
    let (m, t) = (s.midpoint, s.highlight_target_ev);
    let l = look(0.6, 0.85, 1.0);
    for (v, highlight, c) in [
        // (-0.5 + 3) / (3 + 3) = 0.417: between the least contrast and the look's.
        (m + 3.0, 3.0, (t - m) / (3.0 - m)),
        // Far above: the least contrast.
        (m + 3.0, 30.0, s.min_contrast),
        // Under the target: the look.
        (m + 3.0, t - 1.0, l.contrast),
        // Below the midpoint the shadow contrast, whatever the highlight.
        (m - 2.0, 5.0, l.shadow_contrast),
    ] {
        let want = (c - 1.0) * (v - m);
        let img = vec![v; size[0] * size[1]];
        let mut r = run_gpu_with_highlight(&img, size, &s, l, highlight);
        let gain = r.take_image("local_tonemap.log2_gain").unwrap();
        for g in &gain.rgba {
            assert!(
                (g[0] - want).abs() < 5e-3,
                "at {v} with highlight {highlight}: gain {} want {want}",
                g[0]
            );
        }
        let p = LocalTonemapParams::new(&s, l);
        if v > m {
            assert!((reference::contrast_above(&p, highlight) - c).abs() < 1e-6);
        }
    }
}

#[test]
fn off_gives_a_gain_of_zero() {
    let f = fixture();
    let s = LocalTonemapSettings {
        enabled: false,
        ..Default::default()
    };
    let mut r = run_gpu(&f.image, f.size, &s, look(0.5, 0.5, 1.0));
    let gain = r.take_image("local_tonemap.log2_gain").unwrap();
    assert!(gain.rgba.iter().all(|g| g[0] == 0.0));
}

/// The frame's path: `tonemap.apply` evaluates the gain per pixel from the blurred grid and the
/// wide Gaussian instead of reading `local_tonemap.log2_gain`. Against the twins chained (the
/// local tonemap's gain in f32, then the tonemap's twin), on the fixture's image with the
/// default tonemap: at most one 8-bit step apart, in under 2 % of the channels (the GPU's
/// `exp2`, `log2` and `pow` against the CPU's; the gain is not rounded to f16 on either side).
#[test]
fn the_tonemap_evaluates_the_gain_as_the_twins_do() {
    let f = fixture();
    let s = LocalTonemapSettings::default();
    let l = look(0.6, 0.85, 1.2);
    let (rgb, halves) = radiance_of(&f.image);
    let t = twin(&rgb, f.size, &s, l);

    let ctx = common::gpu_context();
    let (w, h) = (f.size[0] as u32, f.size[1] as u32);
    let input = common::texture_with_data(
        &ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&halves),
    );
    // Exposure scale 1: the fixture's log2 luminance is the exposed one.
    let exposure = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test exposure"),
            contents: bytemuck::cast_slice(&[1.0f32, 0.0, 1.0, NO_FIT]),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
        });
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let local = LocalTonemap::new(&ctx, &mut lib).unwrap();
    let tm = Tonemap::new(&ctx, &mut lib).unwrap();
    let ts = TonemapSettings::default();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let hdr = g.import_texture("test.hdr", &input);
    let e = g.import_buffer("test.exposure", &exposure);
    let frame = local.record(&mut g, hdr, e, [w, h], &s, l).unwrap();
    assert!(frame.log2_gain.is_none(), "no gain image unless dumped");
    let ldr = tm
        .record(
            &mut g,
            &mut Default::default(),
            &ts,
            TonemapInputs {
                hdr,
                exposure: e,
                local: LocalGain::of(&frame),
            },
            [w, h],
        )
        .unwrap();
    g.readback(ldr);
    let r = g.execute().unwrap();
    let got = &r.image("tonemap.ldr").unwrap().rgba;

    let p = TonemapParams::new(&ts, None, false, 0)
        .unwrap()
        .with_local_grid(LocalTonemapParams::new(&s, l));
    let (mut worst, mut differ) = (0i32, 0usize);
    for (i, px) in got.iter().enumerate() {
        let (x, y) = ((i % f.size[0]) as u32, (i / f.size[0]) as u32);
        let want = tonemap::reference::apply(&p, 1.0, t.gain[i], None, rgb[i], x, y);
        for k in 0..3 {
            let d = ((px[k] * 255.0).round() as i32 - (want[k] * 255.0).round() as i32).abs();
            worst = worst.max(d);
            differ += (d != 0) as usize;
        }
    }
    let n = got.len() * 3;
    assert!(
        worst <= 1 && differ * 50 <= n,
        "worst {worst} steps, {differ} of {n} channels differ"
    );
}
