//! `hikari bench overhead`: the frame graph's own cost, from frames of near-empty passes.
//! Benchmarks print numbers; they never pass or fail.

use std::time::Instant;

use clap::Args;
use serde_json::json;

use hikari_render::checks::graph_check::{EmptyParams, GraphCheck};
use hikari_render::graph::{GraphRuntime, TimestampMode};
use hikari_render::shader;
use hikari_render::{ContextOptions, GpuContext};

use crate::args::JsonArgs;
use crate::report::Stats;

#[derive(Args, Debug)]
pub struct OverheadArgs {
    /// Passes per frame.
    #[arg(long, default_value_t = 60)]
    pub passes: u32,
    /// Frames measured for each configuration.
    #[arg(long, default_value_t = 200)]
    pub frames: u32,
    /// Frames run first and not measured, for each configuration.
    #[arg(long, default_value_t = 20)]
    pub warmup: u32,
    #[command(flatten)]
    pub output: JsonArgs,
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

pub fn run(a: OverheadArgs) -> anyhow::Result<()> {
    anyhow::ensure!(a.passes >= 2, "--passes must be at least 2");
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    let mut lib = shader::library(shader::capabilities_for(ctx.features))?;
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
    if a.output.json {
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
