//! The frame graph on a real adapter: pooling and aliasing, history, persistent resources,
//! binding checks and dump errors.

use crate::common;

use hikari_render::RenderError;
use hikari_render::checks::graph_check::{FillParams, GraphCheck};
use hikari_render::graph::{GraphRuntime, TextureDesc, TimestampMode};
use hikari_render::shader;

const F16: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

fn setup() -> (hikari_render::GpuContext, GraphCheck) {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let check = GraphCheck::new(&ctx, &mut lib).unwrap();
    (ctx, check)
}

fn fill(v: f32) -> FillParams {
    FillParams {
        value: [v, v, v, 1.0],
    }
}

#[test]
fn disjoint_lifetimes_share_memory_and_overlapping_ones_do_not() {
    aliasing_is_safe(TimestampMode::Pass);
}

#[test]
fn aliasing_is_safe_when_compute_passes_are_merged() {
    // Without per-pass timestamps consecutive compute passes share one wgpu pass; the results
    // must not change.
    aliasing_is_safe(TimestampMode::Frame);
    aliasing_is_safe(TimestampMode::Off);
}

fn aliasing_is_safe(mode: TimestampMode) {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    rt.set_timestamps(mode);
    let desc = TextureDesc::d2(16, 16, F16);
    let mut ids = Vec::new();
    for frame in 0..3 {
        let mut g = rt.begin_frame(&ctx);
        // a and b are alive together (c reads both); c then d reuse their memory.
        let a = g.texture("t.a", desc).unwrap();
        let b = g.texture("t.b", desc).unwrap();
        let c = g.texture("t.c", desc).unwrap();
        let d = g.texture("t.d", desc).unwrap();
        g.pass("t.fill_a")
            .write(a)
            .constants(&fill(1.0))
            .dispatch_threads(&check.fill, [16, 16, 1])
            .unwrap();
        g.pass("t.fill_b")
            .write(b)
            .constants(&fill(2.0))
            .dispatch_threads(&check.fill, [16, 16, 1])
            .unwrap();
        g.pass("t.c")
            .read(a)
            .read(b)
            .write(c)
            .dispatch_threads(&check.add, [16, 16, 1])
            .unwrap();
        g.pass("t.d")
            .read(c)
            .read(c)
            .write(d)
            .dispatch_threads(&check.add, [16, 16, 1])
            .unwrap();
        g.readback(d);
        let r = g.execute().unwrap();
        let id = |n: &str| r.allocations.iter().find(|(name, _)| name == n).unwrap().1;
        assert_ne!(id("t.a"), id("t.b"), "a and b are alive at once");
        assert_ne!(id("t.c"), id("t.a"));
        assert_ne!(id("t.c"), id("t.b"));
        // d is created after a and b died: it takes one of theirs.
        assert!(id("t.d") == id("t.a") || id("t.d") == id("t.b"));
        // (1 + 2) * 2, despite d's memory having held a or b earlier in the frame.
        assert_eq!(r.image("t.d").unwrap().pixel(3, 5)[0], 6.0);
        ids.push([id("t.a"), id("t.b"), id("t.c"), id("t.d")]);
        if frame > 0 {
            assert_eq!(
                ids[frame], ids[0],
                "the pool hands the same textures back every frame"
            );
        }
    }
    assert_eq!(
        rt.pool_stats().textures_created,
        3,
        "three physical textures serve four virtual ones"
    );
}

