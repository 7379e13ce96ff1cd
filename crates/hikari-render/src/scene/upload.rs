//! The scene as the compute rasteriser and the G-buffer resolve read it.
//!
//! One buffer per stream, shared by every instance of a mesh: positions (what the rasteriser
//! reads, 16 bytes a vertex), the other vertex attributes (what the resolve reads), indices with
//! each mesh's base vertex already added, instances, materials, and the chunk table. A chunk is
//! up to [`CHUNK_TRIANGLES`] consecutive triangles of one instance: the rasteriser runs one
//! workgroup per chunk, and a pixel's visibility id is `chunk * CHUNK_TRIANGLES + lane`. The
//! chunks of alpha-tested instances (cut-outs) come after all the others
//! ([`SceneGpu::first_alpha_chunk`]), so that the rasteriser draws the opaque ones without
//! looking at alpha and the cut-outs in passes of their own.
//! Textures go into two 2D arrays, one sRGB (base colour, emissive) and one linear (the rest).

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Vec3, Vec4};

use hikari_scene::{Scene, Wrap};

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, Tex};
use crate::scene::textures::{self, TextureArrays};

/// Triangles per chunk; the rasteriser's workgroup size.
pub const CHUNK_TRIANGLES: u32 = 64;
/// Material texture slot with no texture.
pub const NO_TEXTURE: u32 = u32::MAX;

/// Per-vertex attributes other than the position.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VertexAttr {
    pub uv: [f32; 2],
    /// Octahedral normal, snorm16x2.
    pub normal: u32,
    /// Octahedral tangent, snorm16x2.
    pub tangent: u32,
    /// Linear RGBA vertex colour in [0, 1], unorm16x4.
    pub color: [u32; 2],
    /// Interior mask as unorm16 in the low bits; bit 16: bitangent = -cross(n, t); bit 17: the
    /// mesh has tangents; bit 18: the mesh has its own interior mask, which wins over the
    /// material's (`Mesh::interior_at`: vertex, then material, then the default).
    pub extra: u32,
    pub pad: u32,
}

pub const EXTRA_BITANGENT_NEGATIVE: u32 = 1 << 16;
pub const EXTRA_HAS_TANGENT: u32 = 1 << 17;
pub const EXTRA_HAS_INTERIOR: u32 = 1 << 18;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct InstanceGpu {
    pub model: [[f32; 4]; 4],
    /// Inverse transpose of the model matrix's upper 3x3, in a mat4 for alignment.
    pub normal_model: [[f32; 4]; 4],
    /// Last frame's model matrix, for motion vectors.
    pub prev_model: [[f32; 4]; 4],
    pub material: u32,
    /// `INSTANCE_*` bits.
    pub flags: u32,
    pub pad: [u32; 2],
}

pub const INSTANCE_DOUBLE_SIDED: u32 = 1;
/// The model matrix is not a rotation with uniform scale, so normals need `normal_model` (for
/// the others the model's 3x3 gives the same directions once normalised, and the resolve skips
/// loading a matrix).
pub const INSTANCE_OWN_NORMAL_MATRIX: u32 = 2;
/// `prev_model` differs from `model` (otherwise the resolve does not load it).
pub const INSTANCE_MOVED: u32 = 4;
/// The material is a cut-out (a positive `MaterialGpu::extra` z, its alpha cut-off): its chunks
/// are drawn by the rasteriser's alpha-tested passes.
pub const INSTANCE_ALPHA_TESTED: u32 = 8;

/// Flags of an instance with this model and last frame's model.
pub fn instance_flags(model: Mat4, prev_model: Mat4, double_sided: bool) -> u32 {
    let mut flags = 0;
    if double_sided {
        flags |= INSTANCE_DOUBLE_SIDED;
    }
    if !is_rotation_with_uniform_scale(Mat3::from_mat4(model)) {
        flags |= INSTANCE_OWN_NORMAL_MATRIX;
    }
    if model != prev_model {
        flags |= INSTANCE_MOVED;
    }
    flags
}

