//! Faults the GPU raises after the fact (validation, out of memory, a lost device) end a
//! frame with an error naming them, never a panic or a hang; NaN and infinities written into
//! every input and history of every temporal pass in turn leave the frame finite, and it
//! recovers.

use std::time::{Duration, Instant};

use hikari_render::faults::{Fault, GpuFaults};
use hikari_render::graph::{PassReads, Poison};
use hikari_render::{ContextOptions, FrameSettings, GpuContext, RenderError, Renderer, SunSource};

use crate::common;

/// A context of its own: the faults provoked here must not reach the other tests' frames on
/// the shared device.
fn own_context() -> GpuContext {
    GpuContext::new(&ContextOptions::from_env()).expect("an adapter")
}

#[test]
fn a_validation_error_is_recorded_and_reported_not_a_panic() {
    let ctx = own_context();
    assert!(ctx.faults.check("nothing yet").is_ok());
    // MAP_READ with STORAGE is invalid without MAPPABLE_PRIMARY_BUFFERS: wgpu reports it
    // through the uncaptured-error handler, whose default panics.
    let _ = ctx
        .device
        .create_buffer(&hikari_render::wgpu::BufferDescriptor {
            label: Some("invalid on purpose"),
            size: 64,
            usage: hikari_render::wgpu::BufferUsages::MAP_READ
                | hikari_render::wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
    let e = ctx.faults.check("the test").unwrap_err();
    assert!(
        matches!(&e, RenderError::Gpu { during, message } if during == "the test"
            && message.contains("invalid on purpose")),
        "{e}"
    );
    assert!(
        ctx.faults.check("again").is_ok(),
        "an error is reported once"
    );
}

#[test]
fn a_lost_device_ends_a_wait_with_an_error_at_once() {
    let ctx = own_context();
    ctx.device.destroy();
    let t0 = Instant::now();
    let e = ctx.wait_idle().unwrap_err();
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
    assert!(matches!(e, RenderError::DeviceLost { .. }), "{e}");
    assert!(e.to_string().contains("restart hikari"), "{e}");
}

/// The shared device with a fault recorder of its own, so that faults recorded on purpose
/// reach only this renderer.
fn private_faults() -> GpuContext {
    let mut ctx = common::gpu_context();
    ctx.faults = GpuFaults::default();
    ctx
}

#[test]
fn a_frame_on_a_lost_device_fails_before_any_gpu_work_and_an_out_of_memory_frame_is_dropped() {
    let ctx = private_faults();
    let scene = hikari_scene::builtin::boxes();
    let s = common::small_frame_settings(&scene, 16, 12);
    let mut r = Renderer::new(ctx.clone(), &scene).unwrap();
    r.set_frame(s).unwrap();
    r.frame(false).unwrap();
    let frame_before = r.runtime.frame_index();
    ctx.faults
        .record(Fault::OutOfMemory("a texture of 40 GB".into()));
    let Err(e) = r.frame(false) else {
        panic!("the frame rendered")
    };
    assert!(
        matches!(&e, RenderError::OutOfMemory { message, .. } if message.contains("40 GB")),
        "{e}"
    );
    assert_eq!(
        r.runtime.frame_index(),
        frame_before,
        "the failed frame is not committed"
    );
    r.frame(false).expect("the next frame renders");
    assert!(
        common::gpu_context().faults.check("after").is_ok(),
        "the dropped frame left the device in a state the next frame's work is invalid in"
    );

    ctx.faults.record_lost("simulated");
    let Err(e) = r.frame(false) else {
        panic!("the frame rendered")
    };
    assert!(matches!(e, RenderError::DeviceLost { .. }), "{e}");
}

/// Every technique with a history on, small: the boxes by day with sky, clouds, haze, the
/// GI, TAA and exposure adaptation; the Cornell box for the area lights' denoiser.
fn temporal_frames() -> Vec<(hikari_scene::Scene, FrameSettings)> {
    let boxes = hikari_scene::builtin::boxes();
    let mut s = common::small_frame_settings(&boxes, 24, 16);
    s.settings.sky.enabled = true;
    s.settings.sky.table_quality = 0;
    s.sun = SunSource::Sky;
    s.settings.ray_traced_gi.enabled = true;
    s.settings.haze.enabled = true;
    s.settings.clouds = common::small_clouds(0.5, 400.0);
    let cornell = hikari_scene::builtin::cornell();
    let mut c = common::small_frame_settings(&cornell, 24, 16);
    c.settings.ray_traced_gi.enabled = true;
    vec![(boxes, s), (cornell, c)]
}

fn hdr_finite(r: &mut Renderer, what: &str) -> f64 {
    let f = r.frame(true).unwrap_or_else(|e| panic!("{what}: {e}"));
    let hdr = f.hdr.expect("read back");
    let bad = hdr
        .rgba
        .iter()
        .filter(|p| !p.iter().all(|v| v.is_finite()))
        .count();
    assert_eq!(bad, 0, "{what}: {bad} pixels of the output are not finite");
    hdr.rgba
        .iter()
        .map(|p| f64::from(p[0] + p[1] + p[2]))
        .sum::<f64>()
        / hdr.rgba.len() as f64
}

/// The output's mean over `n` frames (each checked finite).
fn mean_over(r: &mut Renderer, n: usize, what: &str) -> f64 {
    (0..n).map(|_| hdr_finite(r, what)).sum::<f64>() / n as f64
}

/// The temporal passes of a frame and the poisonable textures each reads.
fn temporal_reads(r: &mut Renderer) -> Vec<PassReads> {
    r.runtime.set_record_reads(true);
    let f = r.frame(false).unwrap();
    r.runtime.set_record_reads(false);
    f.result
        .reads
        .into_iter()
        .filter(|p| p.is_temporal())
        .collect()
}

/// Each temporal pass of the frame, each of the float textures it reads that is not a cache
/// (inputs of the frame and histories), overwritten with NaN, +Inf and -Inf in turn: the output
/// and every history written in that frame and the next stay finite. After the sweep the
/// frame comes back to where it was. Cached tables (the sky's, rebuilt when the sun moves) are
/// left out: a NaN there stays finite (the passes that read them sanitise) but would last
/// until the cache is rebuilt.
#[test]
fn nan_and_infinity_in_every_temporal_input_leave_the_frame_finite_and_it_recovers() {
    let ctx = common::gpu_context();
    let mut visited = Vec::new();
    for (scene, s) in temporal_frames() {
        let mut r = Renderer::new(ctx.clone(), &scene).unwrap();
        r.set_frame(s).unwrap();
        mean_over(&mut r, SETTLE_FRAMES, "warm-up");
        let before = mean_over(&mut r, MEAN_FRAMES, "before");
        let reads = temporal_reads(&mut r);
        let histories: Vec<String> = reads
            .iter()
            .flat_map(|p| &p.textures)
            .filter_map(|t| t.name.strip_suffix(".prev"))
            .map(str::to_string)
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        for pass in &reads {
            for t in pass.textures.iter().filter(|t| t.poisonable && !t.cached) {
                let what = format!("{} reading `{}`", pass.pass, t.name);
                let poison = Poison {
                    pass: pass.pass.clone(),
                    texture: t.name.clone(),
                };
                r.runtime.poison_next_frame(poison.clone());
                r.runtime.set_dumps(histories.clone());
                let f = r.frame(true).unwrap_or_else(|e| panic!("{what}: {e}"));
                r.runtime.set_dumps(Vec::new());
                assert_eq!(f.result.poisoned, Some(poison), "{what}: not poisoned");
                for img in f.hdr.iter().chain(&f.result.images) {
                    let bad = img
                        .rgba
                        .iter()
                        .filter(|p| !p.iter().all(|v| v.is_finite()))
                        .count();
                    assert_eq!(bad, 0, "{what}: {bad} texels of `{}` not finite", img.name);
                }
                mean_over(&mut r, 1, &format!("{what}, the frame after"));
                visited.push(what);
            }
        }
        mean_over(&mut r, SETTLE_FRAMES, "settling");
        let after = mean_over(&mut r, MEAN_FRAMES, "after");
        let off = (after - before).abs() / before.max(1e-6);
        assert!(
            off < RECOVERY_TOLERANCE,
            "the frame did not recover from the sweep: mean {after:.4} after against \
             {before:.4} before ({:.0} % off)",
            off * 100.0
        );
    }
    eprintln!("poisoned {} inputs: {}", visited.len(), visited.join("; "));
    for pass in [
        "ray_traced_gi.shade",
        "ray_traced_gi.accumulate",
        "area_lights.temporal",
        "haze.light",
        "taa.resolve",
        "exposure.adapt",
    ] {
        assert!(
            visited.iter().any(|v| v.starts_with(pass)),
            "the temporal pass `{pass}` was not poisoned: {visited:?}"
        );
    }
}

/// Frames for the histories to settle, before the sweep and after it.
const SETTLE_FRAMES: usize = 8;
/// Frames whose mean is compared (the Cornell box at this size is noisy frame to frame).
const MEAN_FRAMES: usize = 6;
/// How far the mean after the sweep may be from the mean before.
const RECOVERY_TOLERANCE: f64 = 0.1;

/// A frame whose textures and buffers need more memory than the GPU has is refused before it
/// runs, naming the memory and the largest resource. The adapter's real heap (the CPU driver's
/// is the machine's memory) is replaced by a small one.
#[test]
fn a_frame_larger_than_the_gpu_memory_is_refused_before_it_runs() {
    let mut ctx = private_faults();
    assert!(
        ctx.memory_bytes.is_some_and(|m| m > 100_000_000),
        "the Vulkan adapter's memory is known: {:?}",
        ctx.memory_bytes
    );
    ctx.memory_bytes = Some(2_000_000);
    let scene = hikari_scene::builtin::boxes();
    let s = common::small_frame_settings(&scene, 64, 48);
    let mut r = Renderer::new(ctx.clone(), &scene).unwrap();
    r.set_frame(s).unwrap();
    let Err(e) = r.frame(false) else {
        panic!("a frame needing more than 2 MB rendered")
    };
    let text = e.to_string();
    assert!(
        matches!(
            e,
            RenderError::Limit {
                limit: 2_000_000,
                ..
            }
        ) && text.contains("GPU memory"),
        "{text}"
    );
    assert!(text.contains("the largest: `"), "{text}");
}
