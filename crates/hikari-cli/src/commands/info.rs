//! `hikari info`: the GPU adapter, whether it can run hikari (and if not, which feature it
//! lacks), its features and limits.

use hikari_render::{ContextOptions, GpuContext};

use crate::gpu_check;

pub fn run() -> anyhow::Result<()> {
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    println!("adapter:  {}", ctx.describe());
    let verdict = gpu_check::why_not(&ctx.info.name, ctx.info.backend, ctx.adapter.features());
    match &verdict {
        None => println!("hikari:   can run on this adapter (64-bit integer atomics present)"),
        Some(why) => println!("hikari:   cannot run: {why}"),
    }
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
    match ctx.memory_bytes {
        Some(b) => println!(
            "memory:   {} MB device-local (a frame that needs more is refused before it runs)",
            b / 1_000_000
        ),
        None => println!("memory:   not reported by this backend"),
    }
    // A script can ask `hikari info` whether hikari runs here by its exit status.
    match verdict {
        None => Ok(()),
        Some(_) => anyhow::bail!("this adapter cannot run hikari (see above)"),
    }
}

mod wgpu_fmt {
    pub use hikari_render::techniques::direct_lighting::RADIANCE_FORMAT as RGBA16F;
    pub const RG11B10: hikari_render::wgpu::TextureFormat =
        hikari_render::wgpu::TextureFormat::Rg11b10Ufloat;
}
