//! Pipelines whose bind group layout comes from the shader itself (naga reflection).
//!
//! hikari binds a pass's own resources in group 0, in binding order, so a pass reads as a
//! chain: `.read(a).write(b).constants(c)` gives bindings 0, 1, 2. Shared WGSL modules that
//! need bindings (the sun's shadow maps, the BVH) declare them in a group of their own,
//! `@group(#{NAME_GROUP})`, which the shader library numbers from 1 for each pipeline; the
//! pass binds such a set with `.set(...)`, made once by the technique that owns it. The reflected layout lets the
//! frame graph check each chain against its shader and name the pass and binding that differ.

use std::sync::atomic::{AtomicU64, Ordering};

use naga_oil::compose::ShaderDefValue;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::shader::{self, ShaderLibrary};

static NEXT_PIPELINE_ID: AtomicU64 = AtomicU64::new(1);

/// What a binding slot of group 0 holds, as the shader declares it.
#[derive(Clone, Debug, PartialEq)]
pub enum BindingKind {
    /// `texture_2d<f32>` and friends, read with `textureLoad` or a sampler.
    SampledTexture {
        view: wgpu::TextureViewDimension,
        sample: wgpu::TextureSampleType,
    },
    /// `texture_storage_2d<format, access>`.
    StorageTexture {
        view: wgpu::TextureViewDimension,
        format: wgpu::TextureFormat,
        access: wgpu::StorageTextureAccess,
    },
    Uniform,
    Storage {
        read_only: bool,
    },
    Sampler {
        comparison: bool,
        /// False where the shader gathers integer texels with it.
        filtering: bool,
    },
}

impl BindingKind {
    /// Whether binding a resource here writes it.
    pub fn writes(&self) -> bool {
        match self {
            BindingKind::StorageTexture { access, .. } => {
                *access != wgpu::StorageTextureAccess::ReadOnly
            }
            BindingKind::Storage { read_only } => !read_only,
            _ => false,
        }
    }
}

#[derive(Clone, Debug)]
pub struct BindingSlot {
    pub binding: u32,
    pub name: String,
    pub kind: BindingKind,
}

fn storage_format(f: naga::StorageFormat) -> Option<wgpu::TextureFormat> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Some(match f {
        S::R8Unorm => T::R8Unorm,
        S::R8Snorm => T::R8Snorm,
        S::R8Uint => T::R8Uint,
        S::R8Sint => T::R8Sint,
        S::R16Uint => T::R16Uint,
        S::R16Sint => T::R16Sint,
        S::R16Float => T::R16Float,
        S::Rg8Unorm => T::Rg8Unorm,
        S::Rg8Snorm => T::Rg8Snorm,
        S::Rg8Uint => T::Rg8Uint,
        S::Rg8Sint => T::Rg8Sint,
        S::R32Uint => T::R32Uint,
        S::R32Sint => T::R32Sint,
        S::R32Float => T::R32Float,
        S::Rg16Uint => T::Rg16Uint,
        S::Rg16Sint => T::Rg16Sint,
        S::Rg16Float => T::Rg16Float,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::Rgba8Snorm => T::Rgba8Snorm,
        S::Rgba8Uint => T::Rgba8Uint,
        S::Rgba8Sint => T::Rgba8Sint,
        S::Bgra8Unorm => T::Bgra8Unorm,
        S::Rgb10a2Uint => T::Rgb10a2Uint,
        S::Rgb10a2Unorm => T::Rgb10a2Unorm,
        S::Rg11b10Ufloat => T::Rg11b10Ufloat,
        S::Rg32Uint => T::Rg32Uint,
        S::Rg32Sint => T::Rg32Sint,
        S::Rg32Float => T::Rg32Float,
        S::Rgba16Uint => T::Rgba16Uint,
        S::Rgba16Sint => T::Rgba16Sint,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba32Uint => T::Rgba32Uint,
        S::Rgba32Sint => T::Rgba32Sint,
        S::Rgba32Float => T::Rgba32Float,
        S::R16Unorm => T::R16Unorm,
        S::R16Snorm => T::R16Snorm,
        S::Rg16Unorm => T::Rg16Unorm,
        S::Rg16Snorm => T::Rg16Snorm,
        S::Rgba16Unorm => T::Rgba16Unorm,
        S::Rgba16Snorm => T::Rgba16Snorm,
        _ => return None,
    })
}

