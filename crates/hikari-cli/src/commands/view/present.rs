//! Putting the frame on the window: the surface, the texture the renderer draws into (shown
//! by egui as the background), egui's paint with its own GPU timestamp pair (the `ui` pass of
//! the table), and reading the picture back for `--screenshot`.

use std::sync::Arc;

use anyhow::Context;
use hikari_render::graph::ImageRgba32;
use hikari_render::techniques::debug_view::TARGET_FORMAT;
use winit::window::Window;

/// The texture the renderer writes the frame into, registered with egui.
pub struct Picture {
    pub texture: wgpu::Texture,
    pub id: egui::TextureId,
}

/// egui's paint, timed with a pair of timestamps when the device has them.
struct UiTimer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    period_ns: f32,
}

pub struct Presenter {
    instance: wgpu::Instance,
    adapter: wgpu::Adapter,
    window: Arc<Window>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    pub egui: egui_wgpu::Renderer,
    timer: Option<UiTimer>,
    pub picture: Option<Picture>,
    /// Paints so far, and the one at which `HIKARI_VIEW_FAULT=surface-lost@N` pretends the
    /// surface was lost.
    paints: u64,
    lose_at: Option<u64>,
    /// Times the surface was lost and made anew.
    pub recreated: u32,
}

/// The surface format: a non-sRGB one, so that the display-encoded frame shows as it is;
/// else the first, and egui converts.
fn pick_format(formats: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    formats
        .iter()
        .copied()
        .find(|f| {
            matches!(
                f,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
            )
        })
        .or_else(|| formats.first().copied())
}

impl Presenter {
    pub fn new(
        instance: &wgpu::Instance,
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        window: Arc<Window>,
    ) -> anyhow::Result<Self> {
        let size = window.inner_size();
        let surface = instance.create_surface(window.clone()).context(
            "cannot show a window on this GPU (wgpu found no surface for it): try another \
             adapter (WGPU_ADAPTER_NAME) or the CPU Vulkan driver (mesa-vulkan-drivers)",
        )?;
        let caps = surface.get_capabilities(adapter);
        let format = pick_format(&caps.formats).with_context(|| {
            format!(
                "the GPU `{}` cannot present to this window (no surface format); try another \
                 adapter with WGPU_ADAPTER_NAME, or the CPU driver (WGPU_BACKEND=vulkan and \
                 mesa-vulkan-drivers)",
                adapter.get_info().name
            )
        })?;
        let mut config = surface
            .get_default_config(adapter, size.width.max(1), size.height.max(1))
            .context("the surface offers no configuration for this GPU")?;
        config.format = format;
        config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        // Frames in flight: the CPU records the next frame while the GPU draws this one.
        config.desired_maximum_frame_latency = 2;
        config.present_mode = wgpu::PresentMode::AutoVsync;
        surface.configure(device, &config);
        let egui = egui_wgpu::Renderer::new(
            device,
            format,
            egui_wgpu::RendererOptions {
                // The frame's pixels are shown exactly as rendered.
                dithering: false,
                ..Default::default()
            },
        );
        let timer = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| UiTimer {
                queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("view.ui.timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                }),
                resolve: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("view.ui.resolve"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                read: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("view.ui.read"),
                    size: 16,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                period_ns: queue.get_timestamp_period(),
            });
        Ok(Self {
            instance: instance.clone(),
            adapter: adapter.clone(),
            window,
            paints: 0,
            lose_at: super::faults::surface_lost_at(),
            recreated: 0,
            device: device.clone(),
            queue: queue.clone(),
            surface,
            config,
            egui,
            timer,
            picture: None,
        })
    }

    /// A new surface for the window, configured as the lost one was.
    fn recreate(&mut self) -> anyhow::Result<()> {
        let surface = self
            .instance
            .create_surface(self.window.clone())
            .context("the window's surface was lost and a new one could not be made")?;
        let caps = surface.get_capabilities(&self.adapter);
        if !caps.formats.contains(&self.config.format) {
            anyhow::bail!(
                "the window's surface was lost and the new one lacks the format {:?}",
                self.config.format
            );
        }
        surface.configure(&self.device, &self.config);
        self.surface = surface;
        self.recreated += 1;
        log::info!("the window's surface was lost; made a new one");
        Ok(())
    }

    /// Follows the window's new size.
    pub fn resize(&mut self, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&self.device, &self.config);
    }

    pub fn size(&self) -> [u32; 2] {
        [self.config.width, self.config.height]
    }

    /// The picture at `size`, made anew (and registered with egui) when the size changed.
    pub fn picture(&mut self, size: [u32; 2]) -> &Picture {
        let stale = self.picture.as_ref().is_none_or(|p| {
            let s = p.texture.size();
            [s.width, s.height] != size
        });
        if stale {
            let texture = self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("view.picture"),
                size: wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: TARGET_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            let id = match self.picture.take() {
                Some(old) => {
                    self.egui.update_egui_texture_from_wgpu_texture(
                        &self.device,
                        &view,
                        wgpu::FilterMode::Nearest,
                        old.id,
                    );
                    old.id
                }
                None => self.egui.register_native_texture(
                    &self.device,
                    &view,
                    wgpu::FilterMode::Nearest,
                ),
            };
            self.picture = Some(Picture { texture, id });
        }
        self.picture.as_ref().unwrap()
    }

