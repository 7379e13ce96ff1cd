//! Snapshot images of every built-in scene at 128x72, compared with the committed PNGs under
//! `tests/snapshots/` by NVIDIA's FLIP, on two statistics of its per-pixel error map: the mean
//! over the image (a change everywhere: exposure, the sun, a material of most surfaces) and
//! the worst mean over 8x8 blocks (a change in one place: a lost tile, a missing lamp, one
//! wrong material). `damaged_snapshots_fail` checks that each damage of that kind, done to
//! the committed images themselves, fails these thresholds; the GPU tests check that the
//! real renders pass them.
//!
//! Re-baselining, when a change of the renderer moves an image on purpose:
//! 1. run `HIKARI_UPDATE_SNAPSHOTS=1 cargo test -p hikari-render --test snapshots` (with the
//!    GPU environment of the other GPU tests) and only for the snapshots whose change you
//!    understand (`-- village cornell`, ...); it writes the new PNGs and fails nothing;
//! 2. look at each new PNG beside the old one (`git diff` shows both in most viewers) and
//!    say in the commit message what changed and why;
//! 3. run the tests again without the variable: the real renders pass, and
//!    `damaged_snapshots_fail` still finds every damage in the new images (an image too dark
//!    or too flat to show damage fails there, and must be made meaningful, not re-baselined).

use crate::common;

use std::path::PathBuf;

use glam::Vec3;
use hikari_render::{FrameSettings, Renderer, Settings};

/// Mean FLIP error allowed over the image: driver rounding stays far below it (about 0.001).
const MAX_MEAN_FLIP: f32 = 0.02;
/// Worst mean FLIP error of an 8x8 block allowed: an edge pixel that flips between two
/// triangles moves a block's mean a little; a block whose content is gone or of another colour
/// moves it a lot.
const MAX_BLOCK_FLIP: f32 = 0.1;
const BLOCK: u32 = 8;
const SIZE: (u32, u32) = (128, 72);

/// FLIP of a test image against a reference, as the thresholds read it.
#[derive(Debug)]
struct FlipScore {
    mean: f32,
    /// The worst mean error of an 8x8 block, and that block's corner in pixels.
    worst_block: f32,
    worst_at: [u32; 2],
}

impl FlipScore {
    fn of(reference: &[u8], test: &[u8]) -> Self {
        let (w, h) = SIZE;
        let flip = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, reference),
            nv_flip::FlipImageRgb8::with_data(w, h, test),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        );
        let errors = flip.to_vec();
        let mean = errors.iter().sum::<f32>() / errors.len() as f32;
        let (mut worst_block, mut worst_at) = (0f32, [0, 0]);
        for by in 0..h / BLOCK {
            for bx in 0..w / BLOCK {
                let sum: f32 = (0..BLOCK * BLOCK)
                    .map(|k| {
                        let (x, y) = (bx * BLOCK + k % BLOCK, by * BLOCK + k / BLOCK);
                        errors[(y * w + x) as usize]
                    })
                    .sum();
                let block = sum / (BLOCK * BLOCK) as f32;
                if block > worst_block {
                    (worst_block, worst_at) = (block, [bx * BLOCK, by * BLOCK]);
                }
            }
        }
        Self {
            mean,
            worst_block,
            worst_at,
        }
    }

    fn check(&self) -> Result<(), String> {
        if self.mean > MAX_MEAN_FLIP {
            return Err(format!("mean FLIP {} > {MAX_MEAN_FLIP}", self.mean));
        }
        if self.worst_block > MAX_BLOCK_FLIP {
            return Err(format!(
                "FLIP {} > {MAX_BLOCK_FLIP} in the 8x8 block at {:?}",
                self.worst_block, self.worst_at
            ));
        }
        Ok(())
    }
}

fn snapshot_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{name}.png"))
}

fn load_snapshot(name: &str) -> Vec<u8> {
    let path = snapshot_path(name);
    let reference = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e}; render it with HIKARI_UPDATE_SNAPSHOTS=1",
                path.display()
            )
        })
        .into_rgb8();
    assert_eq!(reference.dimensions(), SIZE, "{}", path.display());
    reference.into_raw()
}

/// What a snapshot renders: scene, camera, time of day and settings.
struct Shot {
    scene: hikari_scene::Scene,
    camera: Option<&'static str>,
    time: Option<&'static str>,
    settings: Settings,
}

