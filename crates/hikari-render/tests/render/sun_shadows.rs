//! The sun's shadow maps: what the compute rasteriser draws into them against rays from the
//! sun, and scrolled maps against a full redraw.

use crate::common;

use glam::{Vec3, Vec4};
use hikari_bvh::reference::closest_hit_instances;
use hikari_bvh::{Instance, Mesh, Ray};
use hikari_render::techniques::sun_shadows;
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::Scene;

fn bvh_scene(scene: &Scene) -> (Vec<Mesh>, Vec<Instance>) {
    (
        hikari_render::scene::bvh::meshes(scene),
        hikari_render::scene::bvh::instances(scene),
    )
}

fn frame_settings(scene: &Scene, w: u32, h: u32) -> FrameSettings {
    common::small_frame_settings(scene, w, h)
}

/// The shadow maps' texels against the reverse-Z depths of rays from the sun through the
/// same texel centres (as stored: scrolled by each cascade's origin), and how many the rays
/// see a surface through.
#[derive(Debug)]
struct Agreement {
    agree: usize,
    differ: usize,
    covered: usize,
}

impl Agreement {
    fn of(texels: &[f32], want: &[f32]) -> Self {
        let differ = texels
            .iter()
            .zip(want)
            .filter(|(g, w)| (*g - *w).abs() > 1e-5)
            .count();
        Self {
            agree: want.len() - differ,
            differ,
            covered: want.iter().filter(|&&w| w > 0.0).count(),
        }
    }

    fn check(&self) -> Result<(), String> {
        let allowed = common::allowed_differences(self.agree + self.differ);
        if self.covered <= 1000 {
            return Err(format!("the maps see too little: {self:?}"));
        }
        if self.differ > allowed {
            return Err(format!(
                "{} texels differ from the rays (allowed {allowed}), {} agree",
                self.differ, self.agree
            ));
        }
        Ok(())
    }
}

#[test]
fn shadow_maps_match_rays_from_the_sun() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let s = frame_settings(&scene, 64, 48);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let r = renderer
        .render_reading(&s, |out| vec![out.shadows.texels.into()])
        .unwrap();
    let texels: &[f32] = bytemuck::cast_slice(r.buffer("sun_shadows.texels").unwrap());
    let sun = scene.sun.clone().unwrap();
    let cascades = sun_shadows::fit_cascades(
        &s.camera,
        64.0 / 48.0,
        sun.direction,
        renderer.scene().bounds.unwrap(),
        &s.settings.sun_shadows,
    );
    let (meshes, instances) = bvh_scene(&scene);
    let res = s.settings.sun_shadows.resolution;
    // What the rays see, stored where the maps store it.
    let mut want = vec![0f32; texels.len()];
    for (c, cascade) in cascades.iter().enumerate() {
        // The maps scroll: texel (x, y) is stored at (x, y) + origin, wrapped.
        let [ox, oy] = cascade.origin(res);
        let inv = cascade.view_proj.inverse();
        let vp = cascade.view_proj;
        for y in 0..res {
            for x in 0..res {
                let ndc = |z: f32| {
                    let u = (x as f32 + 0.5) / res as f32;
                    let v = (y as f32 + 0.5) / res as f32;
                    let p = inv * Vec4::new(u * 2.0 - 1.0, 1.0 - v * 2.0, z, 1.0);
                    p.truncate() / p.w
                };
                let (from, to) = (ndc(1.0), ndc(0.0));
                let dir = (to - from).normalize();
                let ray = Ray::new(from, dir, 0.0, (to - from).length());
                let at = ((y + oy) % res) * res + (x + ox) % res;
                want[(c as u32 * res * res + at) as usize] =
                    closest_hit_instances(&meshes, &instances, None, &ray)
                        .map(|h| (vp * (from + dir * h.t).extend(1.0)).z)
                        .unwrap_or(0.0);
            }
        }
    }
    let agreement = Agreement::of(texels, &want);
    eprintln!("{agreement:?}");
    agreement.check().unwrap();

    // The same maps with one 32x32 block of covered texels lost (as a tile the rasteriser
    // dropped leaves it: cleared to 0) must fail the same comparison.
    let res = res as usize;
    let block = (0..want.len() / (res * res))
        .flat_map(|c| (0..res / 32).flat_map(move |by| (0..res / 32).map(move |bx| (c, bx, by))))
        .find(|&(c, bx, by)| {
            (0..32 * 32)
                .all(|k| want[c * res * res + (by * 32 + k / 32) * res + bx * 32 + k % 32] > 0.0)
        })
        .expect("a 32x32 block of texels the rays all see a surface through");
    let mut damaged = texels.to_vec();
    let (c, bx, by) = block;
    for k in 0..32 * 32 {
        damaged[c * res * res + (by * 32 + k / 32) * res + bx * 32 + k % 32] = 0.0;
    }
    let lost = Agreement::of(&damaged, &want);
    assert!(
        lost.check().is_err(),
        "block {block:?} dropped, yet the comparison passes: {lost:?}"
    );
}

