//! Bad input and stability of the ray-traced GI (issue 18), through the whole frame: NaN and
//! infinity put into G-buffer texels (`Renderer::override_gbuffer_texels`, after the G-buffer
//! pass, before the GI's) and into the accumulation's history
//! (`GraphRuntime::history_for_next_frame`), and the flicker of the denoised GI while the camera
//! moves, measured by reprojecting each frame into the next on the CPU by depth.

use crate::common;

use glam::{Mat4, Vec3, Vec4};
use hikari_render::graph::ImageRgba32;
use hikari_render::techniques::gbuffer::overrides::{GBufferTarget, GBufferTexel};
use hikari_render::techniques::ray_traced_gi::reference::world_from_depth;
use hikari_render::view::View;
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::Scene;

/// Image side: small, so that the CPU driver renders a frame in well under a second.
const SIZE: u32 = 64;

/// The denoisers' largest radius on screen in these tests (default 40 px, which spans the
/// whole image): it bounds how far one texel can reach, so that the rest can be compared.
const MAX_RADIUS_PX: f32 = 4.0;

/// The GI's textures of one frame, as read back.
struct GiImages {
    /// Accumulated (history): Y SH, CoCg, AO, history length, and the view depth the
    /// accumulation keeps for the next frame's depth test.
    y: ImageRgba32,
    cocg: ImageRgba32,
    ao: ImageRgba32,
    length: ImageRgba32,
    view_depth: ImageRgba32,
    /// This frame's raw sample (the shade pass's output) and hit distance.
    raw_y: ImageRgba32,
    raw_cocg_ao: ImageRgba32,
    distance: ImageRgba32,
    /// After the denoisers.
    den_y: ImageRgba32,
    den_cocg: ImageRgba32,
    den_ao: ImageRgba32,
    /// The lit image kept for the next frame's hits (`reuse_lit`).
    lit: ImageRgba32,
    /// The frame's HDR output and its G-buffer depth.
    hdr: ImageRgba32,
    depth: ImageRgba32,
}

