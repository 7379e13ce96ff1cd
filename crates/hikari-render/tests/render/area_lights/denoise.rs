//! The shadow denoiser: its passes against their twins, noise, NaN, and its history over cuts and resizes.

use super::*;

// ---- The shadow denoiser ----

/// The G-buffer of the point-light penumbra scene (64 x 16, TAA off so the view has no
/// jitter), with its right quarter pushed to another depth and a band of rows given another
/// normal, so that the edge-aware weights have edges to stop at.
struct DenoiseRig {
    ctx: hikari_render::GpuContext,
    denoiser: area_lights::ShadowDenoiser,
    rt: hikari_render::graph::GraphRuntime,
    view: hikari_render::view::View,
    w: u32,
    h: u32,
    depth: Vec<f32>,
    normal: Vec<[f32; 4]>,
    motion: Vec<[f32; 4]>,
}

/// What one frame of the denoiser wrote.
struct DenoiseOut {
    raw: Vec<[f32; 4]>,
    history: reference::VisibilityHistory,
    filtered: Vec<[f32; 4]>,
    radiance: Vec<[f32; 4]>,
}

fn f16r(v: f32) -> f32 {
    half::f16::from_f32(v).to_f32()
}

fn f16r4(v: [f32; 4]) -> [f32; 4] {
    v.map(f16r)
}

impl DenoiseRig {
    fn new() -> Self {
        let (w, h) = (64u32, 16u32);
        let scene = point_light_scene(true);
        let mut s = common::small_frame_settings(&scene, w, h);
        s.settings.taa.enabled = false;
        let ctx = common::gpu_context();
        let mut renderer = Renderer::new(ctx, &scene).unwrap();
        let mut r = renderer
            .render_reading(&s, |o| {
                let g = &o.gbuffer;
                vec![g.depth.into(), g.normal.into(), g.motion.into()]
            })
            .unwrap();
        let mut depth: Vec<f32> = r
            .take_image("gbuffer.depth")
            .unwrap()
            .rgba
            .iter()
            .map(|p| p[0])
            .collect();
        let mut normal = r.take_image("gbuffer.normal").unwrap().rgba;
        let motion = r.take_image("gbuffer.motion").unwrap().rgba;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if x >= 48 {
                    depth[i] *= 0.8;
                }
                if (6..9).contains(&y) {
                    let n = hikari_render::reference::octahedral::encode(
                        Vec3::new(0.6, 0.8, 0.0).normalize(),
                    );
                    normal[i] = f16r4([n.x, n.y, normal[i][2], normal[i][3]]);
                }
            }
        }
        let ctx = common::gpu_context();
        let mut lib =
            hikari_render::shader::library(hikari_render::shader::capabilities_for(ctx.features))
                .unwrap();
        let denoiser = area_lights::ShadowDenoiser::new(&ctx, &mut lib).unwrap();
        let mut rt = hikari_render::graph::GraphRuntime::new();
        rt.set_dumps(
            [
                "area_lights.visibility_raw",
                "area_lights.visibility_accumulated",
                "area_lights.visibility_history_length",
                "area_lights.visibility_view_depth",
                "area_lights.visibility_filtered",
                "area_lights.denoised",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        );
        Self {
            ctx,
            denoiser,
            rt,
            view: hikari_render::view::View::new(&s.camera, w, h),
            w,
            h,
            depth,
            normal,
            motion,
        }
    }

    fn input<'a>(
        &'a self,
        normal_oct: &'a [[f32; 2]],
        shadowed: &'a [[f32; 4]],
        unshadowed: &'a [[f32; 4]],
    ) -> reference::DenoiseInput<'a> {
        reference::DenoiseInput {
            width: self.w,
            height: self.h,
            depth: &self.depth,
            normal_oct,
            motion: &self.motion,
            shadowed,
            unshadowed,
        }
    }

    fn oct(&self) -> Vec<[f32; 2]> {
        self.normal.iter().map(|n| [n[0], n[1]]).collect()
    }

    /// One frame of both passes on the GPU; the inputs are rounded to f16 as uploaded.
    fn frame(
        &mut self,
        params: &area_lights::ShadowDenoiseParams,
        shadowed: &[[f32; 4]],
        unshadowed: &[[f32; 4]],
    ) -> DenoiseOut {
        use wgpu::TextureFormat as F;
        let (w, h) = (self.w, self.h);
        let halves = |v: &[[f32; 4]]| -> Vec<u8> {
            let hs: Vec<half::f16> = v
                .iter()
                .flatten()
                .map(|x| half::f16::from_f32(*x))
                .collect();
            bytemuck::cast_slice(&hs).to_vec()
        };
        let tex = |f, d: &[u8]| common::texture_with_data(&self.ctx, f, w, h, d);
        let depth = tex(F::R32Float, bytemuck::cast_slice(&self.depth));
        let normal = tex(F::Rgba16Float, &halves(&self.normal));
        let motion = tex(F::Rgba16Float, &halves(&self.motion));
        let sh = tex(F::Rgba16Float, &halves(shadowed));
        let un = tex(F::Rgba16Float, &halves(unshadowed));
        let mut g = self.rt.begin_frame(&self.ctx);
        let inputs = area_lights::ShadowDenoiseInputs {
            depth: g.import_texture("test.depth", &depth),
            normal: g.import_texture("test.normal", &normal),
            motion: g.import_texture("test.motion", &motion),
            shadowed: g.import_texture("test.shadowed", &sh),
            unshadowed: g.import_texture("test.unshadowed", &un),
        };
        self.denoiser
            .record(&mut g, &self.view, params, &inputs, [w, h])
            .unwrap();
        let r = g.execute().unwrap();
        let img = |n: &str| r.image(n).unwrap().rgba.clone();
        let first = |n: &str| img(n).iter().map(|p| p[0]).collect::<Vec<f32>>();
        DenoiseOut {
            raw: img("area_lights.visibility_raw"),
            history: reference::VisibilityHistory {
                visibility: img("area_lights.visibility_accumulated"),
                length: first("area_lights.visibility_history_length"),
                view_depth: first("area_lights.visibility_view_depth"),
            },
            filtered: img("area_lights.visibility_filtered"),
            radiance: img("area_lights.denoised"),
        }
    }
}

