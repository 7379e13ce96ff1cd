//! Exposure, primarily from illuminance (the talk's "Tonemapping": metering the light that
//! reaches what the camera sees takes albedo out of the loop): histograms of log2 illuminance
//! and log2 luminance (`exposure.meter`), then one thread (`exposure.adapt`) that turns them
//! into EV100 with the highlight rule, compensation and adaptation, and writes
//! `exposure.value`. CPU twin: [`crate::techniques::exposure::reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{Buf, FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

pub use reference::{HISTOGRAM_BINS, HistogramLayout, NO_HIGHLIGHT};
pub use settings::ExposureSettings;

/// `exposure.value` is fixed.
pub const EXPOSURE_FIXED: u32 = 1;
/// The highlight rule takes part.
pub const EXPOSURE_HIGHLIGHTS: u32 = 2;

/// Rows of pixels each thread of `exposure.meter` counts (`ROWS` in meter.wgsl).
pub const METER_ROWS: u32 = 16;

/// Bytes of `exposure.value`: `vec4<f32>(scale, ev100, metered_lux, highlight)`, highlight the
/// exposed log2 luminance of the highlight percentile ([`NO_HIGHLIGHT`] if nothing metered).
pub const VALUE_BYTES: u64 = 16;

#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ExposureParams {
    pub histogram: [f32; 4],
    pub meter: [f32; 4],
    pub rule: [f32; 4],
    pub adapt: [f32; 4],
    pub config: [u32; 4],
}

impl ExposureParams {
    /// `weather_bias_ev`: the sky's exposure hint for this frame (added when
    /// `s.weather_bias`); `fallback_ev100`: the exposure when metering is off and no EV100 is
    /// fixed (the placeholder meter's).
    pub fn new(s: &ExposureSettings, weather_bias_ev: f32, fallback_ev100: f32) -> Self {
        let h = HistogramLayout::DEFAULT;
        let fixed = s.ev100.or((!s.enabled).then_some(fallback_ev100));
        let mut flags = 0;
        if fixed.is_some() {
            flags |= EXPOSURE_FIXED;
        }
        if s.highlights {
            flags |= EXPOSURE_HIGHLIGHTS;
        }
        let bias = if s.weather_bias { weather_bias_ev } else { 0.0 };
        Self {
            histogram: [
                h.illuminance_log2_min,
                h.illuminance_bins_per_ev,
                h.luminance_log2_min,
                h.luminance_bins_per_ev,
            ],
            meter: [
                s.low_percentile,
                s.high_percentile,
                s.highlight_percentile,
                s.highlight_limit_ev,
            ],
            rule: [
                s.highlight_strength,
                s.compensation_ev + bias,
                s.min_ev100,
                s.max_ev100,
            ],
            adapt: [
                s.adapt_up_ev_per_s,
                s.adapt_down_ev_per_s,
                s.frame_seconds,
                fixed.unwrap_or(0.0),
            ],
            config: [flags, 0, 0, 0],
        }
    }

    pub fn fixed(&self) -> bool {
        self.config[0] & EXPOSURE_FIXED != 0
    }
}

/// The exposure of one frame, for the tonemap.
#[derive(Clone, Copy, Debug)]
pub struct ExposureFrame {
    /// `exposure.value`: `vec4<f32>(scale, ev100, metered_lux, highlight)`, 16 bytes; exposed
    /// linear colour = radiance in nits × scale, scale = 1 / (1.2 × 2^ev100); highlight: the
    /// exposed log2 luminance of `highlight_percentile` of all pixels ([`NO_HIGHLIGHT`] when
    /// nothing was metered), which the local tonemap fits its contrast to.
    pub value: Buf,
    /// `exposure.histogram`: [`HISTOGRAM_BINS`] u32 counts of log2 illuminance, then as many
    /// of log2 luminance ([`HistogramLayout`]); absent when the exposure is fixed.
    pub histogram: Option<Buf>,
}

/// `exposure.state`: one Rgba32Float texel, (EV100, 1 once written, 0, 0) (adapt.wgsl).
const STATE: &str = "exposure.state";

fn state_desc() -> TextureDesc {
    TextureDesc::d2(1, 1, wgpu::TextureFormat::Rgba32Float)
}

pub use crate::frame_context::PreviousExposure;

pub struct Exposure {
    clear: ComputePipeline,
    meter: ComputePipeline,
    adapt: ComputePipeline,
}

impl Exposure {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            clear: ComputePipeline::new(ctx, lib, "exposure/clear.wgsl", "main", &[])?,
            meter: ComputePipeline::new(ctx, lib, "exposure/meter.wgsl", "main", &[])?,
            adapt: ComputePipeline::new(ctx, lib, "exposure/adapt.wgsl", "main", &[])?,
        })
    }

    /// Last frame's exposure, readable by any pass of this frame (before or after
    /// [`Exposure::record`], which reads the same texture and writes the other of the pair).
    pub fn previous(g: &mut FrameGraph<'_>) -> Result<PreviousExposure> {
        let state = g.history_texture(STATE, state_desc())?;
        Ok(PreviousExposure {
            state: state.prev,
            valid: state.valid,
        })
    }

    /// `radiance`: nits (Rgba16Float); `illuminance`: lux at each surface pixel, negative on
    /// the sky (R32Float), as `direct_lighting.shade` writes them.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        radiance: Tex,
        illuminance: Tex,
        size: [u32; 2],
        params: &ExposureParams,
    ) -> Result<ExposureFrame> {
        let histogram_bytes = 2 * HISTOGRAM_BINS as u64 * 4;
        let histogram = g.buffer("exposure.histogram", histogram_bytes)?;
        g.pass("exposure.clear")
            .write(histogram)
            .dispatch_threads(&self.clear, [2 * HISTOGRAM_BINS as u32, 1, 1])?;
        // A fixed exposure reads no histogram; the clear keeps the adapt pass's input defined.
        if !params.fixed() {
            g.pass("exposure.meter")
                .constants(params)
                .read(radiance)
                .read(illuminance)
                .write(histogram)
                .dispatch_threads(&self.meter, [size[0], size[1].div_ceil(METER_ROWS), 1])?;
        }
        let state = g.history_texture(STATE, state_desc())?;
        let value = g.buffer("exposure.value", VALUE_BYTES)?;
        g.pass("exposure.adapt")
            .constants(params)
            .read(histogram)
            .read(state.prev)
            .write(state.cur)
            .write(value)
            .dispatch(&self.adapt, [1, 1, 1])?;
        Ok(ExposureFrame {
            value,
            histogram: (!params.fixed()).then_some(histogram),
        })
    }
}