impl GiImages {
    /// Every GI texture, by name, for the finiteness checks (the HDR image is checked apart).
    fn gi(&self) -> [(&'static str, &ImageRgba32); 12] {
        [
            ("accumulated Y", &self.y),
            ("accumulated CoCg", &self.cocg),
            ("accumulated AO", &self.ao),
            ("history length", &self.length),
            ("history view depth", &self.view_depth),
            ("raw Y", &self.raw_y),
            ("raw CoCg AO", &self.raw_cocg_ao),
            ("hit distance", &self.distance),
            ("denoised Y", &self.den_y),
            ("denoised CoCg", &self.den_cocg),
            ("denoised AO", &self.den_ao),
            ("kept lit image", &self.lit),
        ]
    }
}

/// Names read by `--dump` (they have no handle in the frame's outputs).
const DUMPS: [&str; 4] = [
    "ray_traced_gi.view_depth",
    "ray_traced_gi.raw_y",
    "ray_traced_gi.raw_cocg_ao",
    "ray_traced_gi.lit",
];

fn new_renderer(scene: &Scene) -> Renderer {
    let mut r = Renderer::new(common::gpu_context(), scene).unwrap();
    r.runtime
        .set_dumps(DUMPS.iter().map(|s| s.to_string()).collect());
    r
}

fn render(renderer: &mut Renderer, s: &FrameSettings) -> GiImages {
    let mut picked = None;
    let mut r = renderer
        .render_reading(s, |o| {
            let f = o.ray_traced_gi.expect("ray-traced GI is on");
            let d = o.denoised_gi.expect("the GI denoiser is on");
            picked = Some((f, d, o.hdr, o.gbuffer.depth));
            vec![
                f.gi_y.into(),
                f.gi_cocg.into(),
                f.ao.into(),
                f.history_length.into(),
                f.hit_distance.into(),
                d.gi_y.into(),
                d.gi_cocg.into(),
                d.ao.into(),
                o.hdr.into(),
                o.gbuffer.depth.into(),
            ]
        })
        .unwrap();
    let (f, d, hdr, depth) = picked.unwrap();
    let mut named = |n: &str| r.take_image(n).unwrap_or_else(|| panic!("no dump {n}"));
    let (view_depth, raw_y, raw_cocg_ao, lit) = (
        named(DUMPS[0]),
        named(DUMPS[1]),
        named(DUMPS[2]),
        named(DUMPS[3]),
    );
    let mut take = |t| r.take_image_of(t).unwrap();
    GiImages {
        y: take(f.gi_y),
        cocg: take(f.gi_cocg),
        ao: take(f.ao),
        length: take(f.history_length),
        distance: take(f.hit_distance),
        den_y: take(d.gi_y),
        den_cocg: take(d.gi_cocg),
        den_ao: take(d.ao),
        hdr: take(hdr),
        depth: take(depth),
        view_depth,
        raw_y,
        raw_cocg_ao,
        lit,
    }
}

/// `boxes` (a sunlit ground and coloured boxes) at 64 x 64 from its first camera, GI and
/// both denoisers on, the denoisers' radius capped at [`MAX_RADIUS_PX`], TAA off: its jitter
/// moves silhouettes by a fraction of a pixel each frame, so that pixels on them restart their
/// history by themselves, and it would shift the views the stability test reprojects between.
fn gi_settings(scene: &Scene) -> FrameSettings {
    let mut s = common::small_frame_settings(scene, SIZE, SIZE);
    s.settings.ray_traced_gi.enabled = true;
    s.settings.taa.enabled = false;
    s.settings.gi_denoiser.max_radius_px = MAX_RADIUS_PX;
    s
}

/// Where a texel is not finite: `(what, pixel, value)`.
fn non_finite(img: &GiImages) -> Vec<(&'static str, usize, [f32; 4])> {
    let mut bad = Vec::new();
    for (what, im) in img.gi() {
        for (i, p) in im.rgba.iter().enumerate() {
            if !p.iter().all(|v| v.is_finite()) {
                bad.push((what, i, *p));
            }
        }
    }
    bad
}

fn f16_bytes(v: [f32; 4]) -> Vec<u8> {
    v.iter()
        .flat_map(|x| half::f16::from_f32(*x).to_le_bytes())
        .collect()
}

fn chebyshev(a: usize, b: [u32; 2]) -> u32 {
    let (x, y) = ((a as u32) % SIZE, (a as u32) / SIZE);
    x.abs_diff(b[0]).max(y.abs_diff(b[1]))
}

/// Frames rendered in the G-buffer test: enough for a texel's history to be reprojected and
/// blended twice.
const BAD_GBUFFER_FRAMES: u32 = 3;

/// NaN and infinity in G-buffer texels (depth, octahedral normal, motion vector, emission),
/// overwritten every frame after the G-buffer pass, go through pre-trace, BVH trace, shade, accumulation,
/// both GI denoiser passes and the AO denoiser, over [`BAD_GBUFFER_FRAMES`] frames:
///
/// - every GI texture (raw sample, hit distance, accumulated signal, history length and view
///   depth, denoised signal and AO, the lit image kept for the next frame) is finite
///   everywhere, the bad texels included;
/// - against a clean run (same frames, same rays): the bad texels change the raw samples of
///   few pixels (their own and those whose screen-space march crosses them: at most 2 % of the
///   image), and the accumulated and denoised GI changes only within the reach of a changed
///   pixel: the firefly clamp's 3x3 once a frame, then the two GI passes (each at most
///   [`MAX_RADIUS_PX`] plus the 3x3 of its variance) or the AO denoiser (the same radius plus
///   the pixel it shares a thread with). Beyond that reach every texel equals the clean run's
///   to f16 rounding (2^-10 relative, 2^-14 absolute); the two runs trace the same rays, so
///   nothing else may differ.
///
/// The albedo texel is not overwritten: `gbuffer.albedo` is Rgba8Unorm, which cannot hold NaN
/// or infinity (Vulkan converts a NaN written to it to 0).
#[test]
fn non_finite_gbuffer_texels_stay_out_of_every_gi_output() {
    let scene = hikari_scene::builtin::boxes();
    let s = gi_settings(&scene);
    let mut clean = new_renderer(&scene);
    let clean_frames: Vec<GiImages> = (0..BAD_GBUFFER_FRAMES)
        .map(|_| render(&mut clean, &s))
        .collect();
    // The bad texels: on the ground near the image's lower left corner, so that most of the
    // image lies beyond their reach.
    let depth = &clean_frames[0].depth;
    let texel = |target, pixel: [u32; 2], bytes: Vec<u8>| {
        let d = depth.rgba[(pixel[1] * SIZE + pixel[0]) as usize][0];
        assert!(d > 0.0, "{pixel:?} should be a surface");
        GBufferTexel {
            target,
            pixel,
            size: [1, 1],
            bytes,
        }
    };
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let texels = vec![
        texel(GBufferTarget::Depth, [4, 56], nan.to_le_bytes().to_vec()),
        texel(GBufferTarget::Depth, [8, 56], inf.to_le_bytes().to_vec()),
        texel(
            GBufferTarget::Depth,
            [12, 56],
            (-inf).to_le_bytes().to_vec(),
        ),
        texel(
            GBufferTarget::Normal,
            [4, 60],
            f16_bytes([nan, 0.2, 0.0, 0.0]),
        ),
        texel(
            GBufferTarget::Normal,
            [8, 60],
            f16_bytes([0.3, inf, 0.0, 0.0]),
        ),
        texel(
            GBufferTarget::Normal,
            [12, 60],
            f16_bytes([-inf, nan, 0.0, 0.0]),
        ),
        texel(
            GBufferTarget::Motion,
            [4, 52],
            f16_bytes([nan, 0.0, 3.0, 0.0]),
        ),
        texel(
            GBufferTarget::Motion,
            [8, 52],
            f16_bytes([inf, -inf, 3.0, 0.0]),
        ),
        texel(
            GBufferTarget::Motion,
            [12, 52],
            f16_bytes([0.0, 0.0, nan, 0.0]),
        ),
        texel(
            GBufferTarget::Emissive,
            [16, 56],
            f16_bytes([nan, 1.0, 1.0, 0.0]),
        ),
        texel(
            GBufferTarget::Emissive,
            [16, 60],
            f16_bytes([inf, inf, inf, 0.0]),
        ),
    ];
    let pixels: Vec<[u32; 2]> = texels.iter().map(|t| t.pixel).collect();
    let mut bad = new_renderer(&scene);
    bad.override_gbuffer_texels(texels);

    // Pixels whose raw sample changed in some frame so far.
    let mut changed_raw = vec![false; (SIZE * SIZE) as usize];
    let differs = |a: &[f32; 4], b: &[f32; 4]| {
        a.iter().zip(b).any(|(x, y)| {
            (x - y).abs() > (2f32.powi(-10) * x.abs().max(y.abs())).max(2f32.powi(-14))
        })
    };
    for (frame, c) in clean_frames.iter().enumerate() {
        let b = render(&mut bad, &s);
        // The overrides reached the G-buffer.
        let at = |p: [u32; 2]| b.depth.rgba[(p[1] * SIZE + p[0]) as usize][0];
        assert!(at(pixels[0]).is_nan() && at(pixels[1]) == inf && at(pixels[2]) == -inf);
        let nf = non_finite(&b);
        assert!(
            nf.is_empty(),
            "frame {frame}: {} non-finite GI texels, first {:?}",
            nf.len(),
            &nf[..nf.len().min(8)]
        );
        for (i, flag) in changed_raw.iter_mut().enumerate() {
            *flag |= differs(&b.raw_y.rgba[i], &c.raw_y.rgba[i])
                || differs(&b.raw_cocg_ao.rgba[i], &c.raw_cocg_ao.rgba[i]);
        }
        let changed: Vec<usize> = (0..changed_raw.len()).filter(|&i| changed_raw[i]).collect();
        assert!(
            changed.len() as u32 <= SIZE * SIZE / 50,
            "frame {frame}: the raw samples of {} pixels changed",
            changed.len()
        );
        // Reach: the firefly clamp's 3x3 each frame of history, then the denoisers.
        let reach = (frame as u32 + 1) + 2 * (MAX_RADIUS_PX.ceil() as u32 + 1) + 1;
        let sources: Vec<[u32; 2]> = changed
            .iter()
            .map(|&i| [i as u32 % SIZE, i as u32 / SIZE])
            .chain(pixels.iter().copied())
            .collect();
        let mut far = 0;
        for i in 0..(SIZE * SIZE) as usize {
            if sources.iter().any(|&p| chebyshev(i, p) <= reach) {
                continue;
            }
            far += 1;
            for ((what, bi), (_, ci)) in b.gi().iter().zip(c.gi().iter()) {
                assert!(
                    !differs(&bi.rgba[i], &ci.rgba[i]),
                    "frame {frame}: {what} at ({}, {}), beyond the reach ({reach} px) of every \
                     changed pixel: {:?}, clean {:?}",
                    i as u32 % SIZE,
                    i as u32 / SIZE,
                    bi.rgba[i],
                    ci.rgba[i]
                );
            }
        }
        eprintln!(
            "frame {frame}: {} raw samples changed, {far} pixels beyond the reach {reach} px \
             compared",
            changed.len()
        );
        assert!(
            far >= (SIZE * SIZE / 20) as usize,
            "too few pixels left to compare: {far}"
        );
        // The frame's HDR output too (the deferred lighting reads the same G-buffer).
        let hdr_bad = b
            .hdr
            .rgba
            .iter()
            .filter(|p| !p.iter().all(|v| v.is_finite()))
            .count();
        assert_eq!(hdr_bad, 0, "frame {frame}: {hdr_bad} non-finite HDR pixels");
    }
}

/// Frames rendered before the history is damaged.
const WARM_FRAMES: u32 = 4;

/// NaN and infinity in the accumulation's history (Y SH, CoCg, AO, history length, view depth)
/// and in the lit image kept for the hits, written between two frames of a still camera over
/// a 3x3 block of texels each: the next frame's GI textures are all finite; the block's centre,
/// whose whole 3x3 is damaged, starts again (history length 1, then 2 a frame later); the
/// block's ring takes the undamaged texels of its own 3x3 (the accumulation's fallback where
/// its reprojected texel fails) and, as every other surface pixel, keeps growing its history
/// (length `WARM_FRAMES + 1`). A damaged lit image only feeds the hits that see it; it restarts
/// nothing.
#[test]
fn non_finite_history_texels_restart_their_pixel() {
    damage_history(false);
}

/// The same with `gi_denoiser.recurrent` on, where the accumulation's Y SH, CoCg and AO
/// history are last frame's denoised output.
#[test]
fn non_finite_denoised_history_texels_restart_their_pixel() {
    damage_history(true);
}

fn damage_history(recurrent: bool) {
    let scene = hikari_scene::builtin::boxes();
    let mut s = gi_settings(&scene);
    s.settings.gi_denoiser.recurrent = recurrent;
    // What the accumulation reads as its Y SH, CoCg and AO history.
    let [gi_y, gi_cocg, ao] = if recurrent {
        [
            "gi_denoiser.pass2_y",
            "gi_denoiser.pass2_cocg",
            "gi_denoiser.ao",
        ]
    } else {
        [
            "ray_traced_gi.gi_y",
            "ray_traced_gi.gi_cocg",
            "ray_traced_gi.ao",
        ]
    };
    let mut r = new_renderer(&scene);
    let mut last = None;
    for _ in 0..WARM_FRAMES {
        last = Some(render(&mut r, &s));
    }
    let last = last.unwrap();
    assert!(
        last.length
            .rgba
            .iter()
            .all(|p| p[0] == 0.0 || p[0] == WARM_FRAMES as f32),
        "a still camera grows every surface pixel's history"
    );
    // Block centres: surface pixels each of whose ring pixels has, outside the block and
    // within its own 3x3, a surface texel at a view depth within 2 % of its own (the
    // accumulation's depth test allows 5 %), so that the ring keeps its history; spread over
    // the image, at least 6 pixels apart, so that no two blocks touch.
    let view_depth = |x: i64, y: i64| {
        let inside = (0..SIZE as i64).contains(&x) && (0..SIZE as i64).contains(&y);
        let i = (y * SIZE as i64 + x) as usize;
        (inside && last.length.rgba[i][0] > 0.0).then(|| last.view_depth.rgba[i][0])
    };
    let ring_keeps_history = |cx: i64, cy: i64, rx: i64, ry: i64| {
        let Some(z) = view_depth(rx, ry) else {
            return false;
        };
        (-1..=1).any(|dy: i64| {
            (-1..=1).any(|dx: i64| {
                let (qx, qy) = (rx + dx, ry + dy);
                let outside = (qx - cx).abs() > 1 || (qy - cy).abs() > 1;
                outside && view_depth(qx, qy).is_some_and(|q| (q - z).abs() <= 0.02 * z)
            })
        })
    };
    let candidates: Vec<[u32; 2]> = (0..SIZE * SIZE)
        .map(|i| [i % SIZE, i / SIZE])
        .filter(|p| {
            let (x, y) = (p[0] as i64, p[1] as i64);
            view_depth(x, y).is_some()
                && (-1..=1).all(|dy| {
                    (-1..=1)
                        .all(|dx| (dx, dy) == (0, 0) || ring_keeps_history(x, y, x + dx, y + dy))
                })
        })
        .collect();
    let mut surfaces: Vec<[u32; 2]> = Vec::new();
    for c in candidates.iter().step_by((candidates.len() / 64).max(1)) {
        let apart = |p: &[u32; 2]| p[0].abs_diff(c[0]).max(p[1].abs_diff(c[1])) >= 6;
        if surfaces.iter().all(apart) {
            surfaces.push(*c);
        }
    }
    assert!(surfaces.len() >= 16, "{} block centres", surfaces.len());
    let mut pick = surfaces.iter().step_by(surfaces.len() / 16).copied();
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    // (history, texel bytes for one value, values): each value at its own pixel.
    let half = |v: f32, n: usize| f16_bytes([v; 4])[..2 * n].to_vec();
    let bad: Vec<(&str, Vec<u8>, bool)> = vec![
        (gi_y, half(nan, 4), true),
        (gi_y, f16_bytes([inf, 0.1, 0.1, 0.1]), true),
        (gi_y, f16_bytes([0.1, -inf, 0.1, nan]), true),
        (gi_cocg, half(nan, 2), true),
        (gi_cocg, half(-inf, 2), true),
        (ao, half(nan, 1), true),
        (ao, half(inf, 1), true),
        ("ray_traced_gi.history_length", half(nan, 1), true),
        ("ray_traced_gi.history_length", half(inf, 1), true),
        ("ray_traced_gi.view_depth", nan.to_le_bytes().to_vec(), true),
        ("ray_traced_gi.view_depth", inf.to_le_bytes().to_vec(), true),
        ("ray_traced_gi.lit", half(nan, 4), false),
        ("ray_traced_gi.lit", half(inf, 4), false),
    ];
    let mut restart = Vec::new();
    for (name, bytes, restarts) in &bad {
        let p = pick.next().unwrap();
        let tex = r
            .runtime
            .history_for_next_frame(name)
            .unwrap_or_else(|| panic!("no history {name}"));
        r.ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: tex,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: p[0] - 1,
                    y: p[1] - 1,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &bytes.repeat(9),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(3 * bytes.len() as u32),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 3,
                height: 3,
                depth_or_array_layers: 1,
            },
        );
        if *restarts {
            restart.push((*name, p));
        }
    }
    for next in 1..=2u32 {
        let f = render(&mut r, &s);
        let nf = non_finite(&f);
        assert!(
            nf.is_empty(),
            "frame {next} after the damage: {} non-finite GI texels, first {:?}",
            nf.len(),
            &nf[..nf.len().min(8)]
        );
        for i in 0..(SIZE * SIZE) as usize {
            let p = [i as u32 % SIZE, i as u32 / SIZE];
            let len = f.length.rgba[i][0];
            let want = match restart.iter().find(|(_, q)| *q == p) {
                Some(_) => next as f32,
                None if last.length.rgba[i][0] > 0.0 => (WARM_FRAMES + next) as f32,
                None => 0.0,
            };
            assert_eq!(
                len,
                want,
                "frame {next} after the damage: history length at {p:?}{}",
                restart
                    .iter()
                    .find(|(_, q)| *q == p)
                    .map_or(String::new(), |(n, _)| format!(" (damaged {n})"))
            );
        }
    }
}