    /// Paints egui's output on the window and presents it. Returns the paint's GPU time in ms
    /// with `time` (waiting for it), and the CPU time its recording took on this thread in µs
    /// (from the surface's texture acquired to the submission).
    pub fn paint(
        &mut self,
        textures: &mut egui::TexturesDelta,
        primitives: &[egui::ClippedPrimitive],
        pixels_per_point: f32,
        time: bool,
    ) -> anyhow::Result<(Option<f64>, f64)> {
        // egui's own textures (the font atlas) change even when nothing is painted.
        for (id, deltas) in &textures.set {
            for delta in deltas {
                self.egui
                    .update_texture(&self.device, &self.queue, *id, delta);
            }
        }
        textures.set.clear();
        self.paints += 1;
        let current = if self.lose_at == Some(self.paints) {
            wgpu::CurrentSurfaceTexture::Lost
        } else {
            self.surface.get_current_texture()
        };
        let frame = match current {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            other => {
                match other {
                    // The window changed under the surface (a resize the event has not
                    // reached yet): configure it again.
                    wgpu::CurrentSurfaceTexture::Outdated => {
                        self.surface.configure(&self.device, &self.config)
                    }
                    // The surface itself is gone (the compositor restarted, the display
                    // changed): make a new one for the same window.
                    wgpu::CurrentSurfaceTexture::Lost => self.recreate()?,
                    _ => {}
                }
                // Occluded, a timeout, or reconfigured: skip this paint.
                for id in textures.free.drain() {
                    self.egui.free_texture(&id);
                }
                return Ok((None, 0.0));
            }
        };
        let t0 = super::stats::thread_cpu_us();
        let view = frame.texture.create_view(&Default::default());
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point,
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("view.ui"),
            });
        let extra =
            self.egui
                .update_buffers(&self.device, &self.queue, &mut encoder, primitives, &screen);
        let timer = self.timer.as_ref().filter(|_| time);
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("view.ui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: timer.map(|t| wgpu::RenderPassTimestampWrites {
                        query_set: &t.queries,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.egui.render(&mut pass, primitives, &screen);
        }
        if let Some(t) = timer {
            encoder.resolve_query_set(&t.queries, 0..2, &t.resolve, 0);
            encoder.copy_buffer_to_buffer(&t.resolve, 0, &t.read, 0, 16);
        }
        let commands = extra
            .into_iter()
            .chain([encoder.finish()])
            .collect::<Vec<_>>();
        // The recording's CPU time, on this thread; the submission and the present are the
        // driver's and the window system's.
        let cpu_us = super::stats::thread_cpu_us() - t0;
        self.queue.submit(commands);
        self.queue.present(frame);
        for id in textures.free.drain() {
            self.egui.free_texture(&id);
        }
        let Some(t) = timer else {
            return Ok((None, cpu_us));
        };
        let slice = t.read.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("waiting for the UI's timestamps: {e}"))?;
        let ticks: Vec<u64> = {
            let data = slice
                .get_mapped_range()
                .map_err(|e| anyhow::anyhow!("the UI's timestamps: {e}"))?;
            bytemuck_u64(&data)
        };
        t.read.unmap();
        let gpu = (ticks[1] >= ticks[0] && ticks[0] != 0)
            .then(|| (ticks[1] - ticks[0]) as f64 * t.period_ns as f64 * 1e-6);
        Ok((gpu, cpu_us))
    }

    /// The picture as the window shows it under the panel, read back (waits for the GPU).
    pub fn read_picture(&self) -> anyhow::Result<ImageRgba32> {
        let p = self.picture.as_ref().context("no frame was drawn")?;
        let (w, h) = (p.texture.width(), p.texture.height());
        let row = (w * 4).div_ceil(256) * 256;
        let buf = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view.screenshot"),
            size: row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &p.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buf,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            p.texture.size(),
        );
        self.queue.submit([encoder.finish()]);
        let slice = buf.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("reading the frame back: {e}"))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| anyhow::anyhow!("reading the frame back: {e}"))?;
        let mut rgba = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let line = &data[y * row as usize..][..w as usize * 4];
            rgba.extend(
                line.chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]].map(|v| v as f32 / 255.0)),
            );
        }
        Ok(ImageRgba32 {
            name: "view.picture".into(),
            texture: None,
            width: w,
            height: h,
            format: TARGET_FORMAT,
            rgba,
        })
    }
}

fn bytemuck_u64(bytes: &[u8]) -> Vec<u64> {
    bytes
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
