//! The live renderer API (`Renderer::set_frame` and its setters, then `Renderer::frame`): each
//! change rebuilds or resets only what it must, through the frame context's one history flag,
//! and the renderer alone resolves the sun or moon. Also: memory stays flat over frames.

use crate::common;

use hikari_render::{FrameSettings, HistoryReset, Renderer, SunSource};

/// A small live frame of the boxes with the sky on (its sun and moon come from the clock).
fn live(w: u32, h: u32) -> (hikari_scene::Scene, FrameSettings) {
    let scene = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.sky.enabled = true;
    s.settings.sky.table_quality = 0;
    s.settings.irradiance_probes.enabled = false;
    s.settings.reflection_probes.enabled = false;
    s.sun = SunSource::Sky;
    // TAA's jitter would move the view every frame; the camera checks compare views.
    s.settings.taa.enabled = false;
    (scene, s)
}

fn reset_of(r: &Renderer) -> Option<HistoryReset> {
    r.last_context()
        .expect("a frame was rendered")
        .history
        .reset
}

#[test]
fn each_live_change_resets_exactly_the_history_it_should() {
    let ctx = common::gpu_context();
    let (scene, s) = live(32, 24);
    let mut r = Renderer::new(ctx, &scene).unwrap();
    assert!(r.frame(false).is_err(), "no live frame set yet");
    r.set_frame(s.clone()).unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::FirstFrame));
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), None, "a still frame keeps its history");

    // The clock moves a little: the sun follows, the history stays.
    let before = r.last_context().unwrap().sun.clone().unwrap();
    r.set_clock("2024-07-21", "12:00:30").unwrap();
    r.frame(false).unwrap();
    let cx = r.last_context().unwrap();
    assert_eq!(
        cx.history.reset, None,
        "a small step of the clock keeps the history"
    );
    assert_ne!(cx.sun.clone().unwrap().direction, before.direction);
    // The clock jumps: the light jumps and the history goes.
    r.set_clock("2024-07-21", "16:30").unwrap();
    r.frame(false).unwrap();
    let cx = r.last_context().unwrap();
    assert_eq!(cx.history.reset, Some(HistoryReset::LightJump));
    let after = cx.sun.clone().unwrap();
    assert!(
        after.direction.dot(before.direction) < 0.95 && after.direction.y < before.direction.y,
        "the afternoon sun is lower and elsewhere: {before:?} -> {after:?}"
    );

    // Moving the camera keeps the history and gives motion; a jump drops it.
    let mut cam = s.camera.clone();
    cam.position.x += 0.2;
    cam.target.x += 0.2;
    r.set_camera(cam.clone(), false).unwrap();
    r.frame(false).unwrap();
    let cx = r.last_context().unwrap();
    assert_eq!(cx.history.reset, None, "moving is not a cut");
    assert_ne!(
        cx.view.view_proj, cx.view.prev_view_proj,
        "the motion reaches the view"
    );
    r.frame(false).unwrap();
    let cx = r.last_context().unwrap();
    assert_eq!(
        cx.view.view_proj, cx.view.prev_view_proj,
        "a frame after the move starts from where the last one was"
    );
    cam.position.z += 30.0;
    r.set_camera(cam.clone(), true).unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::CameraCut));
    r.cut_camera();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::CameraCut));

    // Another weather is a jump of the light too.
    r.set_weather("overcast").unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::LightJump));
    // A continuous setting keeps the history; switching a technique drops it.
    let mut settings = r.live_frame().unwrap().settings.clone();
    settings.exposure.compensation_ev += 0.5;
    r.set_settings(settings.clone()).unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), None);
    settings.haze.enabled = !settings.haze.enabled;
    r.set_settings(settings).unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::SettingsChange));

    // A resize reallocates: the image has the new size, the history restarts.
    r.resize(40, 20).unwrap();
    let f = r.frame(true).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::Resize));
    let ldr = f.ldr.unwrap();
    assert_eq!((ldr.width, ldr.height), (40, 20));

    // A new scene: new geometry, no history.
    r.reload_scene(&hikari_scene::builtin::cornell()).unwrap();
    r.set_camera(hikari_scene::builtin::cornell().cameras[0].clone(), true)
        .unwrap();
    r.frame(false).unwrap();
    assert_eq!(reset_of(&r), Some(HistoryReset::SceneChange));
}