fn view_dimension(dim: naga::ImageDimension, arrayed: bool) -> wgpu::TextureViewDimension {
    use wgpu::TextureViewDimension as V;
    match (dim, arrayed) {
        (naga::ImageDimension::D1, _) => V::D1,
        (naga::ImageDimension::D2, false) => V::D2,
        (naga::ImageDimension::D2, true) => V::D2Array,
        (naga::ImageDimension::D3, _) => V::D3,
        (naga::ImageDimension::Cube, false) => V::Cube,
        (naga::ImageDimension::Cube, true) => V::CubeArray,
    }
}

/// Reads group 0 of a module (the pass's own bindings). Groups 1.. are the shared binding sets
/// `sets` (see [`ShaderLibrary::binding_sets`]): use [`reflect_groups`] for them.
pub fn reflect_bindings(path: &str, module: &naga::Module) -> Result<Vec<BindingSlot>> {
    let mut groups = reflect_groups(path, module, &[])?;
    Ok(groups.swap_remove(0))
}

/// Reads every group of a module: group 0, then one group per shared binding set in `sets`.
/// Group 0's bindings must be 0..n without gaps; a set's group holds those of its bindings the
/// shader uses.
pub fn reflect_groups(
    path: &str,
    module: &naga::Module,
    sets: &[String],
) -> Result<Vec<Vec<BindingSlot>>> {
    let err = |message: String| RenderError::Shader {
        path: path.into(),
        message,
    };
    let integer_samplers = samplers_of_integer_textures(module);
    let sampled = textures_sampled_with_filtering(module, &integer_samplers);
    let mut groups: Vec<Vec<BindingSlot>> = vec![Vec::new(); sets.len() + 1];
    for (handle, g) in module.global_variables.iter() {
        let Some(rb) = &g.binding else { continue };
        let name = g.name.clone().unwrap_or_default();
        if rb.group as usize >= groups.len() {
            return Err(err(format!(
                "`{name}` uses @group({}); group 0 holds a pass's own bindings and groups \
                 1.. the shared binding sets it imports ({sets:?}), declared as \
                 @group(#{{NAME_GROUP}})",
                rb.group
            )));
        }
        let kind = match (&module.types[g.ty].inner, g.space) {
            (
                naga::TypeInner::Image {
                    dim,
                    arrayed,
                    class,
                },
                _,
            ) => match class {
                naga::ImageClass::Sampled { kind, multi: _ } => BindingKind::SampledTexture {
                    view: view_dimension(*dim, *arrayed),
                    sample: match kind {
                        naga::ScalarKind::Float => wgpu::TextureSampleType::Float {
                            // A texture the shader only loads texels from may be of an
                            // unfilterable format such as R32Float.
                            filterable: sampled.contains(&handle),
                        },
                        naga::ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                        naga::ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                        other => return Err(err(format!("`{name}`: texel kind {other:?}"))),
                    },
                },
                naga::ImageClass::Depth { .. } => BindingKind::SampledTexture {
                    view: view_dimension(*dim, *arrayed),
                    sample: wgpu::TextureSampleType::Depth,
                },
                naga::ImageClass::Storage { format, access } => BindingKind::StorageTexture {
                    view: view_dimension(*dim, *arrayed),
                    format: storage_format(*format)
                        .ok_or_else(|| err(format!("`{name}`: storage format {format:?}")))?,
                    access: if access
                        .contains(naga::StorageAccess::LOAD | naga::StorageAccess::STORE)
                    {
                        wgpu::StorageTextureAccess::ReadWrite
                    } else if access.contains(naga::StorageAccess::STORE) {
                        wgpu::StorageTextureAccess::WriteOnly
                    } else {
                        wgpu::StorageTextureAccess::ReadOnly
                    },
                },
                other => return Err(err(format!("`{name}`: image class {other:?}"))),
            },
            (naga::TypeInner::Sampler { comparison }, _) => BindingKind::Sampler {
                comparison: *comparison,
                filtering: !integer_samplers.contains(&handle),
            },
            (_, naga::AddressSpace::Uniform) => BindingKind::Uniform,
            (_, naga::AddressSpace::Storage { access }) => BindingKind::Storage {
                read_only: !access.contains(naga::StorageAccess::STORE),
            },
            (other, space) => {
                return Err(err(format!(
                    "`{name}`: unsupported binding {other:?} in {space:?}"
                )));
            }
        };
        groups[rb.group as usize].push(BindingSlot {
            binding: rb.binding,
            name,
            kind,
        });
    }
    for (group, slots) in groups.iter_mut().enumerate() {
        slots.sort_by_key(|s| s.binding);
        // A binding set's group may have gaps: naga_oil leaves out the bindings of a shared
        // module that the entry point does not reach.
        if group > 0 {
            continue;
        }
        for (i, s) in slots.iter().enumerate() {
            if s.binding != i as u32 {
                return Err(err(format!(
                    "bindings of group {group} must be 0..n without gaps; `{}` is @binding({}) but {} was expected",
                    s.name, s.binding, i
                )));
            }
        }
    }
    Ok(groups)
}