#[test]
fn scrolled_shadow_maps_hold_what_a_full_redraw_draws() {
    let scene = hikari_scene::builtin::boxes();
    let mut first = frame_settings(&scene, 96, 64);
    // The two renderers are at different frame indices, so TAA would jitter them differently.
    first.settings.taa.enabled = false;
    // Moves of a few texels in each cascade, in x, y and both.
    let path = [
        Vec3::new(0.37, 0.05, -0.21),
        Vec3::new(0.61, 0.02, -0.05),
        Vec3::new(0.2, -0.11, 0.43),
    ];
    let drew = |r: &hikari_render::graph::FrameResult, pass: &str| {
        r.timings.iter().any(|t| t.name == pass)
    };
    let texels = |r: &hikari_render::graph::FrameResult| -> Vec<f32> {
        bytemuck::cast_slice(r.buffer("sun_shadows.texels").unwrap()).to_vec()
    };
    let read = |out: &hikari_render::frame::FrameOutputs| {
        vec![
            out.shadows.texels.into(),
            out.shadows.map.into(),
            out.lit.into(),
        ]
    };

    let ctx = common::gpu_context();
    let mut scrolled = Renderer::new(ctx, &scene).unwrap();
    let mut fresh = Renderer::new(common::gpu_context(), &scene).unwrap();
    let a = scrolled.render_reading(&first, read).unwrap();
    assert!(drew(&a, "sun_shadows.rasterize"), "new maps are drawn");
    assert!(
        !drew(&a, "sun_shadows.clear_windows"),
        "new maps are drawn whole"
    );
    let res = first.settings.sun_shadows.resolution as usize;
    for (step, offset) in path.iter().enumerate() {
        let mut moved = first.clone();
        moved.camera.position += *offset;
        moved.camera.target += *offset;
        let got = scrolled.render_reading(&moved, read).unwrap();
        assert!(
            drew(&got, "sun_shadows.clear_windows"),
            "step {step}: a moved view draws strips"
        );
        let mut whole = moved.clone();
        whole.settings.sun_shadows.cache = false;
        let want = fresh.render_reading(&whole, read).unwrap();
        // The lit images, through the copies into the lookup's layers and its wrap-around:
        // equal but where a flipped texel or a depth within rounding of a receiver's changes
        // one PCF tap.
        let hdr = |r: &hikari_render::graph::FrameResult| {
            r.image("direct_lighting.radiance").unwrap().rgba.clone()
        };
        let (got_hdr, want_hdr) = (hdr(&got), hdr(&want));
        let off = got_hdr
            .iter()
            .zip(&want_hdr)
            .filter(|(g, w)| (0..3).any(|c| (g[c] - w[c]).abs() > 0.01 * w[c].abs() + 1e-3))
            .count();
        // 0.5 % of the 96x64 image is 30 pixels: a lost 32x32 tile (1024) is far beyond it.
        assert!(
            off * 200 <= got_hdr.len(),
            "step {step}: {off} pixels differ"
        );
        // Texels kept from earlier frames were projected with the earlier centre: the same
        // depths up to rounding, and a texel centre within rounding of an edge may flip.
        // The lookup's layers hold what the buffer holds, texel for texel (the strips copied
        // through the wrap-around). Read back as f32 of the u32 bits: equal bits, equal value.
        let map = got.image("sun_shadows.map").unwrap();
        let buffer = texels(&got);
        let stale = buffer
            .iter()
            .zip(&map.rgba)
            .filter(|(b, m)| b.to_bits() as f32 != m[0])
            .count();
        assert_eq!(stale, 0, "step {step}: layers differ from the buffer");
        let (got, want) = (buffer, texels(&want));
        let (mut flipped, mut worst) = (0, 0f32);
        for (g, w) in got.iter().zip(&want) {
            if (*g == 0.0) != (*w == 0.0) {
                flipped += 1;
            } else {
                worst = worst.max((g - w).abs());
            }
        }
        // 0.1 % of two 256x256 maps is 131 texels, well under a lost 32x32 block (1024).
        assert!(
            flipped * 1000 <= got.len(),
            "step {step}: {flipped} texels flipped"
        );
        // Against the lookup's depth bias (which a difference must stay well inside).
        let sun = scene.sun.clone().unwrap();
        let shadows = &moved.settings.sun_shadows;
        let bounds = scrolled.scene().bounds.unwrap();
        let cascades =
            sun_shadows::fit_cascades(&moved.camera, 1.5, sun.direction, bounds, shadows);
        let range = sun_shadows::depth_range(sun.direction, bounds);
        let params = sun_shadows::ShadowParams::new(&cascades, range, shadows);
        let bias = params.depth_bias[..cascades.len()]
            .iter()
            .copied()
            .fold(f32::MAX, f32::min);
        assert!(
            worst < 0.05 * bias,
            "step {step}: depths differ by {worst}, the smallest depth bias is {bias}"
        );
        assert!(got.len() >= 2 * res * res && got.iter().any(|&d| d > 0.0));
    }
    // A still view draws nothing.
    let mut last = first.clone();
    last.camera.position += path[2];
    last.camera.target += path[2];
    let still = scrolled.render_reading(&last, read).unwrap();
    assert!(
        !drew(&still, "sun_shadows.rasterize"),
        "a still view keeps its maps"
    );
}

