//! The frame as a whole: offline frames are drawn again until nothing was lost and count once;
//! interactive frames never wait for their queue counts, are shown as drawn, and the queues
//! catch up from the counts of earlier frames.

use crate::common;

use hikari_render::Renderer;
use hikari_render::scene::raster::QueueSizes;

fn tiny_queues(renderer: &mut Renderer) {
    for t in ["gbuffer", "sun_shadows"] {
        renderer.raster_queues().set(
            t,
            QueueSizes {
                entries: 4,
                records: 2,
            },
        );
    }
}

#[test]
fn an_overflowing_offline_frame_is_drawn_again_but_counts_once() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let s = common::small_frame_settings(&scene, 128, 80);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    tiny_queues(&mut renderer);
    for want in 0..3u64 {
        let r = renderer.render(&s, false).unwrap();
        assert_eq!(
            r.result.frame, want,
            "each shown frame steps the index once"
        );
    }
    assert_eq!(renderer.runtime.frame_index(), 3);
}

#[test]
fn interactive_frames_run_ahead_and_the_queues_catch_up() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&scene, 128, 80);
    // TAA's jitter would move the visibility buffer from frame to frame.
    s.settings.taa.enabled = false;
    let reference = {
        let mut r = Renderer::new(common::gpu_context(), &scene).unwrap();
        r.render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
            .unwrap()
            .buffer("gbuffer.visibility")
            .unwrap()
            .to_vec()
    };
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    renderer.set_interactive(true);
    tiny_queues(&mut renderer);
    let mut last = Vec::new();
    for want in 0..8u64 {
        let r = renderer
            .render_reading(&s, |out| vec![out.gbuffer.visibility.into()])
            .unwrap();
        assert_eq!(
            r.frame, want,
            "interactive frames are shown as drawn, never redone"
        );
        last = r.buffer("gbuffer.visibility").unwrap().to_vec();
        // Let the GPU finish so the late counts arrive by the next frame or the one after.
        renderer.ctx.wait_idle().unwrap();
    }
    let grown = renderer.raster_queues().sizes("gbuffer", 0);
    assert!(grown.entries > 4, "the queues never grew: {grown:?}");
    assert!(
        last == reference,
        "after the queues grew, frames lose nothing"
    );
}

/// A NaN or infinite camera, sun or light that reaches the renderer is an error naming it,
/// not a frame of garbage or a panic.
#[test]
fn non_finite_cameras_suns_and_lights_are_clear_errors() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let good = common::small_frame_settings(&scene, 64, 48);
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let err = |r: Result<hikari_render::RenderedFrame, hikari_render::RenderError>| {
        r.err().expect("refused").to_string()
    };

    let mut s = good.clone();
    s.camera.position.x = f32::NAN;
    let e = err(renderer.render(&s, false));
    assert!(e.contains("camera") && e.contains("position"), "{e}");

    let mut s = good.clone();
    s.camera.vfov_deg = f32::INFINITY;
    assert!(err(renderer.render(&s, false)).contains("vfov"));

    let mut s = good.clone();
    if let hikari_render::SunSource::Fixed(sun) = &mut s.sun {
        sun.direction = glam::Vec3::new(f32::NAN, 1.0, 0.0);
    }
    let e = err(renderer.render(&s, false));
    assert!(e.contains("sun") && e.contains("direction"), "{e}");

    let mut s = good.clone();
    if let hikari_render::SunSource::Fixed(sun) = &mut s.sun {
        sun.illuminance_lux = f32::INFINITY;
    }
    assert!(err(renderer.render(&s, false)).contains("illuminance"));

    // The renderer still draws a sane frame afterwards.
    renderer.render(&good, false).unwrap();

    let mut bad_light = scene.clone();
    bad_light.lights.push(hikari_scene::Light::point_lumens(
        "broken lamp",
        glam::Vec3::new(0.0, f32::NAN, 0.0),
        100.0,
        glam::Vec3::ONE,
    ));
    let e = Renderer::new(common::gpu_context(), &bad_light)
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("broken lamp"), "{e}");
}