impl Shot {
    fn builtin(name: &str) -> Self {
        let mut settings = Settings::default();
        // Snapshots of the frame without the sky, whose own tests are tests/render/sky.rs: the sky's
        // table build would dominate these tests' time on the CPU driver.
        settings.sky.enabled = false;
        // Ray-traced GI is noisy frame to frame and has its own tests.
        settings.ray_traced_gi.enabled = false;
        // Small maps keep the CPU driver fast; the cascades still cover the view.
        settings.sun_shadows.resolution = 512;
        Self {
            scene: hikari_scene::builtin::by_name(name).unwrap(),
            camera: None,
            time: None,
            settings,
        }
    }

    fn seen_from(mut self, camera: &'static str, time: Option<&'static str>) -> Self {
        self.camera = Some(camera);
        self.time = time;
        self
    }
}

/// The Cornell box lit by a point light 5 cm under the middle of its ceiling, at a fixed
/// exposure. Until area lights arrive the box's own emitter lights nothing, so the box alone
/// renders black walls around a white patch; the point light shows the walls' three colours,
/// the blocks and their shadows.
fn cornell_point_light() -> Shot {
    let mut shot = Shot::builtin("cornell");
    shot.scene.lights.push(hikari_scene::Light::point(
        "snapshot lamp",
        Vec3::new(0.278, 0.499, 0.28),
        3.0,
        Vec3::ONE,
    ));
    // About 12 lux metered (EV100 = log2(12 * 100 / 250)): the floor under a 3 cd lamp half
    // a metre away.
    shot.settings.exposure.ev100 = Some(2.25);
    shot
}

/// The shot rendered at [`SIZE`], as 8-bit sRGB.
fn render(shot: &Shot) -> Vec<u8> {
    let ctx = common::gpu_context();
    let scene = &shot.scene;
    let camera = shot.camera.map_or(scene.cameras[0].clone(), |c| {
        scene.camera(c).unwrap().clone()
    });
    // A time: the sun or moon of that time on the sky settings' default date and place.
    // As a fixed light: the sky is drawn for its direction and the settings' clock stays.
    let sun = shot
        .time
        .map_or(scene.sun.clone(), |t| {
            let mut sky = shot.settings.sky.clone();
            sky.time = t.into();
            hikari_render::techniques::sky::lights::directional_light(&sky).unwrap()
        })
        .into();
    let s = FrameSettings {
        width: SIZE.0,
        height: SIZE.1,
        camera,
        prev_camera: None,
        sun,
        settings: shot.settings.clone(),
    };
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let frame = renderer.render(&s, true).unwrap();
    frame
        .ldr
        .unwrap()
        .rgba
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect()
}

/// Renders `shot` and compares it with `tests/snapshots/{name}.png` (or writes that file when
/// `HIKARI_UPDATE_SNAPSHOTS=1`).
fn snapshot(name: &str, shot: Shot) {
    let rgb = render(&shot);
    let path = snapshot_path(name);
    if std::env::var("HIKARI_UPDATE_SNAPSHOTS").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        // Atomically: a stopped run leaves the old image, not half a new one.
        let tmp = path.with_extension("png.tmp");
        image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb)
            .unwrap()
            .save_with_format(&tmp, image::ImageFormat::Png)
            .unwrap();
        std::fs::rename(&tmp, &path).unwrap();
        eprintln!("updated {}", path.display());
        return;
    }
    let score = FlipScore::of(&load_snapshot(name), &rgb);
    eprintln!("{name}: {score:?}");
    if let Err(e) = score.check() {
        panic!("{name}: {e} against {}", path.display());
    }
}

const SNAPSHOTS: [&str; 7] = [
    "village",
    "village_courtyard_afternoon",
    "village_night_street",
    "village_house_interior",
    "cornell",
    "terrain",
    "boxes",
];

#[test]
fn village() {
    snapshot("village", Shot::builtin("village"));
}

#[test]
fn village_courtyard_afternoon() {
    snapshot(
        "village_courtyard_afternoon",
        Shot::builtin("village").seen_from("courtyard", Some("16:30")),
    );
}

#[test]
fn village_night_street() {
    snapshot(
        "village_night_street",
        Shot::builtin("village").seen_from("night_street", Some("21:30")),
    );
}

#[test]
fn village_house_interior() {
    snapshot(
        "village_house_interior",
        Shot::builtin("village").seen_from("house_interior", None),
    );
}

#[test]
fn cornell() {
    snapshot("cornell", cornell_point_light());
}

#[test]
fn terrain() {
    snapshot("terrain", Shot::builtin("terrain"));
}

#[test]
fn boxes() {
    snapshot("boxes", Shot::builtin("boxes"));
}

// Damage done to the committed images: each must fail the thresholds the renders pass.

