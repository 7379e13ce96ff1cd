//! Temporal anti-aliasing: the camera is jittered by a sub-pixel offset each frame (Halton
//! 2, 3; [`reference::jitter`]) and `taa.resolve` blends this frame's radiance into a history
//! reprojected by the G-buffer's motion vectors, the history clipped to the current 3x3
//! neighbourhood in YCoCg. A still view converges to the supersampled image; the denoisers
//! and particles rely on it. CPU twin: [`reference`].

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
}

impl TaaParams {
    pub fn new(s: &TaaSettings, history_valid: bool) -> Self {
        Self {
            history_valid: history_valid as u32,
            clip: s.clip as u32,
            max_history: s.max_history.max(1) as f32,
            _pad: 0,
        }
    }
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
}

impl Taa {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            resolve: ComputePipeline::new(ctx, lib, "taa/resolve.wgsl", "main", &[])?,
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
