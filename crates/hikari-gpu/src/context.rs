//! The GPU context: instance, adapter, device and queue, chosen headless from the environment.
//!
//! Optional features are requested only when the adapter has them, and everything that uses
//! them checks [`GpuContext::has`] first, so the renderer runs (more slowly, or without GPU
//! timings) on adapters that lack them.

use std::any::{Any, TypeId};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::error::RenderError;

/// Features hikari uses when present; none of them is required.
pub const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::TIMESTAMP_QUERY
    .union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
    .union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES)
    .union(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
    .union(wgpu::Features::SHADER_F16)
    .union(wgpu::Features::SUBGROUP)
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::TEXTURE_COMPRESSION_BC)
    .union(wgpu::Features::SHADER_INT64)
    .union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX)
    .union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS);

/// What the renderer cannot run without beyond WebGPU's core: the software rasteriser of the
/// G-buffer and shadow maps resolves visibility with 64-bit atomics on depth and id
/// (`atomicLoad` to skip occluded fragments, `atomicMax` to keep the nearest).
pub const REQUIRED_FEATURES: wgpu::Features = wgpu::Features::SHADER_INT64
    .union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX)
    .union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS);

/// How long each step of start-up took; `hikari bench` reports it.
#[derive(Clone, Copy, Debug, Default)]
pub struct StartupTimes {
    pub instance: Duration,
    pub adapter: Duration,
    pub device: Duration,
}

impl StartupTimes {
    pub fn total(&self) -> Duration {
        self.instance + self.adapter + self.device
    }
}

/// Options for [`GpuContext::new`]. `Default` reads nothing; use [`ContextOptions::from_env`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Backends to try; `None` means all that this build enables.
    pub backends: Option<wgpu::Backends>,
    /// Case-insensitive substring of the adapter name to pick.
    pub adapter_name: Option<String>,
    /// Ask for wgpu's validation layers (slower; for debugging).
    pub validation: bool,
}

impl ContextOptions {
    /// Reads `WGPU_BACKEND` (e.g. `vulkan`, `metal`, `dx12`, `gl`) and `WGPU_ADAPTER_NAME`.
    pub fn from_env() -> Self {
        Self {
            backends: wgpu::Backends::from_env(),
            adapter_name: std::env::var("WGPU_ADAPTER_NAME")
                .ok()
                .filter(|s| !s.is_empty()),
            validation: std::env::var("HIKARI_GPU_VALIDATION").is_ok_and(|v| v == "1"),
        }
    }
}

/// Values built once per device ([`GpuContext::shared`]), by type.
type SharedValues = HashMap<TypeId, Arc<dyn Any + Send + Sync>>;

/// Everything a pass needs to talk to the GPU. A clone talks to the same device.
#[derive(Clone)]
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub features: wgpu::Features,
    pub limits: wgpu::Limits,
    pub startup: StartupTimes,
    /// Bind every `var<uniform>` as a read-only storage buffer (same bytes, same layout).
    /// On for Mesa's CPU driver (llvmpipe/lavapipe), which recompiles a shader each time it is
    /// bound when a branch or loop bound reads a uniform, and keeps every compiled copy: 13 MB
    /// and about a second a frame. Storage loads are never inlined. `HIKARI_UNIFORMS_AS_STORAGE`
    /// (`1` or `0`) overrides the choice.
    pub uniforms_as_storage: bool,
    /// Errors the device raised after the fact, and its loss ([`crate::faults`]).
    pub faults: crate::faults::GpuFaults,
    /// The size of the adapter's largest device-local memory heap, bytes, where the backend
    /// tells it (Vulkan); a frame that needs more is refused before it runs.
    pub memory_bytes: Option<u64>,
    shared: Arc<Mutex<SharedValues>>,
}

/// Whether `info` is Mesa's CPU driver, whose shader compiler inlines uniform values that
/// steer branches by compiling the shader anew at each bind ([`GpuContext::uniforms_as_storage`]).
fn inlines_uniforms(info: &wgpu::AdapterInfo) -> bool {
    let mesa_cpu = |s: &str| {
        let s = s.to_ascii_lowercase();
        s.contains("llvmpipe") || s.contains("lavapipe")
    };
    info.device_type == wgpu::DeviceType::Cpu && (mesa_cpu(&info.name) || mesa_cpu(&info.driver))
}

