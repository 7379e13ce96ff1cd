//! Snapshot images of every built-in scene at 128x72, compared with the committed PNGs under
//! `tests/snapshots/` by NVIDIA's FLIP (mean error over the image). A change of the renderer
//! that moves an image beyond the threshold fails here; when the change is intended, rerun
//! with `HIKARI_UPDATE_SNAPSHOTS=1` and commit the new PNGs after looking at them.

mod common;

use std::path::PathBuf;

use hikari_render::{FrameSettings, Renderer, Settings};

/// Mean FLIP error allowed: differences of driver rounding stay far below it (about 0.001),
/// a changed shadow, light or material shows up well above it.
const MAX_MEAN_FLIP: f32 = 0.02;
const SIZE: (u32, u32) = (128, 72);

fn snapshot(name: &str) {
    snapshot_at(name, name, None, None);
}

/// Scene `scene` seen from `camera` (its first if `None`) at `time` ("HH:MM"; the scene's sun
/// if `None`), compared with `tests/snapshots/{name}.png`.
fn snapshot_at(name: &str, scene: &str, camera: Option<&str>, time: Option<&str>) {
    let Some(ctx) = common::gpu() else { return };
    let scene = hikari_scene::builtin::by_name(scene).unwrap();
    let camera = camera.map_or(scene.cameras[0].clone(), |c| {
        scene.camera(c).unwrap().clone()
    });
    let sun = time.map_or(scene.sun.clone(), |t| {
        Some(hikari_scene::time_of_day::sun_at(
            hikari_scene::time_of_day::parse_time(t).unwrap(),
        ))
    });
    let mut settings = Settings::default();
    // Snapshots of the placeholder-lit frame; the sky has tests of its own (tests/sky.rs).
    settings.sky.enabled = false;
    // Small maps keep the CPU driver fast; the cascades still cover the view.
    settings.sun_shadows.resolution = 512;
    let s = FrameSettings {
        width: SIZE.0,
        height: SIZE.1,
        camera,
        prev_camera: None,
        sun,
        settings,
    };
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let frame = renderer.render(&s, true).unwrap();
    let ldr = frame.ldr.unwrap();
    let rgb: Vec<u8> = ldr
        .rgba
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{name}.png"));
    if std::env::var("HIKARI_UPDATE_SNAPSHOTS").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb)
            .unwrap()
            .save(&path)
            .unwrap();
        eprintln!("updated {}", path.display());
        return;
    }
    let reference = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e}; render it with HIKARI_UPDATE_SNAPSHOTS=1",
                path.display()
            )
        })
        .into_rgb8();
    assert_eq!(reference.dimensions(), SIZE, "{}", path.display());
    let flip = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(SIZE.0, SIZE.1, reference.as_raw()),
        nv_flip::FlipImageRgb8::with_data(SIZE.0, SIZE.1, &rgb),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = nv_flip::FlipPool::from_image(&flip).mean();
    assert!(
        mean <= MAX_MEAN_FLIP,
        "{name}: mean FLIP {mean} > {MAX_MEAN_FLIP} against {}",
        path.display()
    );
}

#[test]
fn village() {
    snapshot("village");
}

#[test]
fn village_courtyard_afternoon() {
    snapshot_at(
        "village_courtyard_afternoon",
        "village",
        Some("courtyard"),
        Some("16:30"),
    );
}

#[test]
fn village_night_street() {
    snapshot_at(
        "village_night_street",
        "village",
        Some("night_street"),
        Some("21:30"),
    );
}

#[test]
fn village_house_interior() {
    snapshot_at(
        "village_house_interior",
        "village",
        Some("house_interior"),
        None,
    );
}

#[test]
fn cornell() {
    snapshot("cornell");
}

#[test]
fn terrain() {
    snapshot("terrain");
}

#[test]
fn boxes() {
    snapshot("boxes");
}