/// Every (texture, sampler) pair the shader samples with, as global variables.
fn image_samples(
    module: &naga::Module,
) -> Vec<(
    naga::Handle<naga::GlobalVariable>,
    naga::Handle<naga::GlobalVariable>,
)> {
    let mut out = Vec::new();
    let functions = module
        .functions
        .iter()
        .map(|(_, f)| f)
        .chain(module.entry_points.iter().map(|e| &e.function));
    for f in functions {
        for (_, e) in f.expressions.iter() {
            let naga::Expression::ImageSample { image, sampler, .. } = *e else {
                continue;
            };
            if let (
                naga::Expression::GlobalVariable(image),
                naga::Expression::GlobalVariable(sampler),
            ) = (&f.expressions[image], &f.expressions[sampler])
                && !out.contains(&(*image, *sampler))
            {
                out.push((*image, *sampler));
            }
        }
    }
    out
}

/// Float textures a shader samples through a filtering sampler (any sampler but a comparison
/// one or one used with integer textures).
fn textures_sampled_with_filtering(
    module: &naga::Module,
    integer_samplers: &[naga::Handle<naga::GlobalVariable>],
) -> Vec<naga::Handle<naga::GlobalVariable>> {
    image_samples(module)
        .into_iter()
        .filter(|(_, sampler)| {
            matches!(
                module.types[module.global_variables[*sampler].ty].inner,
                naga::TypeInner::Sampler { comparison: false }
            ) && !integer_samplers.contains(sampler)
        })
        .map(|(image, _)| image)
        .collect()
}

/// Samplers a shader uses with integer textures (`textureGather` of a `texture_2d<u32>`): a
/// filtering sampler may not meet an integer texture, so their slots take non-filtering ones.
fn samplers_of_integer_textures(module: &naga::Module) -> Vec<naga::Handle<naga::GlobalVariable>> {
    let integer = |h: naga::Handle<naga::GlobalVariable>| {
        matches!(
            module.types[module.global_variables[h].ty].inner,
            naga::TypeInner::Image {
                class: naga::ImageClass::Sampled {
                    kind: naga::ScalarKind::Uint | naga::ScalarKind::Sint,
                    ..
                },
                ..
            }
        )
    };
    let mut out = Vec::new();
    for (image, sampler) in image_samples(module) {
        if integer(image) && !out.contains(&sampler) {
            out.push(sampler);
        }
    }
    out
}

