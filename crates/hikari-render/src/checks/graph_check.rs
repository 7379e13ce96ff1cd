//! Tiny passes that exercise the frame graph itself: the graph tests and
//! `hikari bench overhead` use them.

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FillParams {
    pub value: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct EmptyParams {
    pub value: [f32; 4],
}

pub struct GraphCheck {
    /// Writes `FillParams::value` into an Rgba16Float storage texture.
    pub fill: ComputePipeline,
    /// `sum = a + b` on Rgba16Float textures.
    pub add: ComputePipeline,
    /// Binds a uniform and a read-only storage buffer and does nothing: per-pass overhead.
    pub empty: ComputePipeline,
    /// Adds a constant to a storage buffer: each pass depends on the previous one.
    pub chain: ComputePipeline,
}

impl GraphCheck {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            fill: ComputePipeline::new(ctx, lib, "graph_check/fill.wgsl", "main", &[])?,
            add: ComputePipeline::new(ctx, lib, "graph_check/add.wgsl", "main", &[])?,
            empty: ComputePipeline::new(ctx, lib, "graph_check/empty.wgsl", "main", &[])?,
            chain: ComputePipeline::new(ctx, lib, "graph_check/chain.wgsl", "main", &[])?,
        })
    }
}