/// Whether m = s R for a scale s and an orthogonal R (mirrors included): then its inverse
/// transpose is m / s^2.
fn is_rotation_with_uniform_scale(m: Mat3) -> bool {
    let g = m.transpose() * m;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let tolerance = 1e-5 * s2;
    s2 > 0.0
        && s2.is_finite()
        && (g - Mat3::from_diagonal(Vec3::splat(s2)))
            .to_cols_array()
            .iter()
            .all(|d| d.abs() <= tolerance)
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialGpu {
    /// rgb: linear base colour; a: alpha, coverage as `extra` z says.
    pub base_color: [f32; 4],
    /// rgb: emitted luminance in nits; a: normal map scale.
    pub emissive: [f32; 4],
    /// Perceptual roughness, metalness, anisotropy strength, anisotropy rotation (radians).
    pub params: [f32; 4],
    /// Occlusion strength, interior mask (negative: none; a mesh's own mask wins over it),
    /// alpha cut-off (0: opaque; else a fragment is drawn where base colour alpha, factor times
    /// texture A times vertex colour A, is at least it), dielectric specular weight
    /// (KHR_materials_specular; 1 is the usual interface, 0 matte).
    pub extra: [f32; 4],
    /// Texture layers: base colour and emissive in the sRGB array, metallic-roughness and
    /// normal in the linear array; [`NO_TEXTURE`] where absent.
    pub textures: [u32; 4],
    /// Occlusion layer (linear array), wrap modes (4 bits a slot: s in bits 0-1, t in 2-3, slots
    /// in the order base colour, metallic-roughness, normal, emissive, occlusion), 0, 0.
    pub more_textures: [u32; 4],
}

/// `instance`, first triangle (global, into the index buffer / 3), triangle count, and the
/// object-space bounds of its triangles, so the rasteriser can skip a chunk outside a view.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Chunk {
    pub instance: u32,
    pub first_triangle: u32,
    pub count: u32,
    pub pad: u32,
    pub bounds_lo: [f32; 4],
    pub bounds_hi: [f32; 4],
}

pub struct SceneGpu {
    pub positions: wgpu::Buffer,
    /// What `positions` held the frame before: the same but for deforming meshes, whose
    /// last frame's pose gives the G-buffer's motion (`scene::rt::SceneRt::update_raster`).
    pub prev_positions: wgpu::Buffer,
    pub attributes: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub instances: wgpu::Buffer,
    pub materials: wgpu::Buffer,
    pub chunks: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub textures: TextureArrays,
    pub chunk_count: u32,
    /// Chunks from this one on are alpha-tested; `chunk_count` when none is.
    pub first_alpha_chunk: u32,
    pub light_count: u32,
    pub triangles: u64,
    /// World-space bounds of every instance, `None` for an empty scene.
    pub bounds: Option<(Vec3, Vec3)>,
    /// The CPU copies the twins and tests read.
    pub cpu: SceneCpu,
}

/// What was uploaded, kept on the CPU for the CPU twins.
#[derive(Clone, Debug, Default)]
pub struct SceneCpu {
    pub positions: Vec<[f32; 4]>,
    pub attributes: Vec<VertexAttr>,
    pub indices: Vec<u32>,
    pub instances: Vec<InstanceGpu>,
    pub materials: Vec<MaterialGpu>,
    pub chunks: Vec<Chunk>,
    /// Chunks from this one on are alpha-tested (see the module doc).
    pub first_alpha_chunk: u32,
    pub lights: Vec<LightGpu>,
    /// The scene's particle emitters, whose sprites the frame generates on the CPU.
    pub particles: Vec<hikari_scene::ParticleEmitter>,
}

/// The alpha cut-off a material is drawn with: 0 (every fragment kept, as glTF's OPAQUE) or
/// the cut-off in (0, 1]. A MASK at 0 keeps every fragment too, so it is drawn as opaque.
pub fn alpha_cutoff(m: &hikari_scene::Material) -> f32 {
    m.alpha_cutoff().filter(|c| *c > 0.0).unwrap_or(0.0)
}

/// A point or spot light.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightGpu {
    /// xyz: world position; w: the scene's range in metres (`f32::MAX` when it gives none);
    /// the lighting pass shortens it to where the light falls below the frame's cut-off.
    pub position_range: [f32; 4],
    /// xyz: unit direction the spot points along; w: 0 point, 1 spot.
    pub direction_kind: [f32; 4],
    /// rgb: colour (luminance 1) times intensity in candela; a unused.
    pub intensity: [f32; 4],
    /// xy: spot cone scale and offset such that the angular factor is
    /// `saturate(cos_angle * scale + offset)^2`; z: the light's radius in metres for its
    /// shadow rays ([`LIGHT_RADIUS_FROM_SETTING`] where the scene gives none); w unused.
    pub spot: [f32; 4],
}

pub const LIGHT_POINT: f32 = 0.0;
/// [`LightGpu::spot`]`[2]` of a light without its own radius: the shadow rays take
/// `area_lights.punctual_radius_m` (any negative value means the same).
pub const LIGHT_RADIUS_FROM_SETTING: f32 = -1.0;
pub const LIGHT_SPOT: f32 = 1.0;