#[test]
fn a_bad_live_change_names_its_field_and_keeps_the_frame() {
    let ctx = common::gpu_context();
    let (scene, s) = live(32, 24);
    let mut r = Renderer::new(ctx, &scene).unwrap();
    r.set_frame(s.clone()).unwrap();
    let e = r.set_clock("2024-13-01", "12:00").unwrap_err().to_string();
    assert!(e.contains("sky.date"), "{e}");
    let e = r.set_clock("2024-07-21", "25:00").unwrap_err().to_string();
    assert!(e.contains("sky.time"), "{e}");
    let e = r.set_place(95.0, 0.0, 9.0).unwrap_err().to_string();
    assert!(e.contains("sky.latitude_deg"), "{e}");
    let e = r.set_weather("monsoon").unwrap_err().to_string();
    assert!(e.contains("sky.weather") && e.contains("overcast"), "{e}");
    let e = r.set_time_of_day(f64::NAN).unwrap_err().to_string();
    assert!(e.contains("sky.time"), "{e}");
    let e = r.resize(0, 10).unwrap_err().to_string();
    assert!(e.contains("width"), "{e}");
    let mut cam = s.camera.clone();
    cam.position.x = f32::NAN;
    let e = r.set_camera(cam, false).unwrap_err().to_string();
    assert!(e.contains("camera"), "{e}");
    let mut bad = r.live_frame().unwrap().settings.clone();
    bad.taa.jitter_samples = 0;
    let e = r.set_settings(bad).unwrap_err().to_string();
    assert!(
        e.starts_with("settings:") && e.contains("taa.jitter_samples"),
        "{e}"
    );
    // Nothing of it stuck: the live frame is the one set.
    let live = r.live_frame().unwrap();
    assert_eq!(live.settings, s.settings);
    assert_eq!(live.camera.position, s.camera.position);
    assert!(live.prev_camera.is_none());
    r.frame(false).unwrap();
}

#[test]
fn the_renderer_alone_resolves_the_sun_and_the_moon() {
    let (_, mut s) = live(32, 24);
    s.settings.sky.time = "12:00".into();
    let noon = s.context().unwrap();
    let sun = noon.sun.clone().unwrap();
    assert!(sun.illuminance_lux > 50_000.0, "{sun:?}");
    // The full moon late that night, a fraction of a lux; the sky is the moon's.
    s.settings.sky.time = "23:50".into();
    let night = s.context().unwrap();
    let moon = night.sun.clone().unwrap();
    assert!((0.05..0.5).contains(&moon.illuminance_lux), "{moon:?}");
    let sky = night.sky.as_ref().unwrap();
    assert_eq!(moon.direction, sky.lights.moon.direction.normalize());
    // A fixed sun is the scene's: the sky follows it and the moon goes.
    s.sun = SunSource::Fixed(hikari_scene::Sun::default());
    let fixed = s.context().unwrap();
    assert_eq!(fixed.sun, Some(hikari_scene::Sun::default()));
    let lights = fixed.sky.unwrap().lights;
    assert_eq!(
        lights.sun.direction,
        hikari_scene::Sun::default().direction.normalize()
    );
    assert_eq!(lights.moon.extraterrestrial_lux, 0.0);
    // `sky.sun = false` and `Off` give none.
    s.settings.sky.sun = false;
    assert!(s.context().unwrap().sun.is_none());
    s.settings.sky.sun = true;
    s.sun = SunSource::Off;
    assert!(s.context().unwrap().sun.is_none());
}

/// The resident memory of this process, bytes (Linux).
fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

/// Mesa's CPU driver compiled a shader anew at every bind when a branch read a uniform, and
/// kept each copy: 13 MB a frame. hikari binds uniforms as storage there
/// (`GpuContext::uniforms_as_storage`); over frames with every technique on, memory is flat.
/// The frames run in a process of their own (this test binary again, running
/// [`memory_probe`] alone), so that the tests running beside this one do not count.
#[test]
fn memory_stays_flat_over_frames_with_every_technique_on() {
    if resident_bytes().is_none() {
        return; // not Linux: nothing to read
    }
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "live::memory_probe",
            "--exact",
            "--include-ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && text.contains("1 passed"),
        "the memory probe failed:\n{text}"
    );
}

/// The frames of [`memory_stays_flat_over_frames_with_every_technique_on`], run by it in a
/// process of their own.
#[test]
#[ignore = "run by memory_stays_flat_over_frames_with_every_technique_on in its own process"]
fn memory_probe() {
    let before = resident_bytes().unwrap();
    let ctx = common::gpu_context();
    if ctx.info.device_type == hikari_render::wgpu::DeviceType::Cpu {
        assert!(
            ctx.uniforms_as_storage,
            "the CPU driver must take uniforms as storage"
        );
    }
    let (scene, mut s) = live(32, 24);
    s.settings.ray_traced_gi.enabled = true;
    s.settings.haze.enabled = true;
    s.settings.taa.enabled = true;
    s.settings.clouds = common::small_clouds(0.5, 400.0);
    let mut r = Renderer::new(ctx, &scene).unwrap();
    r.set_frame(s).unwrap();
    let mut clock = 12.0 * 3600.0;
    for _ in 0..4 {
        clock += 6.0;
        r.set_time_of_day(clock).unwrap();
        r.frame(false).unwrap();
    }
    let warm = resident_bytes().unwrap();
    let frames = 16;
    for _ in 0..frames {
        clock += 6.0;
        r.set_time_of_day(clock).unwrap();
        r.frame(false).unwrap();
    }
    let after = resident_bytes().unwrap();
    let growth = after.saturating_sub(warm) as f64 / f64::from(frames);
    // Well under the leak's 13 MB a frame, well over allocator noise.
    assert!(
        growth < 1.5e6,
        "resident memory grew {:.1} MB a frame ({} MB before the renderer, {} MB after warm-up, \
         {} MB after {frames} more frames)",
        growth / 1e6,
        before / 1_000_000,
        warm / 1_000_000,
        after / 1_000_000
    );
}