/// One camera path's flicker: for each measured frame, the mean over pixels seen in both
/// frames of |c0_t - c0_{t-1}| / max(c0_t, c0_{t-1}, floor), c0 the denoised GI's luminance
/// (its SH's constant term: world-space, so it does not depend on the view), frame t-1
/// reprojected into frame t on the CPU by depth.
struct Flicker {
    /// Mean over the measured frames.
    mean: f32,
    /// Pixels compared in the measured frames, in all.
    pixels: usize,
}

/// The view's projection without TAA's jitter (the tests turn TAA off).
fn matrices(c: &hikari_scene::Camera) -> (Mat4, Mat4) {
    let v = View::new(c, SIZE, SIZE);
    (
        Mat4::from_cols_array_2d(&v.view_proj),
        Mat4::from_cols_array_2d(&v.inv_view_proj),
    )
}

/// Frames a path renders with the camera still before it moves.
const SETTLE_FRAMES: u32 = 8;
/// Frames measured (each against the one before).
const MEASURED_FRAMES: u32 = 10;

/// Renders `SETTLE_FRAMES` still, then `MEASURED_FRAMES` with the camera moved by `step` each
/// frame (with motion vectors), measuring the flicker of each of those against the one before.
fn flicker(scene: &Scene, s: &FrameSettings, step: impl Fn(&mut hikari_scene::Camera)) -> Flicker {
    let mut r = new_renderer(scene);
    let mut s = s.clone();
    let mut prev: Option<(GiImages, hikari_scene::Camera)> = None;
    let (mut sum, mut frames, mut pixels) = (0.0f64, 0, 0);
    for frame in 0..SETTLE_FRAMES + MEASURED_FRAMES {
        let before = s.camera.clone();
        if frame >= SETTLE_FRAMES {
            step(&mut s.camera);
        }
        s.prev_camera = Some(before);
        let img = render(&mut r, &s);
        if let Some((p, pc)) = &prev
            && frame >= SETTLE_FRAMES
        {
            let (_, inv_now) = matrices(&s.camera);
            let (vp_prev, inv_prev) = matrices(pc);
            let mean_c0 =
                img.den_y.rgba.iter().map(|v| v[0].max(0.0)).sum::<f32>() / (SIZE * SIZE) as f32;
            let floor = 0.01 * mean_c0;
            let (mut s_f, mut n) = (0.0f64, 0usize);
            for y in 1..SIZE - 1 {
                for x in 1..SIZE - 1 {
                    let i = (y * SIZE + x) as usize;
                    let d = img.depth.rgba[i][0];
                    if d <= 0.0 {
                        continue;
                    }
                    let world = world_from_depth(inv_now, [SIZE, SIZE], [x, y], d);
                    let clip = vp_prev * Vec4::from((world, 1.0));
                    if clip.w <= 0.0 {
                        continue;
                    }
                    let ndc = clip.truncate() / clip.w;
                    let px = (ndc.x * 0.5 + 0.5) * SIZE as f32;
                    let py = (0.5 - ndc.y * 0.5) * SIZE as f32;
                    if !(px >= 1.0 && py >= 1.0 && px < (SIZE - 1) as f32 && py < (SIZE - 1) as f32)
                    {
                        continue;
                    }
                    let (qx, qy) = (px as u32, py as u32);
                    let j = (qy * SIZE + qx) as usize;
                    let dq = p.depth.rgba[j][0];
                    if dq <= 0.0 {
                        continue;
                    }
                    // Seen in both: the point the previous frame saw there is this one, within
                    // 2 % of its distance (a pixel's footprint at these slopes).
                    let seen = world_from_depth(inv_prev, [SIZE, SIZE], [qx, qy], dq);
                    if (seen - world).length() > 0.02 * (world - pc.position).length() {
                        continue;
                    }
                    let (a, b) = (img.den_y.rgba[i][0], p.den_y.rgba[j][0]);
                    s_f += ((a - b).abs() / a.max(b).max(floor)) as f64;
                    n += 1;
                }
            }
            assert!(
                n > 500,
                "frame {frame}: only {n} pixels seen in both frames"
            );
            sum += s_f / n as f64;
            frames += 1;
            pixels += n;
        }
        prev = Some((img, s.camera.clone()));
    }
    Flicker {
        mean: (sum / frames as f64) as f32,
        pixels,
    }
}