fn layout_entries(
    slots: &[BindingSlot],
    visibility: wgpu::ShaderStages,
    uniforms_as_storage: bool,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    slots
        .iter()
        .map(|s| wgpu::BindGroupLayoutEntry {
            binding: s.binding,
            visibility,
            ty: match &s.kind {
                BindingKind::SampledTexture { view, sample } => wgpu::BindingType::Texture {
                    sample_type: *sample,
                    view_dimension: *view,
                    multisampled: false,
                },
                BindingKind::StorageTexture {
                    view,
                    format,
                    access,
                } => wgpu::BindingType::StorageTexture {
                    access: *access,
                    format: *format,
                    view_dimension: *view,
                },
                BindingKind::Uniform => wgpu::BindingType::Buffer {
                    ty: if uniforms_as_storage {
                        wgpu::BufferBindingType::Storage { read_only: true }
                    } else {
                        wgpu::BufferBindingType::Uniform
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                BindingKind::Storage { read_only } => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage {
                        read_only: *read_only,
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                BindingKind::Sampler {
                    comparison,
                    filtering,
                } => wgpu::BindingType::Sampler(if *comparison {
                    wgpu::SamplerBindingType::Comparison
                } else if *filtering {
                    wgpu::SamplerBindingType::Filtering
                } else {
                    wgpu::SamplerBindingType::NonFiltering
                }),
            },
            count: None,
        })
        .collect()
}

/// A shared binding set's group in a pipeline.
pub struct SetLayout {
    /// The set's name (`sun_shadows` for `#{SUN_SHADOWS_GROUP}`).
    pub name: String,
    /// Its `@group` index, from 1.
    pub group: u32,
    pub slots: Vec<BindingSlot>,
    pub layout: wgpu::BindGroupLayout,
    /// Identifies the layout in bind group caches.
    pub id: u64,
}

/// What every pipeline carries for the frame graph.
pub struct PipelineInfo {
    pub id: u64,
    pub label: String,
    /// Group 0: the pass's own bindings, in chain order.
    pub slots: Vec<BindingSlot>,
    pub bind_group_layout: wgpu::BindGroupLayout,
    /// Groups 1..: the shared binding sets the shader imports, in group order.
    pub sets: Vec<SetLayout>,
}

impl PipelineInfo {
    fn new(
        ctx: &GpuContext,
        label: &str,
        mut groups: Vec<Vec<BindingSlot>>,
        set_names: Vec<String>,
        visibility: wgpu::ShaderStages,
    ) -> Self {
        let layout = |slots: &[BindingSlot], what: &str| {
            ctx.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&format!("{label} {what}")),
                    entries: &layout_entries(slots, visibility, ctx.uniforms_as_storage),
                })
        };
        let slots = groups.remove(0);
        let bind_group_layout = layout(&slots, "group 0");
        let sets = set_names
            .into_iter()
            .zip(groups)
            .enumerate()
            .map(|(i, (name, slots))| SetLayout {
                layout: layout(&slots, &name),
                name,
                group: i as u32 + 1,
                slots,
                id: NEXT_PIPELINE_ID.fetch_add(1, Ordering::Relaxed),
            })
            .collect();
        Self {
            id: NEXT_PIPELINE_ID.fetch_add(1, Ordering::Relaxed),
            label: label.into(),
            slots,
            bind_group_layout,
            sets,
        }
    }

    /// The pipeline layout: group 0, then each set's group.
    fn pipeline_layout(&self, ctx: &GpuContext) -> wgpu::PipelineLayout {
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = std::iter::once(&self.bind_group_layout)
            .chain(self.sets.iter().map(|s| &s.layout))
            .map(Some)
            .collect();
        ctx.device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&self.label),
                bind_group_layouts: &layouts,
                immediate_size: 0,
            })
    }
}

fn checked_module(
    ctx: &GpuContext,
    lib: &mut ShaderLibrary,
    path: &str,
    defs: &[(&str, ShaderDefValue)],
) -> Result<(naga::Module, Vec<Vec<BindingSlot>>, Vec<String>)> {
    let module = lib.module(path, defs)?;
    shader::validate(path, &module, shader::capabilities_for(ctx.features))?;
    let sets = lib.binding_sets(path);
    let max = ctx.limits.max_bind_groups as usize;
    if sets.len() + 1 > max {
        return Err(RenderError::Shader {
            path: path.into(),
            message: format!(
                "needs {} bind groups (its own and the sets {sets:?}); this device has {max}",
                sets.len() + 1
            ),
        });
    }
    let groups = reflect_groups(path, &module, &sets)?;
    let module = if ctx.uniforms_as_storage {
        uniforms_as_storage(module)
    } else {
        module
    };
    Ok((module, groups, sets))
}

/// `module` with every uniform buffer declared as a read-only storage buffer instead
/// ([`GpuContext::uniforms_as_storage`]). WGSL lays out a type the same in both address spaces
/// (the uniform space only adds alignment rules), so the bytes the graph uploads read alike.
/// The reflected slots keep saying `Uniform`: the graph's checks are the same on every adapter.
fn uniforms_as_storage(mut module: naga::Module) -> naga::Module {
    for (_, var) in module.global_variables.iter_mut() {
        if var.space == naga::AddressSpace::Uniform {
            var.space = naga::AddressSpace::Storage {
                access: naga::StorageAccess::LOAD,
            };
        }
    }
    module
}

fn shader_module(ctx: &GpuContext, path: &str, module: naga::Module) -> wgpu::ShaderModule {
    ctx.device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(path),
            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module)),
        })
}

/// # Safety
/// As [`ComputePipeline::new_unchecked`].
unsafe fn unchecked_shader_module(
    ctx: &GpuContext,
    path: &str,
    module: naga::Module,
) -> wgpu::ShaderModule {
    let desc = wgpu::ShaderModuleDescriptor {
        label: Some(path),
        source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module)),
    };
    // SAFETY: the caller vouches for the shader (see `ComputePipeline::new_unchecked`).
    unsafe {
        ctx.device
            .create_shader_module_trusted(desc, wgpu::ShaderRuntimeChecks::unchecked())
    }
}

pub struct ComputePipeline {
    pub info: PipelineInfo,
    pub pipeline: wgpu::ComputePipeline,
    pub workgroup_size: [u32; 3],
}