/// The largest device-local heap of a Vulkan adapter (wgpu itself does not report memory).
fn device_memory(adapter: &wgpu::Adapter) -> Option<u64> {
    // SAFETY: the raw handles are only read, while `adapter` keeps them alive.
    let hal = unsafe { adapter.as_hal::<wgpu::hal::api::Vulkan>() }?;
    let properties = unsafe {
        hal.shared_instance()
            .raw_instance()
            .get_physical_device_memory_properties(hal.raw_physical_device())
    };
    const DEVICE_LOCAL: u32 = 0x1;
    properties
        .memory_heaps
        .iter()
        .take(properties.memory_heap_count as usize)
        .filter(|h| h.flags.as_raw() & DEVICE_LOCAL != 0)
        .map(|h| h.size)
        .max()
}

impl GpuContext {
    /// Creates a headless context. Fails with [`RenderError::NoAdapter`] (which tells the user
    /// how to get a driver) rather than panicking when no adapter can be found.
    pub fn new(options: &ContextOptions) -> Result<Self, RenderError> {
        pollster::block_on(Self::new_async(options))
    }

    pub async fn new_async(options: &ContextOptions) -> Result<Self, RenderError> {
        let t0 = Instant::now();
        let backends = options
            .backends
            .unwrap_or_else(wgpu::Instance::enabled_backend_features);
        let mut flags = wgpu::InstanceFlags::from_build_config();
        if options.validation {
            flags |= wgpu::InstanceFlags::VALIDATION;
        } else {
            flags.remove(wgpu::InstanceFlags::VALIDATION | wgpu::InstanceFlags::DEBUG);
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        desc.flags = flags;
        let instance = wgpu::Instance::new(desc);
        let t1 = Instant::now();

        let adapter =
            Self::pick_adapter(&instance, backends, options.adapter_name.as_deref()).await?;
        let info = adapter.get_info();
        let t2 = Instant::now();

        let features = adapter.features() & OPTIONAL_FEATURES;
        let adapter_limits = adapter.limits();
        // Ask for what the adapter offers for the limits that large frames hit (storage
        // buffers of a BVH, 3D textures of the atmosphere and froxels); keep the rest default.
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: adapter_limits.max_storage_buffer_binding_size,
            max_buffer_size: adapter_limits.max_buffer_size,
            max_storage_buffers_per_shader_stage: adapter_limits
                .max_storage_buffers_per_shader_stage,
            max_storage_textures_per_shader_stage: adapter_limits
                .max_storage_textures_per_shader_stage,
            max_sampled_textures_per_shader_stage: adapter_limits
                .max_sampled_textures_per_shader_stage,
            max_texture_dimension_2d: adapter_limits.max_texture_dimension_2d,
            max_texture_dimension_3d: adapter_limits.max_texture_dimension_3d,
            max_compute_workgroup_storage_size: adapter_limits.max_compute_workgroup_storage_size,
            max_compute_invocations_per_workgroup: adapter_limits
                .max_compute_invocations_per_workgroup,
            max_compute_workgroup_size_x: adapter_limits.max_compute_workgroup_size_x,
            max_compute_workgroup_size_y: adapter_limits.max_compute_workgroup_size_y,
            max_compute_workgroup_size_z: adapter_limits.max_compute_workgroup_size_z,
            max_color_attachment_bytes_per_sample: adapter_limits
                .max_color_attachment_bytes_per_sample,
            // A pass's own group and one a shared binding set it imports (shadows, sky, BRDF
            // tables, BVH...): more than WebGPU's default 4.
            max_bind_groups: adapter_limits.max_bind_groups.min(8),
            ..wgpu::Limits::default().using_resolution(adapter_limits.clone())
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("hikari"),
                required_features: features,
                required_limits: limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| RenderError::Device(e.to_string()))?;
        let t3 = Instant::now();
        let uniforms_as_storage = match std::env::var("HIKARI_UNIFORMS_AS_STORAGE").as_deref() {
            Ok("1") => true,
            Ok("0") => false,
            _ => inlines_uniforms(&info),
        };

        let faults = crate::faults::GpuFaults::install(&device);
        let memory_bytes = device_memory(&adapter);
        Ok(Self {
            memory_bytes,
            shared: Arc::default(),
            faults,
            uniforms_as_storage,
            instance,
            adapter,
            device,
            queue,
            info,
            features,
            limits,
            startup: StartupTimes {
                instance: t1 - t0,
                adapter: t2 - t1,
                device: t3 - t2,
            },
        })
    }

