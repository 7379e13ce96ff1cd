//! Measures raster fill rate on the current GPU: full-screen triangles into various attachment
//! sets, timed with GPU timestamps. `cargo run --release --example raster_fill_rate`.

use hikari_render::{ContextOptions, GpuContext};

const SHADER: &str = r#"
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.5, 1.0);
}
@fragment fn fs1() -> @location(0) vec4<f32> { return vec4<f32>(0.5); }
struct Two { @location(0) a: vec4<f32>, @location(1) b: vec4<f32> }
@fragment fn fs2() -> Two { return Two(vec4<f32>(0.5), vec4<f32>(0.25)); }
"#;

fn main() {
    let ctx = GpuContext::new(&ContextOptions::from_env()).expect("adapter");
    println!("{}", ctx.describe());
    let (w, h) = (3840u32, 2160u32);
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
    let qs = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
        label: None,
        ty: wgpu::QueryType::Timestamp,
        count: 2,
    });
    let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let tex = |format, storage: bool| {
        let mut usage =
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        if storage {
            usage |= wgpu::TextureUsages::STORAGE_BINDING;
        }
        ctx.device
            .create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    use wgpu::TextureFormat as F;
    // (name, colour formats with STORAGE usage or not, depth attachment, instances)
    type Case = (&'static str, Vec<(F, bool)>, bool, u32);
    let cases: Vec<Case> = vec![
        ("depth only", vec![], true, 1),
        ("1x rgba8", vec![(F::Rgba8Unorm, false)], false, 1),
        (
            "1x rgba8 +storage usage",
            vec![(F::Rgba8Unorm, true)],
            false,
            1,
        ),
        ("1x rgba16f", vec![(F::Rgba16Float, false)], false, 1),
        (
            "rg16f+rgba8+depth (gbuffer)",
            vec![(F::Rg16Float, true), (F::Rgba8Unorm, true)],
            true,
            1,
        ),
        (
            "1x rgba8, 8 layers overdraw",
            vec![(F::Rgba8Unorm, false)],
            false,
            8,
        ),
    ];
    for (name, colors, depth, layers) in cases {
        let views: Vec<_> = colors.iter().map(|(f, s)| tex(*f, *s)).collect();
        let dview = depth.then(|| tex(F::Depth32Float, false));
        let targets: Vec<_> = colors
            .iter()
            .map(|(f, _)| {
                Some(wgpu::ColorTargetState {
                    format: *f,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .collect();
        let fs = if colors.len() > 1 { "fs2" } else { "fs1" };
        let targets3 = targets.clone();
        let pipe = ctx
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: None,
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: dview.as_ref().map(|_| wgpu::DepthStencilState {
                    format: F::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Always),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: (!colors.is_empty()).then(|| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &targets3,
                }),
                multiview_mask: None,
                cache: None,
            });
        let mut samples = vec![];
        for _ in 0..20 {
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            {
                let atts: Vec<_> = views
                    .iter()
                    .map(|v| {
                        Some(wgpu::RenderPassColorAttachment {
                            view: v,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    })
                    .collect();
                let mut rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: None,
                    color_attachments: &atts,
                    depth_stencil_attachment: dview.as_ref().map(|v| {
                        wgpu::RenderPassDepthStencilAttachment {
                            view: v,
                            depth_ops: Some(wgpu::Operations {
                                load: wgpu::LoadOp::Clear(0.0),
                                store: wgpu::StoreOp::Store,
                            }),
                            stencil_ops: None,
                        }
                    }),
                    timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                        query_set: &qs,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(&pipe);
                rp.draw(0..3, 0..layers);
            }
            enc.resolve_query_set(&qs, 0..2, &resolve, 0);
            enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, 16);
            ctx.queue.submit([enc.finish()]);
            read.slice(..).map_async(wgpu::MapMode::Read, |_| {});
            ctx.wait_idle().unwrap();
            let t: Vec<u64> =
                bytemuck::cast_slice(&read.slice(..).get_mapped_range().unwrap()).to_vec();
            read.unmap();
            samples.push((t[1] - t[0]) as f64 * ctx.queue.get_timestamp_period() as f64 * 1e-6);
        }
        samples.sort_by(f64::total_cmp);
        let ms = samples[10];
        println!(
            "{name:<32} {ms:8.3} ms  {:6.2} Gpixel/s",
            (w * h * layers) as f64 / ms / 1e6
        );
    }
}
