//! `hikari`: render, benchmark and inspect.

mod args;
mod commands;
mod config;
mod gpu_check;
mod probe_bake;
mod progress;
mod report;
mod scene_source;
mod still;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::{
    bake, bc6h, bench_frame, bench_overhead, bench_probes, bench_rays, bench_soak, compare,
    constants, info, lut, probes, render, sky, timelapse, view,
};

#[derive(Parser)]
#[command(
    name = "hikari",
    version,
    about = "A real-time lighting renderer: Ghost of Tsushima and Metro Exodus lighting, measured"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (display) and a linear EXR (radiance in nits).
    Render(Box<render::RenderArgs>),
    /// Open the scene in a window and render it live: fly the camera, turn the clock,
    /// switch techniques, see debug views and per-pass timings (docs/viewer.md).
    View(Box<view::ViewArgs>),
    /// Render a time-lapse: one view from --from to --to, the clock moving every frame,
    /// --count frames written as numbered PNGs and EXRs.
    Timelapse(Box<timelapse::TimelapseArgs>),
    /// Render one view twice, A and B, differing by settings; write A | B | FLIP error map and
    /// print the FLIP error, both exposures and the luminance ratio.
    Compare(Box<compare::CompareArgs>),
    /// Write the sky of a date, time, place and weather as an equirectangular EXR (nits) and
    /// print its L2 SH and the sun and moon.
    Sky(sky::SkyCommandArgs),
    /// Bake a scene's irradiance probes (on the GPU when there is one, else the CPU) into a bake file, by default the render cache.
    Bake(bake::BakeArgs),
    /// Count a scene's baked probes (`--json`: list every one, with its SH), or print their
    /// values interpolated at `--at` points, relit with `--date`/`--time`/`--weather`.
    Probes(probes::ProbesArgs),
    /// Benchmarks that print per-pass GPU timings.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Compress an HDR image (EXR) to BC6H_UF16 in a DDS file, as the reflection probes are,
    /// and print its error.
    Bc6h(bc6h::Bc6hArgs),
    /// Print the derived colour, spectral and scattering constants (no GPU needed).
    Constants(constants::ConstantsArgs),
    /// Print the GPU adapter, whether it can run hikari (and which feature it lacks if not),
    /// its features and limits.
    Info,
    /// Grading with 3D LUTs: read a grade back from a graded screenshot, or apply one.
    #[command(subcommand)]
    Lut(lut::LutCommand),
}

/// `hikari bench ...`: benchmarks print numbers; they never pass or fail.
#[derive(Subcommand, Debug)]
enum BenchCommand {
    /// Render N frames of a scene and print per-pass GPU median/min/max.
    Frame(Box<bench_frame::BenchFrameArgs>),
    /// Frame-graph overhead: frames of N near-empty passes, CPU and GPU cost per pass.
    Overhead(bench_overhead::OverheadArgs),
    /// BVH build times and GPU ray throughput (Grays/s) for closest and any hit.
    Rays(bench_rays::RaysArgs),
    /// The irradiance probes' relight (73 grid tiles, a 5000-probe mesh) and lookup (every
    /// pixel), each timed on its own.
    Probes(Box<bench_probes::BenchProbesArgs>),
    /// Many frames through the live path (clock, switches, camera cuts, resizes, scene
    /// reloads): memory sampled each cycle must stay flat, every output finite.
    Soak(Box<bench_soak::SoakArgs>),
}

/// Mesa's drivers complain on every start when XDG_RUNTIME_DIR is unset (containers, CI);
/// give them a private one.
fn ensure_runtime_dir() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hikari-runtime-{}", std::process::id()));
    if std::fs::create_dir_all(&dir).is_ok() {
        // SAFETY: called first thing in main, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

fn main() -> ExitCode {
    ensure_runtime_dir();
    // Log lines go above the progress bars, not through them.
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .target(env_logger::Target::Pipe(Box::new(progress::LogWriter)))
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(*args),
        Command::View(args) => view::run(*args),
        Command::Timelapse(args) => timelapse::run(*args),
        Command::Compare(args) => compare::run(*args),
        Command::Sky(args) => sky::run(args),
        Command::Bake(args) => bake::run(args),
        Command::Probes(args) => probes::run(args),
        Command::Bench(BenchCommand::Frame(args)) => bench_frame::run(*args),
        Command::Bench(BenchCommand::Overhead(args)) => bench_overhead::run(args),
        Command::Bench(BenchCommand::Rays(args)) => bench_rays::run(args),
        Command::Bench(BenchCommand::Probes(args)) => bench_probes::run(*args),
        Command::Bench(BenchCommand::Soak(args)) => bench_soak::run(*args),
        Command::Bc6h(args) => bc6h::run(args),
        Command::Constants(args) => constants::run(args),
        Command::Info => info::run(),
        Command::Lut(command) => lut::run(command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