impl ComputePipeline {
    /// Builds `entry` of the entry shader `path` (relative to `shaders/`).
    pub fn new(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        path: &str,
        entry: &str,
        defs: &[(&str, ShaderDefValue)],
    ) -> Result<Self> {
        Self::build(ctx, lib, path, entry, defs, false)
    }

    /// [`ComputePipeline::new`] without wgpu's runtime checks (clamping of every array and
    /// buffer index, a counter in every loop, guards on integer division) and without zeroing
    /// workgroup memory at the start of each workgroup. For hot kernels that can show why they
    /// need none of it.
    ///
    /// # Safety
    /// For every input the kernel may be given: every index it computes is in range of the
    /// array or bound buffer it indexes, every loop terminates, no integer division or
    /// remainder has a zero divisor, and no workgroup memory is read before it is written.
    pub unsafe fn new_unchecked(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        path: &str,
        entry: &str,
        defs: &[(&str, ShaderDefValue)],
    ) -> Result<Self> {
        Self::build(ctx, lib, path, entry, defs, true)
    }

    fn build(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        path: &str,
        entry: &str,
        defs: &[(&str, ShaderDefValue)],
        unchecked: bool,
    ) -> Result<Self> {
        let (module, groups, sets) = checked_module(ctx, lib, path, defs)?;
        let workgroup_size = module
            .entry_points
            .iter()
            .find(|e| e.name == entry && e.stage == naga::ShaderStage::Compute)
            .map(|e| e.workgroup_size)
            .ok_or_else(|| RenderError::Shader {
                path: path.into(),
                message: format!("no compute entry point `{entry}`"),
            })?;
        let label = format!("{path}:{entry}");
        let info = PipelineInfo::new(ctx, &label, groups, sets, wgpu::ShaderStages::COMPUTE);
        let layout = info.pipeline_layout(ctx);
        let sm = if unchecked {
            // SAFETY: only reached through `new_unchecked`, whose caller vouches for the shader.
            unsafe { unchecked_shader_module(ctx, path, module) }
        } else {
            shader_module(ctx, path, module)
        };
        let pipeline = ctx
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                module: &sm,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    zero_initialize_workgroup_memory: !unchecked,
                    ..Default::default()
                },
                cache: None,
            });
        Ok(Self {
            info,
            pipeline,
            workgroup_size,
        })
    }

    /// Workgroups needed to cover `threads` invocations.
    pub fn groups_for(&self, threads: [u32; 3]) -> [u32; 3] {
        std::array::from_fn(|i| threads[i].div_ceil(self.workgroup_size[i].max(1)))
    }
}

/// Fixed-function state of a raster pipeline; the shader file gives the rest.
#[derive(Clone, Debug)]
pub struct RasterDesc<'a> {
    pub vertex_entry: &'a str,
    pub fragment_entry: Option<&'a str>,
    pub color_formats: &'a [wgpu::TextureFormat],
    pub depth: Option<(wgpu::TextureFormat, wgpu::CompareFunction)>,
    pub cull_mode: Option<wgpu::Face>,
}

pub struct RasterPipeline {
    pub info: PipelineInfo,
    pub pipeline: wgpu::RenderPipeline,
}

impl RasterPipeline {
    /// Builds a pipeline that pulls its vertices from storage buffers (no vertex buffers).
    pub fn new(
        ctx: &GpuContext,
        lib: &mut ShaderLibrary,
        path: &str,
        desc: &RasterDesc<'_>,
        defs: &[(&str, ShaderDefValue)],
    ) -> Result<Self> {
        let (module, groups, sets) = checked_module(ctx, lib, path, defs)?;
        let label = format!("{path}:{}", desc.vertex_entry);
        let info = PipelineInfo::new(
            ctx,
            &label,
            groups,
            sets,
            wgpu::ShaderStages::VERTEX_FRAGMENT,
        );
        let layout = info.pipeline_layout(ctx);
        let sm = shader_module(ctx, path, module);
        let targets: Vec<Option<wgpu::ColorTargetState>> = desc
            .color_formats
            .iter()
            .map(|f| {
                Some(wgpu::ColorTargetState {
                    format: *f,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .collect();
        let pipeline = ctx
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &sm,
                    entry_point: Some(desc.vertex_entry),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: desc.cull_mode,
                    ..Default::default()
                },
                depth_stencil: desc.depth.map(|(format, compare)| wgpu::DepthStencilState {
                    format,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: desc.fragment_entry.map(|fe| wgpu::FragmentState {
                    module: &sm,
                    entry_point: Some(fe),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            });
        Ok(Self { info, pipeline })
    }
}
