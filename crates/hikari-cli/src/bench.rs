//! `hikari bench`: per-pass GPU timings. Benchmarks print numbers; they never pass or fail.

use std::collections::BTreeMap;
use std::time::Instant;

use clap::{Args, Subcommand};
use serde_json::json;

use hikari_render::checks::graph_check::{EmptyParams, GraphCheck};
use hikari_render::graph::{FrameResult, GraphRuntime, TimestampMode};
use hikari_render::shader::{self, ShaderLibrary};
use hikari_render::{ContextOptions, GpuContext, Renderer};

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Render N frames of a scene and print per-pass GPU median/min/max.
    Frame(BenchFrameArgs),
    /// Frame-graph overhead: frames of N near-empty passes, CPU and GPU cost per pass.
    Overhead(OverheadArgs),
    /// BVH build times and GPU ray throughput (Grays/s) for closest and any hit.
    Rays(crate::bench_rays::RaysArgs),
}

#[derive(Args, Debug)]
pub struct BenchFrameArgs {
    #[command(flatten)]
    frame: crate::render::FrameArgs,
    /// Frames measured.
    #[arg(long, default_value_t = 100)]
    frames: u32,
    /// Frames rendered first and not measured.
    #[arg(long, default_value_t = 10)]
    warmup: u32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Time the whole frame only: untimed compute passes merge, as in normal rendering, so
    /// the frame span is the real cost (timing each pass adds about 10 us a pass).
    #[arg(long)]
    frame_only: bool,
    /// Move the camera forward this many metres every frame (with motion vectors), so that
    /// cached shadow cascades are redrawn as in a moving view; 0 keeps a still view.
    #[arg(long, default_value_t = 0.0)]
    dolly: f32,
}

#[derive(Args, Debug)]
pub struct OverheadArgs {
    /// Passes per frame.
    #[arg(long, default_value_t = 60)]
    passes: u32,
    #[arg(long, default_value_t = 200)]
    frames: u32,
    #[arg(long, default_value_t = 20)]
    warmup: u32,
    #[arg(long)]
    json: bool,
}

pub fn run(cmd: BenchCommand) -> anyhow::Result<()> {
    match cmd {
        BenchCommand::Frame(a) => frame(a),
        BenchCommand::Overhead(a) => overhead(a),
        BenchCommand::Rays(a) => crate::bench_rays::run(a),
    }
}

#[derive(Default, Clone, Copy, Debug)]
struct Stats {
    median: f64,
    min: f64,
    max: f64,
}

impl Stats {
    fn of(mut v: Vec<f64>) -> Option<Self> {
        if v.is_empty() {
            return None;
        }
        v.sort_by(|a, b| a.total_cmp(b));
        Some(Self {
            median: v[v.len() / 2],
            min: v[0],
            max: v[v.len() - 1],
        })
    }

