//! Exposure: the meter and the adaptation against their CPU twin, adaptation speeds over
//! frames, nights and a 10 EV interior-exterior gap, and the talk's reason for metering
//! illuminance: black and white albedo under the same light get the same exposure.

use crate::common;

use glam::Vec3;
use hikari_render::graph::{FrameResult, GraphRuntime};
use hikari_render::shader;
use hikari_render::techniques::exposure::reference::{self, HISTOGRAM_BINS};
use hikari_render::techniques::exposure::{Exposure, ExposureParams, ExposureSettings};
use hikari_render::{GpuContext, Renderer};
use rand::{Rng, SeedableRng, rngs::SmallRng};

// Not a multiple of the meter's 64x64 workgroup, so that its partial edges are checked.
const SIZE: u32 = 72;

struct Rig {
    ctx: GpuContext,
    exposure: Exposure,
    rt: GraphRuntime,
}

impl Rig {
    fn new() -> Self {
        let ctx = common::gpu_context();
        let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
        let exposure = Exposure::new(&ctx, &mut lib).unwrap();
        Self {
            ctx,
            exposure,
            rt: GraphRuntime::new(),
        }
    }

    /// One accepted frame over `radiance` (f16 on the GPU) and `illuminance`.
    fn frame(
        &mut self,
        radiance: &[[f32; 3]],
        illuminance: &[f32],
        p: &ExposureParams,
    ) -> FrameResult {
        self.frame_sized(radiance, [SIZE, SIZE], illuminance, [SIZE, SIZE], p)
    }

    /// [`Rig::frame`] with the radiance at the output's size and the illuminance at the
    /// render's, as below render scale 1.
    fn frame_sized(
        &mut self,
        radiance: &[[f32; 3]],
        [rw, rh]: [u32; 2],
        illuminance: &[f32],
        [w, h]: [u32; 2],
        p: &ExposureParams,
    ) -> FrameResult {
        let halves: Vec<half::f16> = radiance
            .iter()
            .flat_map(|c| [c[0], c[1], c[2], 1.0].map(half::f16::from_f32))
            .collect();
        let hdr = common::texture_with_data(
            &self.ctx,
            wgpu::TextureFormat::Rgba16Float,
            rw,
            rh,
            bytemuck::cast_slice(&halves),
        );
        let lux = common::texture_with_data(
            &self.ctx,
            wgpu::TextureFormat::R32Float,
            w,
            h,
            bytemuck::cast_slice(illuminance),
        );
        let mut g = self.rt.begin_frame(&self.ctx);
        let hdr = g.import_texture("test.hdr", &hdr);
        let lux = g.import_texture("test.illuminance", &lux);
        let out = self.exposure.record(&mut g, hdr, lux, [w, h], p).unwrap();
        g.readback(out.value);
        if let Some(h) = out.histogram {
            g.readback(h);
        }
        g.execute().unwrap()
    }
}

fn value(r: &FrameResult) -> [f32; 4] {
    bytemuck::cast_slice::<u8, f32>(r.buffer("exposure.value").unwrap())
        .try_into()
        .unwrap()
}

/// Grey surfaces of albedo 0.18 under `lux`, as the twin and the GPU will see them (f16).
fn grey_under(lux: &[f32]) -> Vec<[f32; 3]> {
    lux.iter()
        .map(|&e| [half::f16::from_f32(0.18 * e.max(0.0) / std::f32::consts::PI).to_f32(); 3])
        .collect()
}

/// Random radiance and illuminance over the whole range (a tenth of the pixels sky, one NaN):
/// the GPU's histograms equal the twin's but for pixels whose log2 lands within rounding of a
/// bin edge (at most 4 of 10368 counts), and its value is the twin's from the same histograms
/// to 1e-5 relative.
#[test]
fn meter_and_adapt_match_the_twin() {
    let mut rng = SmallRng::seed_from_u64(19);
    let n = (SIZE * SIZE) as usize;
    let radiance: Vec<[f32; 3]> = (0..n)
        .map(|_| {
            std::array::from_fn(|_| {
                half::f16::from_f32(10f32.powf(rng.random_range(-4.0..5.0))).to_f32()
            })
        })
        .collect();
    let mut illuminance: Vec<f32> = (0..n)
        .map(|_| 10f32.powf(rng.random_range(-3.0..5.5)))
        .collect();
    for e in illuminance.iter_mut().step_by(10) {
        *e = -1.0;
    }
    illuminance[1] = f32::NAN;
    let p = ExposureParams::new(&ExposureSettings::default(), 0.0, 0.0);
    let mut rig = Rig::new();
    let r = rig.frame(&radiance, &illuminance, &p);
    let gpu_bins: Vec<u32> = bytemuck::cast_slice(r.buffer("exposure.histogram").unwrap()).to_vec();
    let cpu_bins = reference::meter(&radiance, &illuminance, &p);
    assert_eq!(gpu_bins.len(), 2 * HISTOGRAM_BINS);
    let moved: i64 = gpu_bins
        .iter()
        .zip(&cpu_bins)
        .map(|(&a, &b)| (a as i64 - b as i64).abs())
        .sum();
    assert!(
        moved <= 8,
        "{moved} counts differ (4 pixels may move a bin each)"
    );
    let want = reference::value(&gpu_bins, None, &p);
    let got = value(&r);
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() <= 1e-5 * w.abs().max(1.0),
            "value {got:?} vs twin {want:?}"
        );
    }
}

