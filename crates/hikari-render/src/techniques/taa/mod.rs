//! Temporal anti-aliasing: the camera is jittered by a sub-pixel offset each frame (Halton
//! 2, 3; [`reference::jitter`]) and `taa.resolve` blends this frame's radiance into a history
//! reprojected by the G-buffer's motion vectors, the history clipped to the current 3x3
//! neighbourhood in YCoCg. A still view converges to the supersampled image; the denoisers
//! and particles rely on it. At a render scale below 1 (`taa.render_scale`) the frame is
//! rendered smaller and `taa.upsample` reconstructs the output's size from the jittered samples
//! and a Catmull-Rom history (temporal upsampling, as FSR 2 and TSR do; docs/scaling.md).
//! CPU twin: [`reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use settings::TaaSettings;

pub const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TaaParams {
    /// 1 when last frame's history may be blended in.
    pub history_valid: u32,
    /// 1: clip the history to the current neighbourhood.
    pub clip: u32,
    /// The most frames the history averages, as a float.
    pub max_history: f32,
    pub _pad: u32,
    /// Upsampling only: this frame's jitter in render pixels (x right, y down).
    pub jitter: [f32; 2],
    /// Upsampling only: render pixels per output pixel along x and y.
    pub ratio: [f32; 2],
}

impl TaaParams {
    pub fn new(s: &TaaSettings, history_valid: bool) -> Self {
        Self {
            history_valid: history_valid as u32,
            clip: s.clip as u32,
            max_history: s.max_history.max(1) as f32,
            _pad: 0,
            jitter: [0.0; 2],
            ratio: [1.0; 2],
        }
    }

    /// The parameters of upsampling a `render`-sized frame drawn with `jitter` to `output`.
    pub fn upsampling(
        s: &TaaSettings,
        history_valid: bool,
        jitter: [f32; 2],
        render: [u32; 2],
        output: [u32; 2],
    ) -> Self {
        Self {
            jitter,
            ratio: [
                render[0] as f32 / output[0] as f32,
                render[1] as f32 / output[1] as f32,
            ],
            ..Self::new(s, history_valid)
        }
    }
}

/// The size a frame is rendered at for an output of `output` at render scale `scale`: each
/// side rounded, at least 1.
pub fn render_size(output: [u32; 2], scale: f32) -> [u32; 2] {
    if scale >= 1.0 {
        return output;
    }
    output.map(|v| ((v as f32 * scale).round() as u32).clamp(1, v))
}

/// Jitter positions in a cycle at render scale `scale`: `samples` per output pixel's worth of
/// render pixel area, so that the cycle covers every output pixel of a render pixel as
/// densely as at full scale (FSR 2's rule: samples / scale^2).
pub fn jitter_cycle(samples: u32, scale: f32) -> u32 {
    if scale >= 1.0 {
        return samples;
    }
    ((samples as f32 / (scale * scale)).ceil() as u32).clamp(samples, 1024)
}

/// What TAA leaves in a frame.
#[derive(Clone, Copy, Debug)]
pub struct TaaFrame {
    /// The anti-aliased radiance in nits: this frame's history (`taa.history`), which the
    /// passes after TAA read; its alpha is the number of frames it averages, not coverage.
    pub output: Tex,
}

pub struct Taa {
    resolve: ComputePipeline,
    upsample: ComputePipeline,
}

impl Taa {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            resolve: ComputePipeline::new(ctx, lib, "taa/resolve.wgsl", "main", &[])?,
            upsample: ComputePipeline::new(ctx, lib, "taa/resolve.wgsl", "upsample", &[])?,
        })
    }

    /// [`Taa::record`] for a frame rendered smaller than the output: `hdr` and `motion` at
    /// the render size, drawn with `jitter` (render pixels); the history and the output at
    /// `output`. With `history_valid` false (a cut, or TAA off) the output is this frame's
    /// samples alone, upsampled.
    #[allow(clippy::too_many_arguments)]
    pub fn record_upsampled<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        hdr: Tex,
        motion: Tex,
        render: [u32; 2],
        output: [u32; 2],
        s: &TaaSettings,
        history_valid: bool,
        jitter: [f32; 2],
    ) -> Result<TaaFrame> {
        let [w, h] = output;
        let history = g.history_texture("taa.history", TextureDesc::d2(w, h, HISTORY_FORMAT))?;
        let params =
            TaaParams::upsampling(s, history_valid && history.valid, jitter, render, output);
        g.pass("taa.upsample")
            .constants(&params)
            .read(hdr)
            .read(motion)
            .read(history.prev)
            .write(history.cur)
            .dispatch_threads(&self.upsample, [w, h, 1])?;
        Ok(TaaFrame {
            output: history.cur,
        })
    }

    /// The anti-aliased radiance of `hdr` (nits), with `motion` the G-buffer's motion vectors.
    /// `history_valid` false (a camera cut) starts the history afresh.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        hdr: Tex,
        motion: Tex,
        [w, h]: [u32; 2],
        s: &TaaSettings,
        history_valid: bool,
    ) -> Result<TaaFrame> {
        let history = g.history_texture("taa.history", TextureDesc::d2(w, h, HISTORY_FORMAT))?;
        let params = TaaParams::new(s, history_valid && history.valid);
        g.pass("taa.resolve")
            .constants(&params)
            .read(hdr)
            .read(motion)
            .read(history.prev)
            .write(history.cur)
            .dispatch_threads(&self.resolve, [w, h, 1])?;
        Ok(TaaFrame {
            output: history.cur,
        })
    }
}