#[test]
fn history_carries_the_previous_frame_and_resets_on_resize() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let run = |size: u32, expect: f32, expect_valid: bool, rt: &mut GraphRuntime| {
        let desc = TextureDesc::d2(size, size, F16);
        let mut g = rt.begin_frame(&ctx);
        let one = g.texture("h.one", desc).unwrap();
        g.pass("h.fill")
            .write(one)
            .constants(&fill(1.0))
            .dispatch_threads(&check.fill, [size, size, 1])
            .unwrap();
        let h = g.history_texture("h.count", desc).unwrap();
        assert_eq!(h.valid, expect_valid);
        g.pass("h.accumulate")
            .read(h.prev)
            .read(one)
            .write(h.cur)
            .dispatch_threads(&check.add, [size, size, 1])
            .unwrap();
        g.readback(h.cur);
        let r = g.execute().unwrap();
        assert_eq!(r.image("h.count").unwrap().pixel(1, 1)[0], expect);
    };
    run(8, 1.0, false, &mut rt);
    run(8, 2.0, true, &mut rt);
    run(8, 3.0, true, &mut rt);
    // A new size starts over from zeros and says so.
    run(4, 1.0, false, &mut rt);
    run(4, 2.0, true, &mut rt);
}

/// A frame drawn again (as after a rasteriser overflow) must not step temporal state twice:
/// an accumulator that adds one each frame reads N after N accepted frames, however many
/// tries were thrown away, and the frame index counts accepted frames only.
#[test]
fn discarded_frames_do_not_advance_history_or_the_frame_index() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let desc = TextureDesc::d2(8, 8, F16);
    let mut accepted = 0u64;
    for frame in 0..6u32 {
        // Frames 1 and 4 are tried three times, the first two thrown away.
        let tries = if frame == 1 || frame == 4 { 3 } else { 1 };
        for attempt in 0..tries {
            assert_eq!(rt.frame_index(), accepted);
            let mut g = rt.begin_frame(&ctx);
            let one = g.texture("t.one", desc).unwrap();
            g.pass("t.fill")
                .write(one)
                .constants(&fill(1.0))
                .dispatch_threads(&check.fill, [8, 8, 1])
                .unwrap();
            let h = g.history_texture("t.count", desc).unwrap();
            assert_eq!(h.valid, accepted > 0, "frame {frame} try {attempt}");
            g.pass("t.accumulate")
                .read(h.prev)
                .read(one)
                .write(h.cur)
                .dispatch_threads(&check.add, [8, 8, 1])
                .unwrap();
            g.readback(h.cur);
            let r = g.execute_uncommitted().unwrap();
            assert_eq!(r.frame, accepted);
            assert_eq!(
                r.image("t.count").unwrap().pixel(3, 3)[0],
                accepted as f32 + 1.0,
                "frame {frame} try {attempt}"
            );
            if attempt + 1 == tries {
                rt.commit_frame();
                accepted += 1;
            } else {
                rt.discard_frame();
            }
        }
    }
    assert_eq!(rt.frame_index(), 6);
}

#[test]
fn persistent_textures_are_created_once() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let desc = TextureDesc::d3(4, 4, 4, wgpu::TextureFormat::Rgba16Float);
    for frame in 0..3 {
        let mut g = rt.begin_frame(&ctx);
        let (lut, created) = g.persistent_texture("p.lut", desc).unwrap();
        assert_eq!(created, frame == 0);
        g.readback(lut);
        let r = g.execute().unwrap();
        assert_eq!(
            r.image("p.lut").unwrap().height,
            16,
            "3D slices stack vertically"
        );
    }
    let _ = check;
}

fn pass_error(r: Result<(), RenderError>) -> String {
    match r {
        Err(e @ RenderError::Pass { .. }) => e.to_string(),
        other => panic!("expected a pass error, got {other:?}"),
    }
}

