//! Shared by the GPU tests. They run on whatever adapter the environment picks (the CPU
//! Vulkan driver in CI); with no adapter they fail, unless HIKARI_SKIP_GPU_TESTS=1.

#![allow(dead_code)]

use hikari_render::{ContextOptions, GpuContext};

pub fn gpu() -> Option<GpuContext> {
    if std::env::var("HIKARI_SKIP_GPU_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("HIKARI_SKIP_GPU_TESTS=1: skipping a GPU test");
        return None;
    }
    match GpuContext::new(&ContextOptions::from_env()) {
        Ok(ctx) => Some(ctx),
        Err(e) => panic!("GPU tests need an adapter (or HIKARI_SKIP_GPU_TESTS=1): {e}"),
    }
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
    hikari_render::FrameSettings {
        width: w,
        height: h,
        camera: scene.cameras[0].clone(),
        prev_camera: None,
        sun: scene.sun.clone(),
        settings,
    }
}