pub fn snorm16x2(v: glam::Vec2) -> u32 {
    let q = |x: f32| ((x.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    q(v.x) | (q(v.y) << 16)
}

pub fn unpack_snorm16x2(p: u32) -> glam::Vec2 {
    let f = |b: u32| ((b as u16 as i16) as f32 / 32767.0).max(-1.0);
    glam::Vec2::new(f(p & 0xffff), f(p >> 16))
}

pub fn unorm16x2(a: f32, b: f32) -> u32 {
    let q = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
    q(a) | (q(b) << 16)
}

fn wrap_bits(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
}

/// Any unit vector perpendicular to `n` (Duff et al. 2017), for meshes without tangents; the
/// WGSL twin is `orthonormal_tangent` in `gbuffer/resolve.wgsl`.
pub fn orthonormal_tangent(n: Vec3) -> Vec3 {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x)
}

impl SceneCpu {
    pub fn build(scene: &Scene, layers: &textures::LayerMap) -> Self {
        let mut cpu = SceneCpu {
            particles: scene.particles.clone(),
            ..SceneCpu::default()
        };
        let mut mesh_first_triangle = Vec::new();
        for m in &scene.meshes {
            let base = cpu.positions.len() as u32;
            mesh_first_triangle.push(cpu.indices.len() as u32 / 3);
            cpu.indices.extend(m.indices.iter().map(|i| i + base));
            cpu.positions
                .extend(m.positions.iter().map(|p| p.extend(1.0).to_array()));
            for v in 0..m.positions.len() {
                let n = m.normals[v].normalize_or(Vec3::Y);
                let (t, negative, has) = match m.tangents.get(v) {
                    Some(t) => (
                        t.truncate().normalize_or(orthonormal_tangent(n)),
                        t.w < 0.0,
                        true,
                    ),
                    None => (orthonormal_tangent(n), false, false),
                };
                let c = m
                    .colors
                    .as_ref()
                    .and_then(|c| c.get(v).copied())
                    .unwrap_or(Vec4::ONE);
                let interior = m.interior.get(v).copied();
                let mut extra = (interior
                    .unwrap_or(hikari_scene::DEFAULT_INTERIOR)
                    .clamp(0.0, 1.0)
                    * 65535.0)
                    .round() as u32;
                if interior.is_some() {
                    extra |= EXTRA_HAS_INTERIOR;
                }
                if negative {
                    extra |= EXTRA_BITANGENT_NEGATIVE;
                }
                if has {
                    extra |= EXTRA_HAS_TANGENT;
                }
                cpu.attributes.push(VertexAttr {
                    uv: m.uvs.get(v).copied().unwrap_or_default().to_array(),
                    normal: snorm16x2(crate::reference::octahedral::encode(n)),
                    tangent: snorm16x2(crate::reference::octahedral::encode(t)),
                    color: [unorm16x2(c.x, c.y), unorm16x2(c.z, c.w)],
                    extra,
                    pad: 0,
                });
            }
        }
        // Opaque instances' chunks first, then the cut-outs' (see the module doc).
        let mut alpha_chunks = Vec::new();
        for (i, inst) in scene.instances.iter().enumerate() {
            let mat = &scene.materials[inst.material];
            let normal = Mat4::from_mat3(Mat3::from_mat4(inst.transform).inverse().transpose());
            let alpha_tested = alpha_cutoff(mat) > 0.0;
            let mut flags = instance_flags(inst.transform, inst.transform, mat.double_sided);
            if alpha_tested {
                flags |= INSTANCE_ALPHA_TESTED;
            }
            cpu.instances.push(InstanceGpu {
                model: inst.transform.to_cols_array_2d(),
                normal_model: normal.to_cols_array_2d(),
                prev_model: inst.transform.to_cols_array_2d(),
                material: inst.material as u32,
                flags,
                pad: [0; 2],
            });
            let chunks = if alpha_tested {
                &mut alpha_chunks
            } else {
                &mut cpu.chunks
            };
            let triangles = scene.meshes[inst.mesh].indices.len() as u32 / 3;
            let first = mesh_first_triangle[inst.mesh];
            let mesh = &scene.meshes[inst.mesh];
            let reach = Vec3::splat(
                mesh.deformation
                    .map_or(0.0, |d| d.max_displacement(mesh))
                    .max(0.0),
            );
            let mut t = 0;
            while t < triangles {
                let count = (triangles - t).min(CHUNK_TRIANGLES);
                let first_index = ((first + t) * 3) as usize;
                let (lo, hi) = cpu.indices[first_index..first_index + count as usize * 3]
                    .iter()
                    .map(|&v| Vec4::from_array(cpu.positions[v as usize]).truncate())
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(p), hi.max(p))
                    });
                // A deforming mesh's vertices leave their rest-pose box by up to its reach
                // (scene_rt draws them moved): the chunk's box covers every pose.
                let (lo, hi) = (lo - reach, hi + reach);
                chunks.push(Chunk {
                    instance: i as u32,
                    first_triangle: first + t,
                    count,
                    pad: 0,
                    bounds_lo: lo.extend(0.0).to_array(),
                    bounds_hi: hi.extend(0.0).to_array(),
                });
                t += count;
            }
        }
        cpu.first_alpha_chunk = cpu.chunks.len() as u32;
        cpu.chunks.append(&mut alpha_chunks);
        for m in &scene.materials {
            let slot = |t: &Option<hikari_scene::TextureRef>, array: &[Option<u32>]| {
                t.map_or((NO_TEXTURE, 0), |r| {
                    let tex = &scene.textures[r.texture];
                    (
                        array[r.texture].unwrap_or(NO_TEXTURE),
                        wrap_bits(tex.wrap_s) | (wrap_bits(tex.wrap_t) << 2),
                    )
                })
            };
            let slots = [
                slot(&m.base_color_texture, &layers.color),
                slot(&m.metallic_roughness_texture, &layers.data),
                slot(&m.normal_texture, &layers.data),
                slot(&m.emissive_texture, &layers.color),
                slot(&m.occlusion_texture, &layers.data),
            ];
            let wraps = slots
                .iter()
                .enumerate()
                .fold(0, |acc, (k, s)| acc | (s.1 << (4 * k)));
            let (aniso, rotation) = m
                .anisotropy
                .map_or((0.0, 0.0), |a| (a.strength, a.rotation));
            cpu.materials.push(MaterialGpu {
                base_color: m.base_color.extend(m.alpha).to_array(),
                emissive: m.emissive_nits.extend(m.normal_scale).to_array(),
                params: [m.roughness, m.metalness, aniso, rotation],
                extra: [
                    m.occlusion_strength,
                    m.interior.unwrap_or(-1.0),
                    alpha_cutoff(m),
                    m.specular,
                ],
                textures: [slots[0].0, slots[1].0, slots[2].0, slots[3].0],
                more_textures: [slots[4].0, wraps, 0, 0],
            });
        }
        for l in &scene.lights {
            let (kind, dir, spot) = match l.kind {
                hikari_scene::LightKind::Point => (LIGHT_POINT, Vec3::NEG_Z, [0.0, 1.0, 0.0, 0.0]),
                hikari_scene::LightKind::Spot {
                    inner_cone,
                    outer_cone,
                } => {
                    // KHR_lights_punctual's smooth cone: linear in cos between the cones.
                    let (ci, co) = (inner_cone.cos(), outer_cone.cos());
                    let scale = 1.0 / (ci - co).max(1e-4);
                    (
                        LIGHT_SPOT,
                        l.direction.normalize(),
                        [scale, -co * scale, 0.0, 0.0],
                    )
                }
            };
            cpu.lights.push(LightGpu {
                position_range: l.position.extend(l.range.unwrap_or(f32::MAX)).to_array(),
                direction_kind: dir.extend(kind).to_array(),
                intensity: (l.color * l.intensity_cd).extend(0.0).to_array(),
                spot: [
                    spot[0],
                    spot[1],
                    l.radius_m.unwrap_or(LIGHT_RADIUS_FROM_SETTING),
                    0.0,
                ],
            });
        }
        cpu
    }
}