    async fn pick_adapter(
        instance: &wgpu::Instance,
        backends: wgpu::Backends,
        name: Option<&str>,
    ) -> Result<wgpu::Adapter, RenderError> {
        let adapters = instance.enumerate_adapters(backends).await;
        let seen: Vec<String> = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
            })
            .collect();
        if let Some(name) = name {
            let want = name.to_lowercase();
            return adapters
                .into_iter()
                .find(|a| a.get_info().name.to_lowercase().contains(&want))
                .ok_or_else(|| RenderError::AdapterNotFound {
                    wanted: name.to_string(),
                    seen,
                });
        }
        // Prefer real GPUs, then integrated, then CPU drivers (lavapipe): the order a user
        // with both a GPU and Mesa installed expects.
        let rank = |a: &wgpu::Adapter| match a.get_info().device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Other => 3,
            wgpu::DeviceType::Cpu => 4,
        };
        adapters
            .into_iter()
            .filter(|a| a.get_info().backend != wgpu::Backend::Noop)
            .min_by_key(rank)
            .ok_or(RenderError::NoAdapter { backends })
    }

    /// The value of type `T` built once for this device and shared by every clone of the
    /// context: `make` runs on the first call (the renderer's compiled pipelines, which every
    /// renderer on one device can share, as a test binary's hundred renderers do). `make` must
    /// not ask for another shared value.
    pub fn shared<T: Any + Send + Sync>(
        &self,
        make: impl FnOnce() -> Result<T, RenderError>,
    ) -> Result<Arc<T>, RenderError> {
        let mut values = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(v) = values.get(&TypeId::of::<T>()) {
            return Ok(v
                .clone()
                .downcast::<T>()
                .expect("stored under its own type"));
        }
        let v = Arc::new(make()?);
        values.insert(TypeId::of::<T>(), v.clone());
        Ok(v)
    }

    /// A storage buffer holding `bytes`, uploaded once (also a copy source and destination).
    /// Empty data gets one zeroed 256-byte row, as wgpu binds no empty buffer; data past the
    /// device's storage binding or buffer size is an error naming `label`.
    pub fn storage_buffer(&self, label: &str, bytes: &[u8]) -> Result<wgpu::Buffer, RenderError> {
        use wgpu::util::DeviceExt;
        let zeros = [0u8; 256];
        let contents = if bytes.is_empty() { &zeros[..] } else { bytes };
        let limit = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        if contents.len() as u64 > limit {
            return Err(RenderError::Limit {
                what: format!("size in bytes of `{label}`"),
                requested: contents.len() as u64,
                limit,
            });
        }
        Ok(self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            }))
    }

    /// Whether an optional feature was granted.
    pub fn has(&self, f: wgpu::Features) -> bool {
        self.features.contains(f)
    }

    /// Whether `format` can be bound as a read-write storage texture here.
    pub fn supports_read_write_storage(&self, format: wgpu::TextureFormat) -> bool {
        self.has(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
            && self
                .adapter
                .get_texture_format_features(format)
                .flags
                .contains(wgpu::TextureFormatFeatureFlags::STORAGE_READ_WRITE)
    }

    /// A one-line description for logs and `hikari info`.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, driver {} {})",
            self.info.name,
            self.info.backend,
            self.info.device_type,
            self.info.driver,
            self.info.driver_info
        )
    }

    /// Blocks until the GPU is idle.
    /// A GPU that has not finished after [`GpuContext::wait_limit`] is taken for hung: the
    /// wait ends with an error rather than never. A lost device ends it at once.
    /// Other errors the device raised stay recorded for the frame's own check.
    pub fn wait_idle(&self) -> Result<(), RenderError> {
        let lost = |reason| RenderError::DeviceLost {
            during: "waiting for the GPU".into(),
            reason,
        };
        let limit = self.wait_limit();
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: Some(limit),
            })
            .map_err(|e| {
                if let Some(why) = self.faults.lost() {
                    return lost(why);
                }
                match e {
                    wgpu::PollError::Timeout => RenderError::Gpu {
                        during: "waiting for the GPU".into(),
                        message: format!(
                            "the GPU did not finish its work in {} s; it may have hung",
                            limit.as_secs()
                        ),
                    },
                    e => RenderError::Device(e.to_string()),
                }
            })?;
        match self.faults.lost() {
            Some(why) => Err(lost(why)),
            None => Ok(()),
        }
    }

    /// How long one wait for the GPU may take: a real GPU resets itself after seconds when a
    /// submission hangs (the driver then reports the device lost); a CPU driver renders a large
    /// frame in minutes.
    pub fn wait_limit(&self) -> Duration {
        match self.info.device_type {
            wgpu::DeviceType::Cpu => Duration::from_secs(3600),
            _ => Duration::from_secs(120),
        }
    }
}