/// A noisy penumbra: unshadowed light `u` on every surface pixel, true visibility a ramp from 0
/// (column 16) to 1 (column 40), and each frame's shadowed light u x k / 4 with k of 4 rays
/// passing (binomial), as the pass's ratio estimator gives with 4 rays.
fn true_visibility(x: u32) -> f32 {
    ((x as f32 + 0.5 - 16.0) / 24.0).clamp(0.0, 1.0)
}

const UNSHADOWED: [f32; 4] = [2.0, 1.5, 1.0, 3.0];

fn noisy_frame(rig: &DenoiseRig, rng: &mut impl rand::Rng) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (mut s, mut u) = (Vec::new(), Vec::new());
    for y in 0..rig.h {
        for x in 0..rig.w {
            let i = (y * rig.w + x) as usize;
            if rig.depth[i] <= 0.0 {
                s.push([0.0; 4]);
                u.push([0.0; 4]);
                continue;
            }
            let v = true_visibility(x);
            let k = (0..4).filter(|_| rng.random::<f32>() < v).count() as f32;
            s.push(UNSHADOWED.map(|c| c * k / 4.0));
            u.push(UNSHADOWED);
        }
    }
    (s, u)
}

fn assert_close4(what: &str, w: u32, gpu: &[[f32; 4]], cpu: &[[f32; 4]], rel: f32, abs: f32) {
    let mut bad = Vec::new();
    for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        for k in 0..4 {
            let tol = rel * c[k].abs() + abs;
            // Written so that NaN fails.
            let ok = (g[k] - c[k]).abs() <= tol;
            if !ok {
                bad.push((i as u32 % w, i as u32 / w, k, g[k], c[k]));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{what}: {} channels beyond tolerance, first {:?}",
        bad.len(),
        &bad[..bad.len().min(6)]
    );
}

/// Both passes against their CPU twins over 5 frames of a noisy penumbra (frame 3 a camera
/// cut), each pass fed what its GPU pass read (the temporal pass last frame's GPU history, the
/// spatial pass this frame's). Tolerance: f16 storage of the outputs (2^-11 relative) and f32
/// order of sums: 2e-3 relative + 2e-3 (visibility), 2e-3 relative + 1e-3 nits (light); the
/// history length and view depth exactly (f16 holds small integers; depth is copied).
#[test]
fn shadow_denoiser_passes_match_their_cpu_twins() {
    use rand::SeedableRng;
    let mut rig = DenoiseRig::new();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(18);
    let settings = area_lights::AreaLightsSettings::default();
    let oct = rig.oct();
    let mut prev: Option<reference::VisibilityHistory> = None;
    for frame in 0..5 {
        let cut = frame == 3;
        let params = area_lights::ShadowDenoiseParams::new(&settings, cut);
        if frame == 1 {
            // From here on a block moves by a fraction of a pixel: the bilinear reprojection.
            for y in 8..16 {
                for x in 8..16 {
                    let m = &mut rig.motion[(y * rig.w + x) as usize];
                    m[0] = 0.5;
                    m[1] = -0.25;
                }
            }
        }
        // Frame 1 records a wrong view depth in a few still pixels (as if they saw another
        // surface): on frame 2 their own texel fails the depth test and the 3x3 about it
        // stands in (SVGF's fallback), so they keep their history.
        let damaged: Vec<usize> = (3..6).map(|y| (y * rig.w + 40) as usize).collect();
        for &i in &damaged {
            match frame {
                1 => rig.motion[i][2] *= 3.0,
                2 => rig.motion[i][2] /= 3.0,
                _ => {}
            }
        }
        let (s, u) = noisy_frame(&rig, &mut rng);
        let out = rig.frame(&params, &s, &u);
        let (s16, u16): (Vec<_>, Vec<_>) = (
            s.iter().map(|v| f16r4(*v)).collect(),
            u.iter().map(|v| f16r4(*v)).collect(),
        );
        let input = rig.input(&oct, &s16, &u16);
        // The graph's first frame has no valid history: the GPU resets by itself.
        let mut p = params;
        if frame == 0 {
            p.config[0] |= area_lights::denoise::SHADOW_DENOISE_RESET;
        }
        let (raw, hist) = reference::denoise_temporal(&p, &rig.view, &input, prev.as_ref());
        let w = rig.w;
        assert_close4(&format!("frame {frame} raw"), w, &out.raw, &raw, 2e-3, 2e-3);
        assert_close4(
            &format!("frame {frame} accumulated"),
            w,
            &out.history.visibility,
            &hist.visibility,
            2e-3,
            2e-3,
        );
        assert_eq!(
            out.history.length, hist.length,
            "frame {frame} history length"
        );
        assert_eq!(
            out.history.view_depth, hist.view_depth,
            "frame {frame} view depth"
        );
        // Frames since the last reset (the first frame, the cut at frame 3).
        let expected_len = if frame >= 3 {
            frame as f32 - 2.0
        } else {
            frame as f32 + 1.0
        };
        let lit = out
            .history
            .length
            .iter()
            .filter(|&&l| l == expected_len)
            .count();
        assert!(
            lit > (w * rig.h) as usize / 2,
            "frame {frame}: {lit} pixels of length {expected_len}"
        );
        if frame == 2 {
            for &i in &damaged {
                assert_eq!(
                    out.history.length[i], 3.0,
                    "damaged pixel {i} lost its history"
                );
            }
        }
        let (filtered, light) = reference::denoise_spatial(&p, &rig.view, &input, &out.history);
        assert_close4(
            &format!("frame {frame} filtered"),
            w,
            &out.filtered,
            &filtered,
            2e-3,
            2e-3,
        );
        assert_close4(
            &format!("frame {frame} light"),
            w,
            &out.radiance,
            &light,
            2e-3,
            1e-3,
        );
        prev = Some(out.history);
    }
}

/// The denoised penumbra's noise drops and its mean stays. Against the exact answer (the ramp
/// times the unshadowed light, which the noisy input averages to):
/// - frame 0 (the spatial filter alone, radius 3 px): the variance over each column's rows
///   (one true value a column), summed over the penumbra's columns, is under 0.3 of the raw
///   input's;
/// - frames 32-63 (history at its cap of 16, the spatial radius 3 / 4 px: the pixel alone): the
///   mean square error against the exact value, pooled over the penumbra's pixels and frames, is
///   under 0.1 of the raw input's (an exponential average of weight 1/16 leaves 1/31);
/// - bias: the mean over those frames and the penumbra's pixels is within 0.01 x the unshadowed
///   light of the exact mean, each column's within 0.05 (about 3 and 4 standard errors: the
///   history's frames are correlated, about one independent sample per 31 frames).
#[test]
fn denoised_penumbra_noise_drops_and_its_mean_stays() {
    use rand::SeedableRng;
    let mut rig = DenoiseRig::new();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    let settings = area_lights::AreaLightsSettings::default();
    let params = area_lights::ShadowDenoiseParams::new(&settings, false);
    let (w, h) = (rig.w, rig.h);
    // Rows of the floor's own normal and depth (the band and the right quarter aside).
    let plain = |x: u32, y: u32| x < 48 && !(6..9).contains(&y);
    let light = UNSHADOWED[1] as f64;
    let frames = 64;
    let (mut mse, mut mse_raw, mut count) = (0f64, 0f64, 0f64);
    let mut columns = vec![(0f64, 0f64); w as usize];
    for frame in 0..frames {
        let (s, u) = noisy_frame(&rig, &mut rng);
        let out = rig.frame(&params, &s, &u);
        if frame == 0 {
            let (mut var_raw, mut var_out) = (0.0, 0.0);
            for x in 18..38 {
                let column = |v: &dyn Fn(u32) -> f32| {
                    let vals: Vec<f32> = (0..h).filter(|&y| plain(x, y)).map(v).collect();
                    let m = vals.iter().sum::<f32>() / vals.len() as f32;
                    vals.iter().map(|a| (a - m) * (a - m)).sum::<f32>() / vals.len() as f32
                };
                var_raw += column(&|y| s[(y * w + x) as usize][1]);
                var_out += column(&|y| out.radiance[(y * w + x) as usize][1]);
            }
            println!("frame 0: row variance {var_out} denoised, {var_raw} raw");
            assert!(var_out < 0.3 * var_raw, "{var_out} vs {var_raw}");
        }
        if frame >= frames / 2 {
            for x in 20..36 {
                let exact = true_visibility(x) as f64 * light;
                for y in (0..h).filter(|&y| plain(x, y)) {
                    let i = (y * w + x) as usize;
                    let (a, b) = (out.radiance[i][1] as f64, s[i][1] as f64);
                    mse += (a - exact).powi(2);
                    mse_raw += (b - exact).powi(2);
                    count += 1.0;
                    columns[x as usize].0 += a - exact;
                    columns[x as usize].1 += 1.0;
                }
            }
        }
    }
    let ratio = mse / mse_raw;
    let bias = columns.iter().map(|c| c.0).sum::<f64>() / count / light;
    let worst = columns
        .iter()
        .filter(|c| c.1 > 0.0)
        .map(|c| (c.0 / c.1 / light).abs())
        .fold(0.0, f64::max);
    println!("frames 32-63: error ratio {ratio}, bias {bias}, worst column {worst} of the light");
    assert!(ratio < 0.1, "mean square error {mse} vs raw {mse_raw}");
    assert!(bias.abs() < 0.01, "bias {bias}");
    assert!(worst < 0.05, "worst column bias {worst}");
}

/// NaN and infinity in any input (shadowed and unshadowed light, depth, normal, motion) never
/// reach the history or the output: every texel of every output is finite over 4 frames, and
/// pixels 4 or more pixels away from the poisoned ones (beyond the filter's reach of 3) match a
/// clean run's.
#[test]
fn nan_in_the_denoisers_inputs_never_reaches_its_outputs() {
    use rand::SeedableRng;
    let settings = area_lights::AreaLightsSettings::default();
    let params = area_lights::ShadowDenoiseParams::new(&settings, false);
    let poisoned = [(20u32, 4u32), (30, 10), (25, 13), (40, 2), (10, 8)];
    let run = |poison: bool| {
        let mut rig = DenoiseRig::new();
        let mut rng = rand::rngs::SmallRng::seed_from_u64(3);
        let w = rig.w;
        if poison {
            let idx = |(x, y): (u32, u32)| (y * w + x) as usize;
            rig.depth[idx(poisoned[2])] = f32::NAN;
            rig.normal[idx(poisoned[3])] = [f32::NAN, 0.0, 0.0, 0.0];
            rig.motion[idx(poisoned[4])] = [f32::INFINITY, 0.0, f32::NAN, 0.0];
        }
        let mut outs = Vec::new();
        for _ in 0..4 {
            let (mut s, mut u) = noisy_frame(&rig, &mut rng);
            if poison {
                s[(poisoned[0].1 * w + poisoned[0].0) as usize] =
                    [f32::NAN, f32::INFINITY, 1.0, f32::NAN];
                u[(poisoned[1].1 * w + poisoned[1].0) as usize] =
                    [f32::INFINITY, f32::NAN, 1.0, -f32::INFINITY];
            }
            outs.push(rig.frame(&params, &s, &u));
        }
        (w, outs)
    };
    let (w, bad) = run(true);
    let (_, clean) = run(false);
    for (f, (b, c)) in bad.iter().zip(&clean).enumerate() {
        let images = [
            ("accumulated", &b.history.visibility, &c.history.visibility),
            ("filtered", &b.filtered, &c.filtered),
            ("light", &b.radiance, &c.radiance),
        ];
        for (what, bi, ci) in images {
            for (i, (p, q)) in bi.iter().zip(ci.iter()).enumerate() {
                let (x, y) = (i as u32 % w, i as u32 / w);
                assert!(
                    p.iter().all(|v| v.is_finite()),
                    "frame {f} {what} ({x}, {y}): {p:?}"
                );
                let far = poisoned
                    .iter()
                    .all(|&(px, py)| px.abs_diff(x).max(py.abs_diff(y)) >= 4);
                if far {
                    assert_eq!(
                        p, q,
                        "frame {f} {what} ({x}, {y}) changed by a poisoned pixel"
                    );
                }
            }
        }
        assert!(b.history.length.iter().all(|l| l.is_finite()));
    }
}

/// The denoiser in the frame: its history grows one frame at a time on a still view, and a
/// camera cut or a resize starts it again (length 1 on every surface pixel); with `denoise` off
/// it does not run and the deferred lighting adds the raw light.
#[test]
fn the_frames_shadow_history_grows_and_resets_on_a_cut_or_a_resize() {
    let scene = point_light_scene(true);
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut lengths = |s: &FrameSettings| -> Vec<f32> {
        let mut r = renderer
            .render_reading(s, |o| {
                let d = o.area_lights_denoised.expect("the denoiser runs");
                vec![d.history_length.into(), o.gbuffer.depth.into()]
            })
            .unwrap();
        let depth = r.take_image("gbuffer.depth").unwrap().rgba;
        let len = r
            .take_image("area_lights.visibility_history_length")
            .unwrap()
            .rgba;
        len.iter()
            .zip(&depth)
            .filter(|(_, d)| d[0] > 0.0)
            .map(|(l, _)| l[0])
            .collect()
    };
    let all = |v: &[f32], want: f32| !v.is_empty() && v.iter().all(|&l| l == want);
    let still = common::small_frame_settings(&scene, 32, 16);
    for frame in 1..=3 {
        let l = lengths(&still);
        assert!(all(&l, frame as f32), "still frame {frame}: {l:?}");
    }
    // A cut: another camera that claims it did not move.
    let mut cut = still.clone();
    cut.camera.position += Vec3::new(0.05, 0.0, 0.0);
    cut.camera.target += Vec3::new(0.05, 0.0, 0.0);
    let l = lengths(&cut);
    assert!(all(&l, 1.0), "after a cut: {l:?}");
    assert!(all(&lengths(&cut), 2.0));
    let mut resized = cut.clone();
    resized.width = 24;
    let l = lengths(&resized);
    assert!(all(&l, 1.0), "after a resize: {l:?}");

    // Off: no denoiser, and the frame's radiance is the raw pass's.
    let mut off = still.clone();
    off.settings.area_lights.denoise = false;
    renderer
        .render_reading(&off, |o| {
            assert!(o.area_lights_denoised.is_none());
            vec![]
        })
        .unwrap();
}