/// Below render scale 1 the illuminance is the render's size and the radiance the output's:
/// both histograms count the render's pixels, the luminance one at the output pixel each maps
/// to, as the twin does.
#[test]
fn the_meter_counts_the_renders_pixels_below_render_scale_one() {
    let mut rng = SmallRng::seed_from_u64(23);
    let (out, render) = ([SIZE, SIZE], [SIZE / 2 + 1, SIZE * 2 / 3]);
    let radiance: Vec<[f32; 3]> = (0..out[0] * out[1])
        .map(|_| {
            std::array::from_fn(|_| {
                half::f16::from_f32(10f32.powf(rng.random_range(-4.0..5.0))).to_f32()
            })
        })
        .collect();
    let illuminance: Vec<f32> = (0..render[0] * render[1])
        .map(|_| 10f32.powf(rng.random_range(-3.0..5.5)))
        .collect();
    let p = ExposureParams::new(&ExposureSettings::default(), 0.0, 0.0);
    let r = Rig::new().frame_sized(&radiance, out, &illuminance, render, &p);
    let gpu: Vec<u32> = bytemuck::cast_slice(r.buffer("exposure.histogram").unwrap()).to_vec();
    let cpu = reference::meter_scaled(&radiance, out, &illuminance, render, &p);
    let pixels = render[0] * render[1];
    assert_eq!(gpu[HISTOGRAM_BINS..].iter().sum::<u32>(), pixels);
    let moved: i64 = gpu
        .iter()
        .zip(&cpu)
        .map(|(&a, &b)| (a as i64 - b as i64).abs())
        .sum();
    assert!(moved <= 8, "{moved} counts differ from the twin");
}

/// A scene that turns 10 EV brighter, then back: EV100 rises at `adapt_up_ev_per_s` and
/// falls at `adapt_down_ev_per_s` times the frame time; a first frame and `frame_seconds` 0
/// snap; a fixed EV100 overrides.
#[test]
fn adaptation_moves_at_its_speeds() {
    let n = (SIZE * SIZE) as usize;
    let dim = vec![100.0f32; n];
    let bright = vec![100.0 * 1024.0f32; n];
    let mut s = ExposureSettings {
        frame_seconds: 0.5,
        highlights: false,
        ..Default::default()
    };
    let p = ExposureParams::new(&s, 0.0, 0.0);
    let mut rig = Rig::new();
    let ev0 = value(&rig.frame(&grey_under(&dim), &dim, &p))[1];
    // Snapped to the incident-meter rule, within half a bin (1/8 EV).
    assert!((ev0 - (100f32 / 2.5).log2()).abs() <= 0.125 + 1e-4, "{ev0}");
    let ev1 = value(&rig.frame(&grey_under(&bright), &bright, &p))[1];
    assert!((ev1 - (ev0 + 3.0 * 0.5)).abs() < 1e-4, "up: {ev0} -> {ev1}");
    let ev2 = value(&rig.frame(&grey_under(&bright), &bright, &p))[1];
    assert!((ev2 - (ev1 + 1.5)).abs() < 1e-4, "up again: {ev1} -> {ev2}");
    let ev3 = value(&rig.frame(&grey_under(&dim), &dim, &p))[1];
    assert!(
        (ev3 - (ev2 - 1.0 * 0.5)).abs() < 1e-4,
        "down: {ev2} -> {ev3}"
    );
    s.frame_seconds = 0.0;
    let ev4 = value(&rig.frame(&grey_under(&dim), &dim, &ExposureParams::new(&s, 0.0, 0.0)))[1];
    assert!((ev4 - ev0).abs() < 1e-5, "snap: {ev4} vs {ev0}");
    s.ev100 = Some(2.5);
    let v = value(&rig.frame(&grey_under(&dim), &dim, &ExposureParams::new(&s, 0.0, 0.0)));
    assert_eq!(v[1], 2.5);
    assert!((v[0] - 1.0 / (1.2 * 2f32.powf(2.5))).abs() < 1e-7);
}