/// The camera's motion: a dolly towards its target with a sideways pan, about 1.5 pixels of
/// screen motion a frame at the boxes (13 m away, 0.17 m a pixel at 64 px): fast enough that
/// a history taken without the motion vectors smears (with the accumulation's reprojection
/// ignoring them, the flicker measured 0.146 against 0.083, breaking both bounds).
fn dolly_and_pan(c: &mut hikari_scene::Camera) {
    let f = c.forward();
    let side = f.cross(Vec3::Y).normalize();
    let d = f * 0.1 + side * 0.25;
    c.position += d;
    c.target += d;
}

/// Bound on the mean flicker of the denoised GI with a moving camera (relative change a frame
/// on surfaces seen in both frames): 10 %. One ray a pixel denoised alone changes by about
/// twice that a frame here (the control); a history of n frames divides the noise's standard
/// deviation by about √n, so after the settling frames the accumulated signal must at least
/// halve it.
const FLICKER_BOUND: f32 = 0.10;
/// Bound on the moving camera's flicker as a multiple of the still camera's: 1.5. Reprojection
/// to the nearest texel and surfaces coming into view add a little; a history dropped or
/// smeared on motion adds as much as the noise itself.
const FLICKER_FACTOR: f32 = 1.5;

/// Stable over frames with a moving camera: `boxes` at 64 x 64 by day, GI and denoisers on,
/// TAA off (so that the view is not jittered and the reprojection is exact), the camera
/// dollying and panning ([`dolly_and_pan`]) for [`MEASURED_FRAMES`] frames after
/// [`SETTLE_FRAMES`] still. The denoised GI's flicker (see [`Flicker`]) stays below
/// [`FLICKER_BOUND`] and at most [`FLICKER_FACTOR`] times a still camera's over the same frames
/// (which measures the estimator's own noise left after accumulation and denoising). The
/// control: the same path with the accumulation off (each frame's one ray a pixel, denoised
/// alone, what a history dropped on motion leaves) must break the bound, so the measure can
/// fail.
#[test]
fn denoised_gi_is_stable_with_a_moving_camera() {
    let scene = hikari_scene::builtin::boxes();
    let mut s = gi_settings(&scene);
    s.settings.gi_denoiser.max_radius_px =
        hikari_render::techniques::gi_denoiser::GiDenoiserSettings::default().max_radius_px;
    let still = flicker(&scene, &s, |_| {});
    let moving = flicker(&scene, &s, dolly_and_pan);
    let mut broken = s.clone();
    broken.settings.ray_traced_gi.accumulate = false;
    let dropped = flicker(&scene, &broken, dolly_and_pan);
    eprintln!(
        "flicker: still {:.4} ({} px), moving {:.4} ({} px), no accumulation {:.4} ({} px)",
        still.mean, still.pixels, moving.mean, moving.pixels, dropped.mean, dropped.pixels
    );
    assert!(
        moving.mean < FLICKER_BOUND,
        "moving camera: flicker {} over the bound {FLICKER_BOUND}",
        moving.mean
    );
    assert!(
        moving.mean <= FLICKER_FACTOR * still.mean,
        "moving camera: flicker {} over {FLICKER_FACTOR} times the still camera's {}",
        moving.mean,
        still.mean
    );
    assert!(
        dropped.mean > FLICKER_BOUND,
        "without accumulation the flicker {} should break the bound {FLICKER_BOUND}",
        dropped.mean
    );
}