/// Linear luminance of an 8-bit sRGB pixel.
fn luminance(p: &[u8]) -> f32 {
    let lin = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * lin(p[0]) + 0.7152 * lin(p[1]) + 0.0722 * lin(p[2])
}

/// The 32x32 tile (corner in pixels, on a 16-pixel grid) that maximises `score` of its pixels.
fn best_tile(rgb: &[u8], score: impl Fn(&[u8]) -> f32) -> [u32; 2] {
    let (w, h) = SIZE;
    let mut best = (f32::MIN, [0, 0]);
    for y in (0..=h - 32).step_by(16) {
        for x in (0..=w - 32).step_by(16) {
            let s: f32 = (0..32 * 32)
                .map(|k| {
                    let i = (((y + k / 32) * w + x + k % 32) * 3) as usize;
                    score(&rgb[i..i + 3])
                })
                .sum();
            if s > best.0 {
                best = (s, [x, y]);
            }
        }
    }
    best.1
}

/// `rgb` with every pixel of the 32x32 tile at `corner` changed by `f`.
fn edit_tile(rgb: &[u8], corner: [u32; 2], f: impl Fn(&mut [u8])) -> Vec<u8> {
    let mut out = rgb.to_vec();
    for k in 0..32 * 32 {
        let i = (((corner[1] + k / 32) * SIZE.0 + corner[0] + k % 32) * 3) as usize;
        f(&mut out[i..i + 3]);
    }
    out
}

/// An 8-bit sRGB value scaled by `k` in linear light.
fn scale_srgb(c: u8, k: f32) -> u8 {
    let c = c as f32 / 255.0;
    let lin = if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    } * k;
    let s = if lin <= 0.0031308 {
        lin * 12.92
    } else {
        1.055 * lin.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[test]
fn damaged_snapshots_fail() {
    let mut passed = Vec::new();
    for name in SNAPSHOTS {
        let reference = load_snapshot(name);
        // Lit content the damage can take away; a black image shows no damage.
        let lit = reference
            .chunks(3)
            .filter(|p| p.iter().any(|&c| c > 8))
            .count();
        assert!(
            lit * 4 > reference.len() / 3,
            "{name}: only {lit} of {} pixels show anything: the snapshot cannot fail",
            reference.len() / 3
        );
        assert!(FlipScore::of(&reference, &reference).check().is_ok());
        let brightest = best_tile(&reference, luminance);
        // Most saturated: where a material's colour shows most.
        let colourful = best_tile(&reference, |p| {
            let (max, min) = (*p.iter().max().unwrap(), *p.iter().min().unwrap());
            (max - min) as f32
        });
        let damages = [
            (
                "a lost 32x32 tile",
                edit_tile(&reference, brightest, |p| p.fill(0)),
            ),
            (
                "a light's contribution halved in its brightest tile",
                edit_tile(&reference, brightest, |p| {
                    for c in p.iter_mut() {
                        *c = scale_srgb(*c, 0.5);
                    }
                }),
            ),
            (
                "a material's colour swapped (red and green, blue and red)",
                edit_tile(&reference, colourful, |p| p.rotate_left(1)),
            ),
            (
                "the whole image a third darker (a light of the whole view dimmed)",
                reference
                    .iter()
                    .map(|&c| scale_srgb(c, 2.0 / 3.0))
                    .collect(),
            ),
        ];
        for (what, damaged) in damages {
            let score = FlipScore::of(&reference, &damaged);
            eprintln!("{name}, {what}: {score:?}");
            if score.check().is_ok() {
                passed.push(format!("{name}, {what}: {score:?}"));
            }
        }
    }
    assert!(
        passed.is_empty(),
        "damaged images that pass:\n{}",
        passed.join("\n")
    );
}

#[test]
fn renders_with_a_light_off_or_a_wrong_material_fail_the_cornell_snapshot() {
    // The same damage as above, made by the renderer: the lamp switched off, and the red wall
    // given the green wall's material.
    let reference = load_snapshot("cornell");
    let mut unlit = cornell_point_light();
    unlit.settings.direct_lighting.punctual = false;
    let mut repainted = cornell_point_light();
    let red = repainted
        .scene
        .materials
        .iter()
        .position(|m| m.name == "red")
        .unwrap();
    let green = repainted.scene.materials[repainted
        .scene
        .materials
        .iter()
        .position(|m| m.name == "green")
        .unwrap()]
    .clone();
    repainted.scene.materials[red] = green;
    for (what, shot) in [("lamp off", unlit), ("red wall green", repainted)] {
        let score = FlipScore::of(&reference, &render(&shot));
        assert!(
            score.check().is_err(),
            "{what}: passes the cornell snapshot: {score:?}"
        );
    }
}
