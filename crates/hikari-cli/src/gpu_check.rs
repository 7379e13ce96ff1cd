//! Whether a GPU adapter can run hikari: the features beyond WebGPU's core that the renderer
//! cannot do without (`hikari_render::context::REQUIRED_FEATURES`: 64-bit integer atomics,
//! which the compute rasteriser resolves visibility with). `hikari info` says it, and the
//! commands that render refuse such an adapter at start-up with the same words, instead of
//! failing later in a shader.

use hikari_render::GpuContext;
use hikari_render::context::REQUIRED_FEATURES;
use hikari_render::wgpu;

/// What a user reads about a feature hikari needs.
fn explain(name: &str) -> &'static str {
    match name {
        "SHADER_INT64" => "64-bit integers in shaders",
        "SHADER_INT64_ATOMIC_MIN_MAX" => "64-bit atomic min and max in shaders",
        "SHADER_INT64_ATOMIC_ALL_OPS" => "every 64-bit atomic operation in shaders",
        _ => "a shader feature",
    }
}

/// The required features `adapter` lacks, by wgpu's name with what each is.
pub fn missing(adapter: wgpu::Features) -> Vec<String> {
    (REQUIRED_FEATURES & adapter.complement())
        .iter_names()
        .map(|(name, _)| format!("{name} ({})", explain(name)))
        .collect()
}

/// Why the adapter `name` on `backend` with `features` cannot run hikari, or `None` when it
/// can.
pub fn why_not(name: &str, backend: wgpu::Backend, features: wgpu::Features) -> Option<String> {
    let missing = missing(features);
    if missing.is_empty() {
        return None;
    }
    let advice = match backend {
        wgpu::Backend::Gl => {
            " OpenGL has no 64-bit atomics: use Vulkan, Metal or DX12 (WGPU_BACKEND), or the \
             CPU Vulkan driver (`./x setup`, or `apt-get install mesa-vulkan-drivers`)."
        }
        _ => {
            " Try another adapter (WGPU_ADAPTER_NAME, WGPU_BACKEND; `hikari info` lists the \
             one picked), a newer driver, or the CPU Vulkan driver (`./x setup`)."
        }
    };
    Some(format!(
        "the GPU adapter {name} ({backend:?}) cannot run hikari: it lacks {}, which the compute \
         rasteriser needs.{advice}",
        missing.join(", ")
    ))
}

/// An error when `ctx`'s adapter lacks a feature hikari needs.
pub fn ensure_can_run(ctx: &GpuContext) -> anyhow::Result<()> {
    match why_not(&ctx.info.name, ctx.info.backend, ctx.adapter.features()) {
        Some(why) => anyhow::bail!("{why}"),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_adapter_without_64_bit_atomics_is_named_with_what_it_lacks() {
        assert_eq!(
            why_not("Test GPU", wgpu::Backend::Vulkan, REQUIRED_FEATURES),
            None
        );
        assert_eq!(
            why_not(
                "Test GPU",
                wgpu::Backend::Vulkan,
                REQUIRED_FEATURES | wgpu::Features::TIMESTAMP_QUERY
            ),
            None
        );
        let without = REQUIRED_FEATURES & wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS.complement();
        let why = why_not("Test GPU", wgpu::Backend::Vulkan, without).unwrap();
        assert!(
            why.contains("Test GPU")
                && why.contains("SHADER_INT64_ATOMIC_ALL_OPS")
                && !why.contains("SHADER_INT64_ATOMIC_MIN_MAX"),
            "{why}"
        );
        let why = why_not("Test GPU", wgpu::Backend::Gl, wgpu::Features::empty()).unwrap();
        for name in [
            "SHADER_INT64 ",
            "SHADER_INT64_ATOMIC_MIN_MAX",
            "SHADER_INT64_ATOMIC_ALL_OPS",
            "OpenGL",
        ] {
            assert!(why.contains(name), "{name}: {why}");
        }
    }
}
