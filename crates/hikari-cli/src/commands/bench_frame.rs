//! `hikari bench frame`: N frames of a scene, per-pass GPU median, min and max. Benchmarks
//! print numbers; they never pass or fail.

use std::time::Instant;

use clap::Args;
use serde_json::json;

use hikari_render::Renderer;
use hikari_render::graph::TimestampMode;
use hikari_render::techniques::ray_traced_gi::reference::HIT_NOT_TRACED;

use crate::args::{FrameArgs, JsonArgs};
use crate::probe_bake;
use crate::report::{BvhUpdates, FrameTimings, ms};
use crate::scene_source::{self, ResolvedFrame};

#[derive(Args, Debug)]
pub struct BenchFrameArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Frames measured.
    #[arg(long, default_value_t = 100)]
    pub frames: u32,
    /// Frames rendered first and not measured.
    #[arg(long, default_value_t = 10)]
    pub warmup: u32,
    #[command(flatten)]
    pub output: JsonArgs,
    /// Time the whole frame only: untimed compute passes merge, as in normal rendering, so
    /// the frame span is the real cost (timing each pass adds about 10 us a pass).
    #[arg(long)]
    pub frame_only: bool,
    /// Move the camera forward this many metres every frame (with motion vectors), so that
    /// cached shadow cascades are redrawn as in a moving view; 0 keeps a still view.
    #[arg(long, default_value_t = 0.0)]
    pub dolly: f32,
    /// Advance the scene time (`scene_rt.time_s`, from 0 or its configured value) this many
    /// seconds every frame, so that deforming meshes move and their BLAS are refitted (under
    /// the refit budget) as in a running game; 0 keeps the time still.
    #[arg(long, default_value_t = 0.0)]
    pub time_step: f32,
    /// Move the sky's clock this many seconds every frame (through the live renderer API,
    /// as `timelapse` and the viewer do), so that the sun, sky, clouds, probes and haze follow
    /// a moving light; 0 keeps the clock still. Compare with a still clock to see what a
    /// clock change costs.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub clock_step: f64,
}