/// The hit words, instances and normals of one frame's GI rays.
fn rays(renderer: &mut Renderer, s: &FrameSettings) -> [Vec<u32>; 3] {
    let r = renderer
        .render_reading(s, |o| {
            let rays = o.ray_traced_gi_rays.expect("ray-traced GI is on");
            vec![
                rays.hits.into(),
                rays.hit_instances.into(),
                rays.hit_normals.into(),
            ]
        })
        .unwrap();
    let words = |name: &str| -> Vec<u32> { bytemuck::pod_collect_to_vec(r.buffer(name).unwrap()) };
    [
        words("ray_traced_gi.hits"),
        words("ray_traced_gi.hit_instances"),
        words("ray_traced_gi.hit_normals"),
    ]
}

/// A pre-trace hit takes the normal of the G-buffer texel it crossed; where that texel's normal
/// is not finite it records none (`RTGI_NO_NORMAL`, 0), rather than whatever direction packing
/// a NaN gives. NaN normals over the right half of `boxes` (frame 0): the left half's rays are
/// the clean run's (same hit words and instances: the march reads depth, not normals), and each
/// hit normal is the clean run's or, where it changed, none. At least a few of the left half's
/// pre-trace hits must land in the right half, or nothing was tested.
#[test]
fn a_pretrace_hit_on_a_non_finite_normal_records_no_normal() {
    let scene = hikari_scene::builtin::boxes();
    let s = gi_settings(&scene);
    let [hits, instances, normals] = rays(&mut new_renderer(&scene), &s);
    let mut bad = new_renderer(&scene);
    bad.override_gbuffer_texels(vec![GBufferTexel {
        target: GBufferTarget::Normal,
        pixel: [SIZE / 2, 0],
        size: [SIZE / 2, SIZE],
        bytes: f16_bytes([f32::NAN, f32::NAN, 0.0, 0.0]),
    }]);
    let [b_hits, b_instances, b_normals] = rays(&mut bad, &s);
    let mut dropped = 0;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            if x >= SIZE / 2 {
                assert_eq!(
                    b_normals[i], 0,
                    "({x}, {y}) has a bad normal: no ray, no normal"
                );
                continue;
            }
            assert_eq!(
                (b_hits[i], b_instances[i]),
                (hits[i], instances[i]),
                "({x}, {y})"
            );
            if b_normals[i] != normals[i] {
                assert_eq!(
                    b_normals[i], 0,
                    "({x}, {y}): a hit normal packed from a NaN texel (clean {:#x})",
                    normals[i]
                );
                dropped += 1;
            }
        }
    }
    eprintln!("{dropped} pre-trace hits crossed a NaN normal");
    assert!(
        dropped >= 3,
        "only {dropped} pre-trace hits crossed the NaN half"
    );

    // The hook's own bad input: a rectangle past the image's edge and a texel of the wrong
    // size are errors that name the override, not panics.
    for (pixel, size, bytes) in [
        ([SIZE - 2, 0], [4, 1], f16_bytes([0.0; 4])),
        ([0, 0], [1, 1], vec![0u8; 3]),
    ] {
        bad.override_gbuffer_texels(vec![GBufferTexel {
            target: GBufferTarget::Normal,
            pixel,
            size,
            bytes,
        }]);
        let e = bad
            .render(&s, false)
            .err()
            .expect("a bad override is an error");
        assert!(e.to_string().contains("G-buffer override 0"), "{e}");
    }
}

