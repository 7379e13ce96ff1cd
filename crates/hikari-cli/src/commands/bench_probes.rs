//! `hikari bench probes`: the irradiance probes' run-time costs that issue 17 sets targets
//! for, each timed on its own with GPU timestamps. Benchmarks print numbers; they never pass
//! or fail.
//!
//! * `irradiance_probes.relight_grid`: the talk's grid update, 8x8 + 3x3 = 73 tiles of 768
//!   probes (target 20 us; the talk: 123 us on a PS4);
//! * `irradiance_probes.relight_mesh`: one tetrahedral mesh of 5000 probes (target 10 us; the
//!   talk: 60 us), and `irradiance_probes.relight_scene_mesh`, the scene's largest mesh;
//! * `irradiance_probes.lookup`: the deferred lighting's probe lookup alone at every pixel of
//!   the frame (3840x2160 unless `--width`/`--height` say otherwise), on the frame's own
//!   G-buffer, writing the irradiance out.
//!
//! The relight dispatches copy the scene's baked probes as many times as the sizes need
//! (`hikari_render::techniques::irradiance_probes::relight_bench`) and run in a graph of their
//! own after each rendered frame; the lookup runs inside each rendered frame, right after the
//! G-buffer. The frame's own `irradiance_probes.relight` (its budget's tiles and one mesh in a
//! single dispatch) and `direct_lighting.shade` (which does the lookup among everything else)
//! are printed beside them.

use anyhow::Context;
use clap::Args;
use serde_json::json;

use hikari_render::graph::{GraphRuntime, TimestampMode};
use hikari_render::techniques::irradiance_probes::LOOKUP_PASS;
use hikari_render::techniques::irradiance_probes::relight_bench::{RelightBench, RelightBenchSpec};
use hikari_render::techniques::sky::{self, SkyParams, reference::SkyTwin};
use hikari_render::{FrameSettings, Renderer};

use crate::args::{FrameArgs, JsonArgs};
use crate::probe_bake;
use crate::report::{FrameTimings, PassRow};
use crate::scene_source::{self, ResolvedFrame};

/// The lookup is timed at 3840x2160 unless `--width`/`--height` say otherwise: the help says so.
#[derive(Args, Debug)]
#[command(
    mut_arg("width", |a| a.help("Image width in pixels [default: 3840]")),
    mut_arg("height", |a| a.help("Image height in pixels [default: 2160]"))
)]
pub struct BenchProbesArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Frames measured: each renders the scene (timing the lookup) and then runs the relight
    /// dispatches once.
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// Frames run first and not measured (the first relights every probe).
    #[arg(long, default_value_t = 10)]
    pub warmup: u32,
    /// Grid tiles of 768 probes in the grid dispatch, 1 to 4096 (the talk: 8x8 + 3x3).
    #[arg(long, default_value_t = 73)]
    pub grid_tiles: u32,
    /// Probes of the tetrahedral mesh dispatch, 1 to 1000000 (the talk: about 5000).
    #[arg(long, default_value_t = 5000)]
    pub mesh_probes: u32,
    /// Irradiance-probe bake file [default: the cache under $XDG_CACHE_HOME/hikari, baked on
    /// a miss].
    #[arg(long)]
    pub bake: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub output: JsonArgs,
}

/// The frame the lookup is timed on, unless `--width`/`--height` say otherwise.
const LOOKUP_SIZE: (u32, u32) = (3840, 2160);

/// The passes reported, in this order, with what each one is.
const REPORTED: [(&str, &str); 6] = [
    (
        hikari_render::techniques::irradiance_probes::relight_bench::GRID_PASS,
        "grid update",
    ),
    (
        hikari_render::techniques::irradiance_probes::relight_bench::MESH_PASS,
        "one tetrahedral mesh",
    ),
    (
        hikari_render::techniques::irradiance_probes::relight_bench::SCENE_MESH_PASS,
        "the scene's largest mesh",
    ),
    (LOOKUP_PASS, "lookup at every pixel"),
    (
        "irradiance_probes.relight",
        "the frame's relight (its budget, one dispatch)",
    ),
    (
        "direct_lighting.shade",
        "the deferred lighting (lookup included)",
    ),
];

/// The raw radiance SH (nits) of the frame's sky, from the sky's CPU twin (as `hikari probes`
/// relights).
fn sky_radiance_sh(frame: &FrameSettings) -> anyhow::Result<[glam::Vec3; 9]> {
    let s = &frame.settings.sky;
    let (params, sizes) = s.table_key().map_err(|e| anyhow::anyhow!("{e}"))?;
    let atmosphere = sky::atmosphere_for(&params, sizes)?;
    let cx = frame.context()?;
    let lights = cx
        .sky
        .as_ref()
        .context("the probes' relight needs the sky on")?
        .lights;
    let (raw, _) = SkyTwin::new(&atmosphere, SkyParams::new(&atmosphere, &lights, s, 0.0)).sh();
    Ok(raw.coeffs)
}

