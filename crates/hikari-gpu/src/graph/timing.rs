//! GPU timestamps at the start and end of every pass.

use crate::context::GpuContext;

/// One pass's cost in one frame.
#[derive(Clone, Debug)]
pub struct PassTiming {
    /// `technique.stage`, as the pass was named.
    pub name: String,
    /// GPU time between the pass's begin and end timestamps; `None` without timestamp queries.
    pub gpu_ms: Option<f64>,
    /// CPU time spent encoding the pass (bind groups, commands), in microseconds.
    pub cpu_us: f64,
    /// The bytes it binds to read and to write ([`super::Traffic`]): its memory floor with the
    /// adapter's bandwidth. Zero for passes that are not a pipeline's (copies, clears).
    pub traffic: super::Traffic,
}

pub(crate) struct GpuTimer {
    set: wgpu::QuerySet,
    capacity: u32,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f64,
}

impl GpuTimer {
    /// `None` when the device cannot write timestamps at pass boundaries.
    pub fn new(ctx: &GpuContext, passes: u32) -> Option<Self> {
        if !ctx.has(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let capacity = (passes.max(16) * 2)
            .next_power_of_two()
            .min(wgpu::QUERY_SET_MAX_QUERIES);
        let bytes = capacity as u64 * 8;
        Some(Self {
            set: ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("hikari.timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: capacity,
            }),
            capacity,
            resolve: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("hikari.timestamps.resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("hikari.timestamps.readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            period_ns: ctx.queue.get_timestamp_period() as f64,
        })
    }

    pub fn passes(&self) -> u32 {
        self.capacity / 2
    }

    fn fits(&self, (begin, end): (Option<u32>, Option<u32>)) -> bool {
        (begin.is_some() || end.is_some())
            && begin.is_none_or(|q| q < self.capacity)
            && end.is_none_or(|q| q < self.capacity)
    }

    /// Timestamp writes at the given query indices (begin, end) of a compute pass.
    pub fn compute_writes(
        &self,
        q: (Option<u32>, Option<u32>),
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.fits(q).then_some(wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: q.0,
            end_of_pass_write_index: q.1,
        })
    }

    pub fn render_writes(
        &self,
        q: (Option<u32>, Option<u32>),
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.fits(q).then_some(wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: q.0,
            end_of_pass_write_index: q.1,
        })
    }

    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, passes: u32) {
        let n = (passes.min(self.passes()) * 2).max(2);
        encoder.resolve_query_set(&self.set, 0..n, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, n as u64 * 8);
    }

    /// Maps the readback buffer (after the frame was submitted) and returns per-pass
    /// milliseconds and the span from the first pass's begin to the last pass's end.
    pub fn read(
        &self,
        ctx: &GpuContext,
        passes: u32,
    ) -> crate::Result<(Vec<Option<f64>>, Option<f64>)> {
        let n = passes.min(self.passes()) as usize;
        let bytes = (n.max(1) * 16) as u64;
        let slice = self.readback.slice(0..bytes);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        ctx.wait_idle()?;
        let ticks: Vec<u64> = {
            let data = slice
                .get_mapped_range()
                .map_err(|e| crate::RenderError::Gpu {
                    during: "timestamp read back".into(),
                    message: e.to_string(),
                })?;
            bytemuck::cast_slice::<u8, u64>(&data).to_vec()
        };
        self.readback.unmap();
        let mut out: Vec<Option<f64>> = (0..n)
            .map(|i| {
                let (a, b) = (ticks[2 * i], ticks[2 * i + 1]);
                // A pass the driver did not time leaves both zero; an end before its begin
                // means the counter wrapped or was reset: report nothing rather than garbage.
                (b >= a && a != 0).then(|| (b - a) as f64 * self.period_ns * 1e-6)
            })
            .collect();
        let span = (n > 0 && ticks[0] != 0 && ticks[2 * n - 1] >= ticks[0])
            .then(|| (ticks[2 * n - 1] - ticks[0]) as f64 * self.period_ns * 1e-6);
        out.resize(passes as usize, None);
        Ok((out, span))
    }
}
