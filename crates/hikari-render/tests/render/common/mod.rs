//! Shared by the GPU tests. They run on whatever adapter the environment picks (the CPU
//! Vulkan driver in CI). There is no way to skip them: a test that cannot get an adapter
//! fails, so a machine without one never reports GPU tests as passed.

#![allow(dead_code)]

pub mod cutout;
pub mod probes;

use hikari_render::{ContextOptions, GpuContext};

/// The GPU context for a test; panics (failing the test) when there is no adapter. Every
/// test of the binary talks to one device, so that the renderer's pipelines are compiled
/// once ([`GpuContext::shared`]) rather than by each of the hundred renderers the tests make:
/// on the CPU driver that compile is seconds.
pub fn gpu_context() -> GpuContext {
    static CONTEXT: std::sync::OnceLock<GpuContext> = std::sync::OnceLock::new();
    CONTEXT
        .get_or_init(|| {
            GpuContext::new(&ContextOptions::from_env()).unwrap_or_else(|e| {
                panic!(
                    "GPU tests need an adapter and fail without one (set WGPU_BACKEND and \
                     VK_ICD_FILENAMES for the CPU Vulkan driver): {e}"
                )
            })
        })
        .clone()
}

/// Pixels (or shadow-map texels) a rasteriser's output may have that disagree with rays cast
/// through the same centres: only centres within rounding of an edge two triangles share, or
/// of a silhouette, may go either way, and those form thin lines, not areas. The budget is at
/// most 256, a quarter of one 32x32 tile (1024 px), so one tile the rasteriser loses (its
/// queue entries dropped, a workgroup that never ran) fails a comparison at any image size;
/// the raster and shadow-map tests drop a tile from their GPU result to check that it does.
pub fn allowed_differences(pixels: usize) -> usize {
    (pixels / 2000).clamp(16, 256)
}

/// A texture filled from `data` (tightly packed rows).
pub fn texture_with_data(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    w: u32,
    h: u32,
    data: &[u8],
) -> wgpu::Texture {
    use wgpu::util::DeviceExt;
    ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("test input"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        data,
    )
}

/// Frame settings for a small test image of `scene` from its first camera: the scene's sun,
/// two 256-texel shadow cascades over 40 m (small maps keep the CPU driver fast).
pub fn small_frame_settings(
    scene: &hikari_scene::Scene,
    w: u32,
    h: u32,
) -> hikari_render::FrameSettings {
    let mut settings = hikari_render::Settings::default();
    settings.sun_shadows.resolution = 256;
    settings.sun_shadows.cascades = 2;
    settings.sun_shadows.max_distance_m = 40.0;
    // The atmosphere has its own tests (tests/sky.rs); here the placeholders light the frame.
    settings.sky.enabled = false;
    // Ray-traced GI has its own tests (tests/render/ray_traced_gi/, gi_validation.rs): here the
    // frame's other techniques are checked against their twins, which leave it out.
    settings.ray_traced_gi.enabled = false;
    // The haze and the clouds have their own tests (tests/haze.rs, clouds.rs), which hold the
    // frame with them to their twins; here they would add light the other twins leave out.
    settings.haze.enabled = false;
    settings.clouds.enabled = false;
    hikari_render::FrameSettings {
        width: w,
        height: h,
        camera: scene.cameras[0].clone(),
        prev_camera: None,
        sun: scene.sun.clone().into(),
        settings,
    }
}

/// Clouds small enough for the CPU driver (a 64² map, 16 steps with 3 towards the light) with
/// features of `feature_m` metres, so that a small view holds cloud edges.
pub fn small_clouds(coverage: f32, feature_m: f32) -> hikari_render::settings::CloudsSettings {
    hikari_render::settings::CloudsSettings {
        enabled: true,
        coverage,
        feature_m,
        map_size: 64,
        steps: 16,
        light_steps: 3,
        ..Default::default()
    }
}