pub fn run(mut a: BenchProbesArgs) -> anyhow::Result<()> {
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    anyhow::ensure!(
        (1..=4096).contains(&a.grid_tiles),
        "--grid-tiles {} is outside 1 to 4096",
        a.grid_tiles
    );
    anyhow::ensure!(
        (1..=1_000_000).contains(&a.mesh_probes),
        "--mesh-probes {} is outside 1 to 1000000",
        a.mesh_probes
    );
    // The size for the lookup, unless asked otherwise.
    a.frame.size.width.get_or_insert(LOOKUP_SIZE.0);
    a.frame.size.height.get_or_insert(LOOKUP_SIZE.1);
    let ResolvedFrame {
        scene,
        settings,
        description,
        ..
    } = scene_source::resolve(&a.frame)?;
    let s = &settings.settings;
    anyhow::ensure!(
        s.irradiance_probes.enabled && s.sky.enabled && s.sky.sky,
        "bench probes: the probes are off (`irradiance_probes.enabled`, `sky.enabled` and \
         `sky.sky` must be on)"
    );
    let header = format!(
        "bench probes: {}, {} frames after {} warm-up",
        description.line(),
        a.frames,
        a.warmup
    );
    if !a.output.json {
        println!("{header}");
    }
    let sky_sh = sky_radiance_sh(&settings)?;
    let ctx = crate::still::gpu()?;
    let adapter = ctx.describe();
    let has_timestamps = ctx.has(hikari_render::wgpu::Features::TIMESTAMP_QUERY);
    let mut renderer = Renderer::new(ctx, &scene)?;
    probe_bake::attach(
        &mut renderer,
        &scene,
        &description.source,
        &settings,
        a.bake.as_deref(),
    )?;
    let data = renderer.irradiance_probes_state().data().ok_or_else(|| {
        anyhow::anyhow!(
            "bench probes: {} has no irradiance probes in its bake",
            description.line()
        )
    })?;
    renderer.irradiance_probes_state().set_lookup_pass(true);
    // The frame's relight is timed: its round robin runs even though the light stands still.
    renderer.irradiance_probes_state().set_never_rest(true);
    renderer.runtime.set_timestamps(TimestampMode::Pass);
    let spec = RelightBenchSpec {
        grid_tiles: a.grid_tiles,
        mesh_probes: a.mesh_probes,
    };
    let bench = RelightBench::new(&renderer.ctx, &data, &spec, &sky_sh)?;
    let mut bench_rt = GraphRuntime::new();
    bench_rt.set_timestamps(TimestampMode::Pass);

    let sun = settings.directional_light()?;
    let mut timings = FrameTimings::default();
    for i in 0..a.warmup + a.frames {
        let f = renderer.render(&settings, false)?;
        let mut g = bench_rt.begin_frame(&renderer.ctx);
        renderer.irradiance_probes().record_relight_bench(
            &mut g,
            &bench,
            sun.as_ref(),
            &s.irradiance_probes,
        )?;
        let r = g.execute()?;
        if i >= a.warmup {
            timings.add(&f.result);
            timings.add(&r);
        }
    }
    let summary = timings.summary();
    let pixels = settings.width as u64 * settings.height as u64;
    let counts = |pass: &str| -> serde_json::Value {
        if let Some(w) = bench.workloads.iter().find(|w| w.pass == pass) {
            json!({ "probes": w.probes, "tiles": w.tiles, "workgroups": w.chunk_count })
        } else if pass == LOOKUP_PASS || pass == "direct_lighting.shade" {
            json!({ "pixels": pixels })
        } else {
            json!({})
        }
    };
    let rows: Vec<(&str, &str, Option<&PassRow>)> = REPORTED
        .iter()
        .map(|&(name, what)| (name, what, summary.passes.iter().find(|p| p.name == name)))
        .filter(|(_, _, row)| row.is_some())
        .collect();
    if a.output.json {
        let passes: Vec<_> = rows
            .iter()
            .map(|(name, what, row)| {
                let row = row.unwrap();
                json!({
                    "name": name,
                    "what": what,
                    "counts": counts(name),
                    "gpu_us": row.gpu_ms.map(|s| json!({ "median": s.median * 1e3, "min": s.min * 1e3, "max": s.max * 1e3 })),
                    "cpu_us": row.cpu_us.json(),
                })
            })
            .collect();
        let out = json!({
            "benchmark": "probes",
            "adapter": adapter,
            "scene": description.json(),
            "width": settings.width, "height": settings.height,
            "frames": a.frames,
            "warmup": a.warmup,
            "bake": { "probes": data.probe_count(), "grid_tiles": data.tiles.len(), "meshes": data.meshes.len() },
            "timestamps": has_timestamps,
            "passes": passes,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("adapter: {adapter}");
    println!(
        "bake: {} probes, {} grid tiles, {} tetrahedral meshes",
        data.probe_count(),
        data.tiles.len(),
        data.meshes.len()
    );
    println!(
        "{:<38} {:>10} {:>9} {:>9} {:>11}  counts",
        "pass", "GPU med us", "min", "max", "CPU med us"
    );
    for (name, what, row) in rows {
        let row = row.unwrap();
        let f = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{:.1}", v * 1e3));
        let c = counts(name);
        let counts = match bench.workloads.iter().find(|w| w.pass == name) {
            Some(w) => format!("{} probes, {} tiles", w.probes, w.tiles),
            None if c.get("pixels").is_some() => format!("{pixels} pixels"),
            None => String::new(),
        };
        println!(
            "{:<38} {:>10} {:>9} {:>9} {:>11.1}  {counts} ({what})",
            name,
            f(row.gpu_ms.map(|s| s.median)),
            f(row.gpu_ms.map(|s| s.min)),
            f(row.gpu_ms.map(|s| s.max)),
            row.cpu_us.median,
        );
    }
    Ok(())
}
