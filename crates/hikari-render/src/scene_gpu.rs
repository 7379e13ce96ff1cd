//! The scene uploaded for rasterisation: one vertex buffer, one index buffer, one instance
//! buffer, and a draw per instance.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use wgpu::util::DeviceExt;

use hikari_scene::Scene;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 4],
    pub normal: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Instance {
    pub model: [[f32; 4]; 4],
    pub normal_model: [[f32; 4]; 4],
    pub base_color_roughness: [f32; 4],
    pub metal_emissive: [f32; 4],
}

#[derive(Clone, Copy, Debug)]
pub struct Draw {
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    pub instance: u32,
}

pub struct SceneGpu {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub instances: wgpu::Buffer,
    pub draws: Vec<Draw>,
    pub triangles: u64,
}

impl SceneGpu {
    /// Validates and uploads `scene`. Sizes beyond the device limits are an error that says
    /// which buffer and by how much.
    pub fn upload(ctx: &GpuContext, scene: &Scene) -> Result<Self> {
        scene
            .validate()
            .map_err(|e| RenderError::Graph(format!("scene: {e}")))?;
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        let mut ranges = Vec::new();
        for m in &scene.meshes {
            let (first_index, base_vertex) = (indices.len() as u32, vertices.len() as i32);
            vertices.extend(m.positions.iter().zip(&m.normals).map(|(p, n)| Vertex {
                position: p.extend(1.0).to_array(),
                normal: n.extend(0.0).to_array(),
            }));
            indices.extend_from_slice(&m.indices);
            ranges.push((first_index, m.indices.len() as u32, base_vertex));
        }
        let instances: Vec<Instance> = scene
            .instances
            .iter()
            .map(|inst| {
                let mat = &scene.materials[inst.material];
                let normal =
                    Mat4::from_mat3(glam::Mat3::from_mat4(inst.transform).inverse().transpose());
                Instance {
                    model: inst.transform.to_cols_array_2d(),
                    normal_model: normal.to_cols_array_2d(),
                    base_color_roughness: mat.base_color.extend(mat.roughness).to_array(),
                    metal_emissive: [
                        mat.metalness,
                        mat.emissive_nits.x,
                        mat.emissive_nits.y,
                        mat.emissive_nits.z,
                    ],
                }
            })
            .collect();
        let draws: Vec<Draw> = scene
            .instances
            .iter()
            .enumerate()
            .filter(|(_, inst)| ranges[inst.mesh].1 > 0)
            .map(|(i, inst)| {
                let (first_index, index_count, base_vertex) = ranges[inst.mesh];
                Draw {
                    first_index,
                    index_count,
                    base_vertex,
                    instance: i as u32,
                }
            })
            .collect();
        let limit = ctx.limits.max_storage_buffer_binding_size;
        let buffer =
            |name: &str, bytes: &[u8], usage: wgpu::BufferUsages| -> Result<wgpu::Buffer> {
                // Empty scenes still bind a buffer: wgpu refuses zero-sized bindings.
                let padded;
                let bytes = if bytes.is_empty() {
                    padded = [0u8; 64];
                    &padded[..]
                } else {
                    bytes
                };
                if bytes.len() as u64 > limit {
                    return Err(RenderError::Limit {
                        what: format!("scene {name} buffer size in bytes"),
                        requested: bytes.len() as u64,
                        limit,
                    });
                }
                Ok(ctx
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(name),
                        contents: bytes,
                        usage,
                    }))
            };
        Ok(Self {
            vertices: buffer(
                "vertices",
                bytemuck::cast_slice(&vertices),
                wgpu::BufferUsages::STORAGE,
            )?,
            indices: buffer(
                "indices",
                bytemuck::cast_slice(&indices),
                wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
            )?,
            instances: buffer(
                "instances",
                bytemuck::cast_slice(&instances),
                wgpu::BufferUsages::STORAGE,
            )?,
            triangles: scene.triangle_count() as u64,
            draws,
        })
    }
}
