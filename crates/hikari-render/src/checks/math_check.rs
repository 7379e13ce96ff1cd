//! Verification kernels for the WGSL math twins (`hikari::sh`, `hikari::color`, `hikari::brdf`): no frame uses
//! them. `tests/render/math_twins.rs` runs each on a few hundred random cases and compares the results
//! with hikari-math on the CPU, so a twin that drifts from its reference fails a test instead
//! of showing up as a lighting bug.
//!
//! Every kernel reads one flat record of `f32` per case and writes one flat record per case
//! (layouts documented in `shaders/math_check/*.wgsl`): flat records keep WGSL's array-stride
//! and `vec3` padding rules out of the comparison.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::GraphRuntime;
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

/// Uniform of every math-check kernel: the number of cases in the input buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MathCheckParams {
    pub count: u32,
    pub pad_a: u32,
    pub pad_b: u32,
    pub pad_c: u32,
}

/// One verification kernel: its shader entry point and the sizes of its records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// SH basis L1 / L2 and evaluation (mono L1, mono L2, RGB L2).
    ShEval,
    /// Irradiance from L1 mono and L2 RGB radiance SH.
    ShIrradiance,
    /// Per-band scaling (mono and RGB), the Sloan 2017 window and the deringing window.
    ShBands,
    /// Projection of a delta direction.
    ShDelta,
    /// Newton minimum search of a scalar L2 function.
    ShFindMin,
    /// Deringing of RGB L2: strength, coefficients, and the GPU's own scan of the result.
    ShDering,
    /// Linear-maximum direction and directionality boost of RGB L2.
    ShBoost,
    /// The Metro Exodus YCoCg + L1 encoding and its decoders.
    YCoCg,
    /// sRGB transfer functions and Rec.709 luminance.
    Transfer,
    /// The generated colour matrices applied to vectors.
    Matrices,
    /// The Purkinje shift with the generated matrices.
    Purkinje,
    /// The BRDF (anisotropic and isotropic forms, per-light weights) and its albedo tables.
    Brdf,
    /// The reflection probes' cube and cone math (`hikari::reflection_probe_math`).
    ReflectionProbe,
}

impl Kernel {
    /// Entry shader, relative to `shaders/`.
    pub fn shader(self) -> &'static str {
        match self {
            Kernel::ShEval
            | Kernel::ShIrradiance
            | Kernel::ShBands
            | Kernel::ShDelta
            | Kernel::ShFindMin
            | Kernel::ShDering
            | Kernel::ShBoost => "math_check/sh.wgsl",
            Kernel::YCoCg => "math_check/ycocg.wgsl",
            Kernel::Transfer | Kernel::Matrices | Kernel::Purkinje => "math_check/color.wgsl",
            Kernel::Brdf => "math_check/brdf.wgsl",
            Kernel::ReflectionProbe => "math_check/reflection_probe.wgsl",
        }
    }

    pub fn entry(self) -> &'static str {
        match self {
            Kernel::ShEval => "eval",
            Kernel::ShIrradiance => "irradiance",
            Kernel::ShBands => "bands",
            Kernel::ShDelta => "delta",
            Kernel::ShFindMin => "find_min",
            Kernel::ShDering => "dering",
            Kernel::ShBoost => "boost",
            Kernel::YCoCg => "main",
            Kernel::Transfer => "transfer",
            Kernel::Matrices => "matrices",
            Kernel::Purkinje => "purkinje",
            Kernel::Brdf => "eval",
            Kernel::ReflectionProbe => "main",
        }
    }

    /// Input floats per case (the shader's `IN_*` constant).
    pub fn in_stride(self) -> usize {
        match self {
            Kernel::ShEval => 39,
            Kernel::ShIrradiance => 34,
            Kernel::ShBands => 41,
            Kernel::ShDelta => 4,
            Kernel::ShFindMin => 9,
            Kernel::ShDering => 27,
            Kernel::ShBoost => 28,
            Kernel::YCoCg => 16,
            Kernel::Transfer => 5,
            Kernel::Matrices => 3,
            Kernel::Purkinje => 3,
            Kernel::Brdf => 22,
            Kernel::ReflectionProbe => 19,
        }
    }

    /// Output floats per case (the shader's `OUT_*` constant).
    pub fn out_stride(self) -> usize {
        match self {
            Kernel::ShEval => 18,
            Kernel::ShIrradiance => 4,
            Kernel::ShBands => 42,
            Kernel::ShDelta => 9,
            Kernel::ShFindMin => 4,
            Kernel::ShDering => 34,
            Kernel::ShBoost => 30,
            Kernel::YCoCg => 23,
            Kernel::Transfer => 9,
            Kernel::Matrices => 31,
            Kernel::Purkinje => 3,
            Kernel::Brdf => 14,
            Kernel::ReflectionProbe => 8,
        }
    }
}

/// A built verification kernel.
pub struct MathCheck {
    pub kernel: Kernel,
    pub pipeline: ComputePipeline,
    /// For the kernels that evaluate `hikari::brdf`.
    brdf_tables: crate::brdf_tables::BrdfTables,
}

impl MathCheck {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary, kernel: Kernel) -> Result<Self> {
        Ok(Self {
            kernel,
            pipeline: ComputePipeline::new(ctx, lib, kernel.shader(), kernel.entry(), &[])?,
            brdf_tables: crate::brdf_tables::BrdfTables::new(ctx),
        })
    }

    /// Runs the kernel on `input` (whole records, `in_stride` floats each) in one frame of its
    /// own and returns the output records (`out_stride` floats each).
    pub fn run(&self, ctx: &GpuContext, input: &[f32]) -> Result<Vec<f32>> {
        let (k, name) = (self.kernel, self.kernel.entry());
        let count = input.len() / k.in_stride();
        if count == 0 || count * k.in_stride() != input.len() {
            return Err(RenderError::Pass {
                pass: format!("math_check.{name}"),
                message: format!(
                    "{} input floats is not a positive number of {}-float records",
                    input.len(),
                    k.in_stride()
                ),
            });
        }
        let input_buffer = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("math_check.input"),
                contents: bytemuck::cast_slice(input),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let params = MathCheckParams {
            count: count as u32,
            ..Default::default()
        };
        let out_name = format!("math_check.{name}.output");
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(ctx);
        let input = g.import_buffer("math_check.input", &input_buffer);
        let output = g.buffer(&out_name, (count * k.out_stride() * 4) as u64)?;
        let tables =
            (!self.pipeline.info.sets.is_empty()).then(|| self.brdf_tables.binding_set(&mut g));
        let mut pass = g
            .pass(&format!("math_check.{name}"))
            .constants(&params)
            .read(input)
            .write(output);
        if let Some(t) = tables {
            pass = pass.set(t);
        }
        pass.dispatch_threads(&self.pipeline, [count as u32, 1, 1])?;
        g.readback(output);
        let result = g.execute()?;
        let bytes = result
            .buffers
            .iter()
            .find(|(n, _)| *n == out_name)
            .map(|(_, b)| b)
            .ok_or_else(|| RenderError::Pass {
                pass: format!("math_check.{name}"),
                message: "output buffer was not read back".into(),
            })?;
        Ok(bytemuck::pod_collect_to_vec(
            &bytes[..count * k.out_stride() * 4],
        ))
    }
}