/// `gi_denoiser.recurrent`: frame 2's accumulation blends its raw sample onto frame 1's
/// *denoised* output (second pass, AO denoiser), where off it blends onto frame 1's own
/// accumulated signal. A still camera and TAA off, so that every surface pixel reprojects onto
/// itself with history length 2 (blend weight 1/2; the firefly clamp starts at 4): checked in
/// c0 and AO at every surface pixel, within f16 rounding (2^-10 relative, 2^-11 absolute on AO).
/// The two histories differ at most pixels, so the test tells them apart.
#[test]
fn the_recurrent_denoiser_accumulates_onto_last_frames_denoised_output() {
    let scene = hikari_scene::builtin::boxes();
    for recurrent in [true, false] {
        let mut s = gi_settings(&scene);
        s.settings.gi_denoiser.recurrent = recurrent;
        let mut r = new_renderer(&scene);
        let one = render(&mut r, &s);
        let two = render(&mut r, &s);
        let (mut checked, mut differ) = (0, 0);
        for i in 0..(SIZE * SIZE) as usize {
            if two.length.rgba[i][0] != 2.0 {
                continue;
            }
            let (prev_y, prev_ao, other_y) = if recurrent {
                (
                    one.den_y.rgba[i][0],
                    one.den_ao.rgba[i][0],
                    one.y.rgba[i][0],
                )
            } else {
                (one.y.rgba[i][0], one.ao.rgba[i][0], one.den_y.rgba[i][0])
            };
            let want_y = 0.5 * (prev_y + two.raw_y.rgba[i][0]);
            let want_ao = 0.5 * (prev_ao + two.raw_cocg_ao.rgba[i][2]);
            let got_y = two.y.rgba[i][0];
            assert!(
                (got_y - want_y).abs() <= want_y.abs() / 1024.0 + 1e-6,
                "recurrent {recurrent}, pixel {i}: accumulated c0 {got_y}, want {want_y}"
            );
            assert!(
                (two.ao.rgba[i][0] - want_ao).abs() <= 1.0 / 2048.0,
                "recurrent {recurrent}, pixel {i}: accumulated AO {}, want {want_ao}",
                two.ao.rgba[i][0]
            );
            checked += 1;
            if (other_y - prev_y).abs() > 0.01 * prev_y.abs().max(1e-3) {
                differ += 1;
            }
        }
        assert!(
            checked > 1000,
            "recurrent {recurrent}: {checked} pixels checked"
        );
        assert!(
            differ * 2 > checked,
            "recurrent {recurrent}: denoised and accumulated differ at {differ} of {checked}"
        );
    }
}