pub fn run(a: BenchFrameArgs) -> anyhow::Result<()> {
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    anyhow::ensure!(
        a.dolly.is_finite() && a.dolly.abs() <= 100.0,
        "--dolly {} is outside -100 to 100 metres a frame",
        a.dolly
    );
    anyhow::ensure!(
        a.time_step.is_finite() && a.time_step.abs() <= 10.0,
        "--time-step {} is outside -10 to 10 seconds a frame",
        a.time_step
    );
    anyhow::ensure!(
        a.clock_step.is_finite() && a.clock_step.abs() <= 3600.0,
        "--clock-step {} is outside -3600 to 3600 seconds a frame",
        a.clock_step
    );
    let ResolvedFrame {
        scene,
        mut settings,
        description,
        ..
    } = scene_source::resolve(&a.frame)?;
    // What runs, stated before the (possibly long) run, from what was resolved rather than
    // from the flags alone: a config file can name the scene, camera, time and size too.
    let header = format!(
        "bench frame: {}, {} frames after {} warm-up{}{}",
        description.line(),
        a.frames,
        a.warmup,
        if a.dolly != 0.0 {
            format!(", dolly {} m a frame", a.dolly)
        } else {
            String::new()
        },
        if a.clock_step != 0.0 {
            format!(", clock {} s a frame", a.clock_step)
        } else {
            String::new()
        }
    );
    if !a.output.json {
        println!("{header}");
    }
    let ctx = crate::still::gpu()?;
    let adapter = ctx.describe();
    let startup = ctx.startup;
    let has_timestamps = ctx.has(hikari_render::wgpu::Features::TIMESTAMP_QUERY);
    let t0 = Instant::now();
    let mut renderer = Renderer::new(ctx, &scene)?;
    probe_bake::attach(&mut renderer, &scene, &description.source, &settings, None)?;
    renderer.runtime.set_timestamps(if a.frame_only {
        TimestampMode::Frame
    } else {
        TimestampMode::Pass
    });
    let setup_ms = ms(t0.elapsed());
    renderer.set_frame(settings.clone())?;
    let clock = settings
        .settings
        .sky
        .date_time()
        .map(|t| f64::from(t.seconds_of_day()))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    for _ in 0..a.warmup {
        renderer.frame(false)?;
    }
    let mut timings = FrameTimings::default();
    let mut bvh = BvhUpdates::default();
    for i in 0..a.frames {
        if a.dolly != 0.0 {
            let step = settings.camera.forward() * a.dolly;
            settings.prev_camera = Some(settings.camera.clone());
            settings.camera.position += step;
            settings.camera.target += step;
        }
        if a.time_step != 0.0 {
            let t = settings.settings.scene_rt.time_s.unwrap_or(0.0);
            settings.settings.scene_rt.time_s = Some(t + a.time_step);
        }
        if a.dolly != 0.0 || a.time_step != 0.0 {
            renderer.set_settings(settings.settings.clone())?;
            renderer.set_camera(settings.camera.clone(), false)?;
        }
        if a.clock_step != 0.0 {
            renderer.set_time_of_day(clock + a.clock_step * f64::from(i + 1))?;
        }
        let f = renderer.frame(false)?;
        timings.add(&f.result);
        bvh.add(renderer.scene_rt_stats());
    }
    let mut summary = timings.summary();
    if !a.frame_only {
        summary.bandwidth_gbs = Some(copy_bandwidth(&renderer.ctx)?);
    }
    let triangles = renderer.scene().triangles;
    let rays = if settings.settings.ray_traced_gi.enabled {
        Some(gi_ray_counts(&mut renderer, &settings)?)
    } else {
        None
    };
    if a.output.json {
        let out = json!({
            "benchmark": "frame",
            "adapter": adapter,
            "scene": description.json(),
            // Also at the top level, where reports before the `scene` object read them.
            "camera": description.camera,
            "width": settings.width, "height": settings.height,
            "frames": a.frames,
            "warmup": a.warmup,
            "dolly_m": a.dolly,
            "time_step_s": a.time_step,
            "clock_step_s": a.clock_step,
            "frame_only": a.frame_only,
            "triangles": triangles,
            "startup_ms": { "instance": ms(startup.instance), "adapter": ms(startup.adapter), "device": ms(startup.device), "total": ms(startup.total()) },
            "pipelines_and_upload_ms": setup_ms,
            "timestamps": has_timestamps,
            "passes": summary.passes_json(),
            "frame_gpu_ms": summary.span_ms.map(|s| s.json()),
            "frame_cpu_encode_us": summary.encode_us.json(),
            "scene_bvh_update": bvh.json(),
            "gi_rays": rays.map(|r| r.json()),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("adapter: {adapter}");
    println!(
        "startup: {:.1} ms (instance {:.1}, adapter {:.1}, device {:.1}); pipelines + scene upload {:.1} ms; {} triangles",
        ms(startup.total()),
        ms(startup.instance),
        ms(startup.adapter),
        ms(startup.device),
        setup_ms,
        triangles
    );
    summary.print_table();
    bvh.print();
    if let Some(r) = rays {
        r.print();
    }
    Ok(())
}

/// Where one frame's GI rays ended (read back after the timed frames, so the read-back
/// costs none of them): rays are the pixels with a surface; the pre-trace resolved those it
/// hit in the depth buffer, and queued the rest for the BVH.
struct GiRayCounts {
    traced: u64,
    queued: u64,
}

impl GiRayCounts {
    fn resolved(&self) -> u64 {
        self.traced.saturating_sub(self.queued)
    }

    fn percent(&self) -> f64 {
        100.0 * self.resolved() as f64 / self.traced.max(1) as f64
    }

    fn json(&self) -> serde_json::Value {
        json!({
            "traced": self.traced,
            "pretrace_resolved": self.resolved(),
            "bvh_queued": self.queued,
            "pretrace_percent": self.percent(),
        })
    }

    fn print(&self) {
        println!(
            "GI rays: {} traced, the pre-trace resolved {} ({:.1} %), {} went to the BVH",
            self.traced,
            self.resolved(),
            self.percent(),
            self.queued
        );
    }
}

fn gi_ray_counts(
    renderer: &mut Renderer,
    settings: &hikari_render::FrameSettings,
) -> anyhow::Result<GiRayCounts> {
    let r = renderer.render_reading(settings, |o| match o.ray_traced_gi_rays {
        Some(rays) => vec![rays.hits.into(), rays.queue.into()],
        None => Vec::new(),
    })?;
    let words = |name: &str| -> Vec<u32> {
        r.buffer(name)
            .unwrap_or_default()
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let hits = words("ray_traced_gi.hits");
    let queue = words("ray_traced_gi.queue");
    Ok(GiRayCounts {
        traced: hits.iter().filter(|&&w| w != HIT_NOT_TRACED).count() as u64,
        queued: queue.first().copied().unwrap_or(0) as u64,
    })
}

/// The adapter's memory bandwidth as a large buffer copy sees it, GB/s of read plus write:
/// the rate against which `bench frame` states each pass's memory floor. 256 MiB copied as
/// many times as make about 50 ms (once on the CPU driver), timed on the host from submit to
/// done, after one copy that is not timed.
fn copy_bandwidth(ctx: &hikari_render::GpuContext) -> anyhow::Result<f64> {
    use hikari_render::wgpu;
    let size: u64 = (256u64 << 20).min(ctx.limits.max_buffer_size);
    let make = |label| {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let (src, dst) = (make("bench.bandwidth.src"), make("bench.bandwidth.dst"));
    let copies = |n: u32| -> anyhow::Result<f64> {
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        for _ in 0..n {
            enc.copy_buffer_to_buffer(&src, 0, &dst, 0, size);
        }
        let t = Instant::now();
        ctx.queue.submit([enc.finish()]);
        ctx.wait_idle()?;
        Ok(t.elapsed().as_secs_f64())
    };
    let one = copies(1)?.max(1e-6);
    let n = ((0.05 / one).ceil() as u32).clamp(1, 256);
    let seconds = copies(n)?;
    Ok(2.0 * size as f64 * f64::from(n) / seconds.max(1e-9) / 1e9)
}