    fn json(&self) -> serde_json::Value {
        json!({ "median": self.median, "min": self.min, "max": self.max })
    }
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The `--timings` table of a single frame.
pub fn print_single_frame(r: &FrameResult) {
    println!("{:<32} {:>10} {:>10}", "pass", "GPU ms", "CPU us");
    for t in &r.timings {
        let gpu = t.gpu_ms.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        println!("{:<32} {:>10} {:>10.1}", t.name, gpu, t.cpu_us);
    }
    if let Some(s) = r.gpu_span_ms {
        println!("{:<32} {:>10.4}", "frame (first to last pass)", s);
    }
}

fn frame(a: BenchFrameArgs) -> anyhow::Result<()> {
    let (scene, mut settings) = a.frame.resolve()?;
    anyhow::ensure!(
        a.dolly.is_finite() && a.dolly.abs() <= 100.0,
        "--dolly {} is outside -100 to 100 metres a frame",
        a.dolly
    );
    let scene_name = a.frame.scene.clone().unwrap_or_else(|| "village".into());
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    let adapter = ctx.describe();
    let startup = ctx.startup;
    let has_timestamps = ctx.has(hikari_render::wgpu::Features::TIMESTAMP_QUERY);
    let t0 = Instant::now();
    let mut renderer = Renderer::new(ctx, &scene)?;
    renderer.runtime.set_timestamps(if a.frame_only {
        TimestampMode::Frame
    } else {
        TimestampMode::Pass
    });
    let setup_ms = ms(t0.elapsed());
    for _ in 0..a.warmup {
        renderer.render(&settings, false)?;
    }
    let mut per_pass: BTreeMap<String, (usize, Vec<f64>, Vec<f64>)> = BTreeMap::new();
    let (mut spans, mut encode) = (Vec::new(), Vec::new());
    for _ in 0..a.frames {
        if a.dolly != 0.0 {
            let step = settings.camera.forward() * a.dolly;
            settings.prev_camera = Some(settings.camera.clone());
            settings.camera.position += step;
            settings.camera.target += step;
        }
        let f = renderer.render(&settings, false)?;
        for (i, t) in f.result.timings.iter().enumerate() {
            let e = per_pass
                .entry(t.name.clone())
                .or_insert((i, vec![], vec![]));
            e.1.extend(t.gpu_ms);
            e.2.push(t.cpu_us);
        }
        spans.extend(f.result.gpu_span_ms);
        encode.push(f.result.cpu_encode_us);
    }
    let mut rows: Vec<_> = per_pass.into_iter().collect();
    rows.sort_by_key(|(_, (i, _, _))| *i);
    let rows: Vec<(String, Option<Stats>, Stats)> = rows
        .into_iter()
        .map(|(name, (_, gpu, cpu))| (name, Stats::of(gpu), Stats::of(cpu).unwrap_or_default()))
        .collect();
    let span = Stats::of(spans);
    let encode = Stats::of(encode).unwrap_or_default();
    if a.json {
        let passes: Vec<_> = rows
            .iter()
            .map(
                |(n, g, c)| json!({ "name": n, "gpu_ms": g.map(|s| s.json()), "cpu_us": c.json() }),
            )
            .collect();
        let out = json!({
            "benchmark": "frame",
            "adapter": adapter,
            "scene": scene_name,
            "camera": settings.camera.name,
            "width": settings.width, "height": settings.height, "frames": a.frames,
            "triangles": renderer.scene().triangles,
            "startup_ms": { "instance": ms(startup.instance), "adapter": ms(startup.adapter), "device": ms(startup.device), "total": ms(startup.total()) },
            "pipelines_and_upload_ms": setup_ms,
            "timestamps": has_timestamps,
            "passes": passes,
            "frame_gpu_ms": span.map(|s| s.json()),
            "frame_cpu_encode_us": encode.json(),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("adapter: {adapter}");
    println!(
        "startup: {:.1} ms (instance {:.1}, adapter {:.1}, device {:.1}); pipelines + scene upload {:.1} ms",
        ms(startup.total()),
        ms(startup.instance),
        ms(startup.adapter),
        ms(startup.device),
        setup_ms
    );
    println!(
        "scene {} ({} triangles), {}x{}, {} frames after {} warm-up",
        scene_name,
        renderer.scene().triangles,
        settings.width,
        settings.height,
        a.frames,
        a.warmup
    );
    println!(
        "{:<32} {:>10} {:>10} {:>10} {:>12}",
        "pass", "GPU med ms", "min", "max", "CPU med us"
    );
    for (name, g, c) in &rows {
        match g {
            Some(g) => println!(
                "{:<32} {:>10.4} {:>10.4} {:>10.4} {:>12.1}",
                name, g.median, g.min, g.max, c.median
            ),
            None => println!(
                "{:<32} {:>10} {:>10} {:>10} {:>12.1}",
                name, "n/a", "", "", c.median
            ),
        }
    }
    // Per technique: the sum of its passes' medians (technique = name before the first dot).
    let mut techniques: Vec<(String, f64)> = Vec::new();
    for (name, g, _) in &rows {
        let t = name.split('.').next().unwrap_or(name).to_string();
        let ms = g.as_ref().map_or(0.0, |g| g.median);
        match techniques.iter_mut().find(|(n, _)| *n == t) {
            Some(e) => e.1 += ms,
            None => techniques.push((t, ms)),
        }
    }
    for (t, ms) in &techniques {
        println!("{:<32} {:>10.4}", format!("{t} (sum of medians)"), ms);
    }
    match span {
        Some(s) => println!(
            "{:<32} {:>10.4} {:>10.4} {:>10.4} {:>12.1}",
            "frame (first to last pass)", s.median, s.min, s.max, encode.median
        ),
        None => println!(
            "no GPU timestamps on this adapter; CPU encode median {:.1} us",
            encode.median
        ),
    }
    Ok(())
}

/// How the passes of the overhead benchmark relate.
#[derive(Clone, Copy, Debug)]
enum Chain {
    /// Passes read the same buffer and write nothing: no barriers.
    Independent,
    /// Each pass reads and writes one buffer: a barrier before every pass.
    Dependent,
}

/// CPU microseconds to record and encode one frame of `passes` empty passes, the GPU span
/// and each pass's GPU time.
fn overhead_frame(
    ctx: &GpuContext,
    rt: &mut GraphRuntime,
    check: &GraphCheck,
    passes: u32,
    chain: Chain,
) -> anyhow::Result<(f64, Option<f64>, Vec<f64>)> {
    let t0 = Instant::now();
    let mut g = rt.begin_frame(ctx);
    let (buffer, _) = g.persistent_buffer("overhead.buffer", 256)?;
    for i in 0..passes {
        let params = EmptyParams {
            value: [i as f32, 0.0, 0.0, 0.0],
        };
        match chain {
            Chain::Independent => g
                .pass("overhead.empty")
                .constants(&params)
                .read(buffer)
                .dispatch(&check.empty, [1, 1, 1])?,
            Chain::Dependent => g
                .pass("overhead.chain")
                .constants(&params)
                .write(buffer)
                .dispatch(&check.chain, [1, 1, 1])?,
        }
    }
    let record_us = t0.elapsed().as_secs_f64() * 1e6;
    let r = g.execute()?;
    let gpu: Vec<f64> = r.timings.iter().filter_map(|t| t.gpu_ms).collect();
    Ok((record_us + r.cpu_encode_us, r.gpu_span_ms, gpu))
}

fn overhead(a: OverheadArgs) -> anyhow::Result<()> {
    anyhow::ensure!(a.passes >= 2, "--passes must be at least 2");
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features))?;
    let check = GraphCheck::new(&ctx, &mut lib)?;
    let mut rt = GraphRuntime::new();
    let mut measure = |passes: u32,
                       chain: Chain,
                       mode: TimestampMode|
     -> anyhow::Result<(Stats, Option<Stats>, Option<Stats>)> {
        rt.set_timestamps(mode);
        for _ in 0..a.warmup {
            overhead_frame(&ctx, &mut rt, &check, passes, chain)?;
        }
        let (mut cpu, mut span, mut each) = (vec![], vec![], vec![]);
        for _ in 0..a.frames {
            let (c, s, e) = overhead_frame(&ctx, &mut rt, &check, passes, chain)?;
            cpu.push(c);
            span.extend(s);
            each.extend(e);
        }
        Ok((Stats::of(cpu).unwrap(), Stats::of(span), Stats::of(each)))
    };
    let n = a.passes as f64;
    let mut rows = Vec::new();
    for chain in [Chain::Independent, Chain::Dependent] {
        for mode in [TimestampMode::Frame, TimestampMode::Pass] {
            let (cpu1, span1, _) = measure(2, chain, mode)?;
            let (cpun, spann, each) = measure(a.passes, chain, mode)?;
            // The slope between a 2-pass and an N-pass frame is what each added pass costs,
            // free of the per-frame fixed cost (submission, timestamp resolve).
            let cpu_per_pass = (cpun.median - cpu1.median) / (n - 2.0);
            let gpu_per_pass = match (span1, spann) {
                (Some(s1), Some(sn)) => Some((sn.median - s1.median) * 1e3 / (n - 2.0)),
                _ => None,
            };
            rows.push((chain, mode, cpun, cpu_per_pass, spann, gpu_per_pass, each));
        }
    }
    if a.json {
        let out: Vec<_> = rows
            .iter()
            .map(|(chain, mode, cpun, cpu_pp, spann, gpu_pp, each)| {
                json!({
                    "passes": format!("{chain:?}"),
                    "timestamps": format!("{mode:?}"),
                    "cpu_frame_us": cpun.json(),
                    "cpu_us_per_pass": cpu_pp,
                    "gpu_span_ms": spann.map(|s| s.json()),
                    "gpu_us_per_pass": gpu_pp,
                    "gpu_ms_each_pass": each.map(|s| s.json()),
                })
            })
            .collect();
        let out = json!({ "benchmark": "overhead", "adapter": ctx.describe(), "passes": a.passes, "frames": a.frames, "results": out });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("adapter: {}", ctx.describe());
    println!(
        "frames of 2 and {} near-empty compute passes (a uniform and a storage buffer, 1 workgroup), {} frames each; medians",
        a.passes, a.frames
    );
    println!(
        "{:<12} {:<11} {:>13} {:>13} {:>14} {:>14} {:>15}",
        "passes",
        "timestamps",
        "CPU frame us",
        "CPU us/pass",
        "GPU span ms",
        "GPU us/pass",
        "GPU us one pass"
    );
    for (chain, mode, cpun, cpu_pp, spann, gpu_pp, each) in rows {
        let f = |v: Option<f64>, p: usize| v.map_or("n/a".to_string(), |v| format!("{v:.p$}"));
        println!(
            "{:<12} {:<11} {:>13.1} {:>13.2} {:>14} {:>14} {:>15}",
            format!("{chain:?}"),
            format!("{mode:?}"),
            cpun.median,
            cpu_pp,
            f(spann.map(|s| s.median), 4),
            f(gpu_pp, 2),
            f(each.map(|s| s.median * 1e3), 2),
        );
    }
    Ok(())
}