/// A 0.05 lux night meters to EV100 log2(0.05 / 2.5) = -5.6 (no floor); an interior of 20 lux
/// with a door onto 20000 lux (10 EV) meters between the two, and the exposure follows
/// compensation one for one.
#[test]
fn nights_and_a_ten_ev_gap() {
    let n = (SIZE * SIZE) as usize;
    let s = ExposureSettings {
        highlights: false,
        ..Default::default()
    };
    let mut rig = Rig::new();
    let night = vec![0.05f32; n];
    let ev = value(&rig.frame(
        &grey_under(&night),
        &night,
        &ExposureParams::new(&s, 0.0, 0.0),
    ))[1];
    assert!(
        (ev - (0.05f32 / 2.5).log2()).abs() <= 0.125 + 1e-4,
        "night: {ev}"
    );

    let gap: Vec<f32> = (0..n)
        .map(|i| {
            if i % SIZE as usize >= 54 {
                20_000.0
            } else {
                20.0
            }
        })
        .collect();
    let comp = ExposureSettings {
        compensation_ev: 1.0,
        ..s.clone()
    };
    let a = value(&rig.frame(&grey_under(&gap), &gap, &ExposureParams::new(&s, 0.0, 0.0)))[1];
    let b = value(&rig.frame(
        &grey_under(&gap),
        &gap,
        &ExposureParams::new(&comp, 0.0, 0.0),
    ))[1];
    let (inside, outside) = ((20f32 / 2.5).log2(), (20_000f32 / 2.5).log2());
    assert!(a > inside && a < outside, "{inside} < {a} < {outside}");
    assert!((a - b - 1.0).abs() < 1e-5, "compensation: {a} -> {b}");
}

/// The talk's reason for an illuminance meter: the boxes scene with every surface white
/// (albedo 0.9) and with every surface black (0.03) under the same sun and sky gets the same
/// exposure, though its mean luminance differs by about 5 EV.
#[test]
fn black_and_white_albedo_get_the_same_exposure() {
    let render = |albedo: f32| {
        let mut scene = hikari_scene::builtin::boxes();
        for m in &mut scene.materials {
            m.base_color = Vec3::splat(albedo);
            m.metalness = 0.0;
            m.emissive_nits = Vec3::ZERO;
        }
        let settings = common::small_frame_settings(&scene, 96, 64);
        let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
        let mut r = renderer
            .render_reading(&settings, |o| {
                vec![o.exposure.value.into(), o.lit.into(), o.illuminance.into()]
            })
            .unwrap();
        let hdr = r.take_image("direct_lighting.radiance").unwrap();
        let lux = r.take_image("direct_lighting.illuminance").unwrap();
        let mean_log2_luminance = hdr
            .rgba
            .iter()
            .map(|c| reference::luminance([c[0], c[1], c[2]]).max(1e-6).log2())
            .sum::<f32>()
            / hdr.rgba.len() as f32;
        (value(&r), mean_log2_luminance, lux.rgba)
    };
    let (white, white_l, white_lux) = render(0.9);
    let (black, black_l, black_lux) = render(0.03);
    // The meter's input itself does not see albedo: the same lux at every pixel (to f32
    // rounding), the sky (-1) in the same places.
    let surface = white_lux.iter().filter(|p| p[0] >= 0.0).count();
    assert!(surface > white_lux.len() / 2, "{surface} surface pixels");
    for (w, b) in white_lux.iter().zip(&black_lux) {
        assert!(
            (w[0] - b[0]).abs() <= 1e-5 * w[0].abs().max(1.0),
            "{} vs {} lux",
            w[0],
            b[0]
        );
    }
    assert!(
        white_l - black_l > 2.0,
        "the albedo changes the image: {white_l} vs {black_l}"
    );
    assert!(
        (white[1] - black[1]).abs() < 1e-3,
        "EV100 {} (white) vs {} (black)",
        white[1],
        black[1]
    );
    assert!(white[2] > 0.0 && white[2].is_finite());
}

/// An interactive renderer adapts over the wall-clock time between frames: after the target
/// falls by 3 EV (compensation +3), the exposure falls by `adapt_down_ev_per_s` times the time
/// since the previous frame began (bounded by what this test measures around the calls), not
/// all the way; an offline renderer (`frame_seconds` 0) snaps to the new target.
#[test]
fn interactive_frames_adapt_over_their_wall_clock_time() {
    use std::time::{Duration, Instant};
    let scene = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&scene, 64, 40);
    s.settings.taa.enabled = false;
    let speed = s.settings.exposure.adapt_down_ev_per_s;
    let ev = |r: &mut Renderer, s: &hikari_render::FrameSettings| {
        value(
            &r.render_reading(s, |o| vec![o.exposure.value.into()])
                .unwrap(),
        )[1]
    };
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    renderer.set_interactive(true);
    let target = ev(&mut renderer, &s);
    let a = Instant::now();
    assert!(
        (ev(&mut renderer, &s) - target).abs() < 1e-4,
        "a still target holds"
    );
    let b = Instant::now();
    std::thread::sleep(Duration::from_millis(400));
    s.settings.exposure.compensation_ev = 3.0;
    let c = Instant::now();
    let moved = target - ev(&mut renderer, &s);
    let d = Instant::now();
    let (least, most) = ((c - b).as_secs_f32() * speed, (d - a).as_secs_f32() * speed);
    assert!(
        moved >= least - 1e-3 && moved <= most.min(3.0) + 1e-3,
        "fell {moved} EV, expected {least} to {most}"
    );
    assert!(moved < 3.0 - 1e-3 || most >= 3.0, "snapped: {moved}");

    let mut offline = Renderer::new(common::gpu_context(), &scene).unwrap();
    let snapped = ev(&mut offline, &s);
    assert!(
        (target - snapped - 3.0).abs() < 1e-4,
        "{target} -> {snapped}"
    );
}
