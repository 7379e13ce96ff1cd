//! `hikari`: render, benchmark and inspect.

mod bench;
mod bench_rays;
mod config;
mod constants;
mod render;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    Render(render::RenderArgs),
    /// Benchmarks that print per-pass GPU timings.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Print the derived colour, spectral and scattering constants (no GPU needed).
    Constants(constants::ConstantsArgs),
    /// Print the GPU adapter, its features and limits.
    Info,
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
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(args),
        Command::Bench(cmd) => bench::run(cmd),
        Command::Constants(args) => constants::run(args),
        Command::Info => info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn info() -> anyhow::Result<()> {
    let ctx = hikari_render::GpuContext::new(&hikari_render::ContextOptions::from_env())?;
    println!("adapter:  {}", ctx.describe());
    println!(
        "startup:  {:.1} ms (instance {:.1}, adapter {:.1}, device {:.1})",
        ctx.startup.total().as_secs_f64() * 1e3,
        ctx.startup.instance.as_secs_f64() * 1e3,
        ctx.startup.adapter.as_secs_f64() * 1e3,
        ctx.startup.device.as_secs_f64() * 1e3
    );
    println!("features: {:?}", ctx.features);
    for f in [wgpu_fmt::RGBA16F, wgpu_fmt::RG11B10] {
        println!(
            "read-write storage {f:?}: {}",
            ctx.supports_read_write_storage(f)
        );
    }
    println!(
        "max 2D texture {}, max 3D texture {}, max storage buffer binding {} bytes",
        ctx.limits.max_texture_dimension_2d,
        ctx.limits.max_texture_dimension_3d,
        ctx.limits.max_storage_buffer_binding_size
    );
    Ok(())
}

mod wgpu_fmt {
    pub use hikari_render::techniques::direct_lighting::RADIANCE_FORMAT as RGBA16F;
    pub const RG11B10: hikari_render::wgpu::TextureFormat =
        hikari_render::wgpu::TextureFormat::Rg11b10Ufloat;
}