/// The scene's buffers and textures imported into one frame's graph, once, for every pass.
#[derive(Clone, Copy, Debug)]
pub struct SceneInFrame {
    pub positions: Buf,
    pub prev_positions: Buf,
    pub attributes: Buf,
    pub indices: Buf,
    pub instances: Buf,
    pub materials: Buf,
    pub chunks: Buf,
    pub lights: Buf,
    pub color_textures: Tex,
    pub data_textures: Tex,
    pub chunk_count: u32,
    /// Chunks from this one on are alpha-tested; `chunk_count` when none is.
    pub first_alpha_chunk: u32,
    pub light_count: u32,
    pub bounds: Option<(Vec3, Vec3)>,
}

impl SceneGpu {
    pub fn import(&self, g: &mut FrameGraph<'_>) -> SceneInFrame {
        SceneInFrame {
            positions: g.import_buffer("scene.positions", &self.positions),
            prev_positions: g.import_buffer("scene.prev_positions", &self.prev_positions),
            attributes: g.import_buffer("scene.attributes", &self.attributes),
            indices: g.import_buffer("scene.indices", &self.indices),
            instances: g.import_buffer("scene.instances", &self.instances),
            materials: g.import_buffer("scene.materials", &self.materials),
            chunks: g.import_buffer("scene.chunks", &self.chunks),
            lights: g.import_buffer("scene.lights", &self.lights),
            color_textures: g.import_texture("scene.color_textures", &self.textures.color),
            data_textures: g.import_texture("scene.data_textures", &self.textures.data),
            chunk_count: self.chunk_count,
            first_alpha_chunk: self.first_alpha_chunk,
            light_count: self.light_count,
            bounds: self.bounds,
        }
    }