#[test]
fn binding_mistakes_name_the_pass_and_binding() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let a = g.texture("m.a", TextureDesc::d2(8, 8, F16)).unwrap();
    let wrong = g
        .texture(
            "m.wrong",
            TextureDesc::d2(8, 8, wgpu::TextureFormat::Rgba8Unorm),
        )
        .unwrap();

    let e = pass_error(
        g.pass("m.too_few")
            .write(a)
            .dispatch(&check.fill, [1, 1, 1]),
    );
    assert!(e.contains("m.too_few") && e.contains("binds 1"), "{e}");

    let e = pass_error(
        g.pass("m.read_as_write")
            .read(a)
            .constants(&fill(0.0))
            .dispatch(&check.fill, [1, 1, 1]),
    );
    assert!(e.contains("target_tex") && e.contains("`read`"), "{e}");

    let e = pass_error(
        g.pass("m.format")
            .write(wrong)
            .constants(&fill(0.0))
            .dispatch(&check.fill, [1, 1, 1]),
    );
    assert!(e.contains("Rgba16Float") && e.contains("m.wrong"), "{e}");

    let b = g.texture("m.b", TextureDesc::d2(8, 8, F16)).unwrap();
    let e = pass_error(
        g.pass("m.unwritten")
            .read(b)
            .read(b)
            .write(a)
            .dispatch(&check.add, [1, 1, 1]),
    );
    assert!(e.contains("no earlier pass"), "{e}");
}

#[test]
fn limits_and_dump_names_are_checked() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let too_big = ctx.limits.max_texture_dimension_2d + 1;
    assert!(matches!(
        g.texture("l.big", TextureDesc::d2(too_big, 4, F16)),
        Err(RenderError::Limit { .. })
    ));
    assert!(matches!(
        g.texture("l.zero", TextureDesc::d2(0, 4, F16)),
        Err(RenderError::Limit { .. })
    ));
    drop(g);

    rt.set_dumps(vec!["no.such.thing".into()]);
    let mut g = rt.begin_frame(&ctx);
    let a = g.texture("d.a", TextureDesc::d2(8, 8, F16)).unwrap();
    g.pass("d.fill")
        .write(a)
        .constants(&fill(1.0))
        .dispatch_threads(&check.fill, [8, 8, 1])
        .unwrap();
    let e = g.execute().unwrap_err().to_string();
    assert!(e.contains("no.such.thing") && e.contains("d.a"), "{e}");

    rt.set_dumps(vec!["d.a".into()]);
    let mut g = rt.begin_frame(&ctx);
    let a = g.texture("d.a", TextureDesc::d2(8, 8, F16)).unwrap();
    g.pass("d.fill")
        .write(a)
        .constants(&fill(0.5))
        .dispatch_threads(&check.fill, [8, 8, 1])
        .unwrap();
    let r = g.execute().unwrap();
    assert_eq!(r.image("d.a").unwrap().pixel(7, 7), [0.5, 0.5, 0.5, 1.0]);
}

/// A frame of two passes, `n.first` and `n.second`, both filling one texture.
fn two_fills(
    ctx: &hikari_render::GpuContext,
    check: &GraphCheck,
    rt: &mut GraphRuntime,
) -> hikari_render::graph::FrameResult {
    let mut g = rt.begin_frame(ctx);
    let a = g.texture("n.a", TextureDesc::d2(8, 8, F16)).unwrap();
    for (name, v) in [("n.first", 1.0), ("n.second", 2.0)] {
        g.pass(name)
            .write(a)
            .constants(&fill(v))
            .dispatch_threads(&check.fill, [8, 8, 1])
            .unwrap();
    }
    g.execute().unwrap()
}

#[test]
fn every_pass_gets_a_timing_row_under_its_name() {
    let (ctx, check) = setup();
    let mut rt = GraphRuntime::new();
    let r = two_fills(&ctx, &check, &mut rt);
    let names: Vec<&str> = r.timings.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["n.first", "n.second"]);
    if ctx.has(wgpu::Features::TIMESTAMP_QUERY) {
        assert!(
            r.timings.iter().all(|t| t.gpu_ms.is_some_and(|v| v >= 0.0)),
            "{:?}",
            r.timings
        );
        assert!(r.gpu_span_ms.is_some());
    }

    // Frame mode: one span, no per-pass numbers.
    rt.set_timestamps(TimestampMode::Frame);
    let r = two_fills(&ctx, &check, &mut rt);
    assert!(r.timings.iter().all(|t| t.gpu_ms.is_none()));
    assert_eq!(
        r.gpu_span_ms.is_some(),
        ctx.has(wgpu::Features::TIMESTAMP_QUERY)
    );
}