#[test]
fn a_sun_turned_less_than_the_hold_keeps_the_cached_maps() {
    use hikari_render::techniques::sun_shadows::{
        HELD_SUN_DEG, HOLD_CASTER_M, ShadowCache, hold_deg,
    };
    let s = hikari_render::techniques::sun_shadows::settings::SunShadowsSettings::default();
    assert!(s.cache, "the hold applies with caching on, the default");
    let a = glam::Vec3::new(0.3, 0.8, 0.2).normalize();
    let axis = a.cross(glam::Vec3::X).normalize();
    let turned = |deg: f32| glam::Quat::from_axis_angle(axis, deg.to_radians()) * a;
    let hold = HELD_SUN_DEG;
    let mut cache = ShadowCache::default();
    assert_eq!(cache.held_sun(0, a, hold, &s), a);
    // Below the hold the cascade keeps the direction it was drawn for...
    assert_eq!(cache.held_sun(0, turned(0.5 * hold), hold, &s), a);
    assert_eq!(cache.held_sun(0, turned(0.9 * hold), hold, &s), a);
    // ...past it, it follows the sun, and holds from there.
    let past = turned(1.5 * hold);
    assert!((cache.held_sun(0, past, hold, &s) - past).length() < 1e-6);
    assert!((cache.held_sun(0, turned(1.6 * hold), hold, &s) - past).length() < 1e-6);
    // Each cascade holds its own: a coarse one (a longer hold) keeps what it was drawn for
    // where the fine one above moved on.
    let coarse = hold_deg(0.5);
    assert_eq!(cache.held_sun(3, a, coarse, &s), a);
    assert_eq!(cache.held_sun(3, turned(1.6 * hold), coarse, &s), a);
    // Without caching every frame draws for the sun as it is.
    let uncached =
        hikari_render::techniques::sun_shadows::settings::SunShadowsSettings { cache: false, ..s };
    let b = turned(0.5 * hold);
    assert!((cache.held_sun(0, b, hold, &uncached) - b).length() < 1e-6);
    // The hold: at least a tenth of a degree, and the turn that moves a 10 m caster's shadow
    // by half a texel where texels are coarse.
    assert_eq!(hold_deg(0.005), HELD_SUN_DEG);
    let half_texel = HOLD_CASTER_M * hold_deg(0.5).to_radians().tan();
    assert!((half_texel - 0.25).abs() < 1e-4, "{half_texel}");
    assert!(hold_deg(0.5) > 1.0 && hold_deg(0.5) < 2.0);
}