    /// Validates and uploads `scene`. Sizes beyond the device limits are an error that says
    /// which buffer and by how much.
    pub fn upload(ctx: &GpuContext, scene: &Scene) -> Result<Self> {
        scene
            .validate()
            .map_err(|e| RenderError::Graph(format!("scene: {e}")))?;
        let (textures, layers) = TextureArrays::upload(ctx, scene)?;
        let cpu = SceneCpu::build(scene, &layers);
        // Empty scenes still bind a buffer (a zeroed row); the error names the scene's buffer.
        let buffer = |name: &str, bytes: &[u8]| ctx.storage_buffer(&format!("scene {name}"), bytes);
        let bounds = scene
            .instances
            .iter()
            .fold(None, |acc: Option<(Vec3, Vec3)>, inst| {
                let Some((lo, hi)) = scene.meshes[inst.mesh].bounds() else {
                    return acc;
                };
                let corners = (0..8).map(|i| {
                    let c = Vec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    );
                    inst.transform.transform_point3(c)
                });
                Some(corners.fold(
                    acc.unwrap_or((Vec3::INFINITY, Vec3::NEG_INFINITY)),
                    |(a, b), c| (a.min(c), b.max(c)),
                ))
            });
        Ok(Self {
            positions: buffer("positions", bytemuck::cast_slice(&cpu.positions))?,
            prev_positions: buffer("previous positions", bytemuck::cast_slice(&cpu.positions))?,
            attributes: buffer("vertex attributes", bytemuck::cast_slice(&cpu.attributes))?,
            indices: buffer("indices", bytemuck::cast_slice(&cpu.indices))?,
            instances: buffer("instances", bytemuck::cast_slice(&cpu.instances))?,
            materials: buffer("materials", bytemuck::cast_slice(&cpu.materials))?,
            chunks: buffer("chunks", bytemuck::cast_slice(&cpu.chunks))?,
            lights: buffer("lights", bytemuck::cast_slice(&cpu.lights))?,
            textures,
            chunk_count: cpu.chunks.len() as u32,
            first_alpha_chunk: cpu.first_alpha_chunk,
            light_count: cpu.lights.len() as u32,
            triangles: scene.triangle_count() as u64,
            bounds,
            cpu,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn only_non_conformal_transforms_need_their_own_normal_matrix() {
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let conformal = [
            Mat4::IDENTITY,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(3.5),
                rotation,
                Vec3::new(100.0, 2.0, -40.0),
            ),
            Mat4::from_scale_rotation_translation(Vec3::new(-0.2, 0.2, 0.2), rotation, Vec3::ZERO),
        ];
        for m in conformal {
            assert_eq!(instance_flags(m, m, false), 0, "{m}");
            // What the resolve relies on: the inverse transpose is the 3x3 up to a scale.
            let n = Mat3::from_mat4(m).inverse().transpose();
            let v = Vec3::new(0.3, -0.8, 0.52).normalize();
            assert!(((n * v).normalize() - (Mat3::from_mat4(m) * v).normalize()).length() < 1e-5);
        }
        let sheared = [
            Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)),
            Mat4::from_scale_rotation_translation(Vec3::new(1.0, 1.0, 1.001), rotation, Vec3::ZERO),
            Mat4::from_cols_array(&[
                1.0, 0.5, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
            ]),
            Mat4::from_scale(Vec3::ZERO),
        ];
        for m in sheared {
            assert_eq!(
                instance_flags(m, m, false),
                INSTANCE_OWN_NORMAL_MATRIX,
                "{m}"
            );
        }
        let moved = Mat4::from_translation(Vec3::X);
        assert_eq!(
            instance_flags(moved, Mat4::IDENTITY, true),
            INSTANCE_MOVED | INSTANCE_DOUBLE_SIDED
        );
    }
}
