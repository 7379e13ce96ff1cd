//! The scene as the ray tracer's input: one `hikari_bvh::Mesh` per scene mesh, one
//! `hikari_bvh::Instance` per scene instance (its BLAS index is the mesh index, and hits report
//! the scene instance's index), and what the traversal needs for alpha cut-outs.
//!
//! Cut-outs (glTF `alphaMode` MASK, and BLEND drawn as a mask): [`blases`] marks every triangle
//! of a mesh that some instance draws with a cut-out material as non-opaque
//! (`hikari_bvh::TRIANGLE_NON_OPAQUE`), so the traversal asks a filter about hits on them.
//! [`BvhAlpha`] is the GPU filter's data (uploaded with `BvhTrace::upload_alpha`), and
//! [`SceneAlphaFilter`] its CPU twin, for the `*_filtered` traversals of hikari-bvh. Both
//! evaluate what the rasteriser's alpha test does (`raster/setup.wgsl`, `alpha_covers`): base
//! colour alpha, material factor times interpolated vertex colour A times the base colour
//! texture's A (bilinear, mip 0), against the material's cut-off.

use bytemuck::{Pod, Zeroable};
use glam::{Affine3A, Vec2};
use hikari_bvh::{Blas, BuildOptions, BvhError, Instance, Mesh};
use hikari_scene::Scene;

use crate::reference::textures::TwinTextures;
use crate::scene::textures::LayerMap;
use crate::scene::upload::{NO_TEXTURE, alpha_cutoff, unorm16x2};

pub fn meshes(scene: &Scene) -> Vec<Mesh> {
    scene
        .meshes
        .iter()
        .map(|m| {
            Mesh::new(
                m.positions.clone(),
                m.indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect(),
            )
        })
        .collect()
}

pub fn instances(scene: &Scene) -> Vec<Instance> {
    scene
        .instances
        .iter()
        .map(|i| Instance::new(Affine3A::from_mat4(i.transform), i.mesh as u32))
        .collect()
}

/// Per scene mesh: whether some instance draws it with a cut-out material (a positive
/// [`alpha_cutoff`]). An instance of such a mesh with an opaque material has a cut-off of 0 in
/// [`BvhAlpha`], and the filter accepts its hits at once.
pub fn cutout_meshes(scene: &Scene) -> Vec<bool> {
    let mut cut = vec![false; scene.meshes.len()];
    for inst in &scene.instances {
        if alpha_cutoff(&scene.materials[inst.material]) > 0.0 {
            cut[inst.mesh] = true;
        }
    }
    cut
}

/// One BLAS per scene mesh (named after it), the triangles of [`cutout_meshes`] marked
/// non-opaque.
pub fn blases(scene: &Scene, options: &BuildOptions) -> Result<Vec<Blas>, BvhError> {
    let cut = cutout_meshes(scene);
    meshes(scene)
        .iter()
        .zip(&scene.meshes)
        .zip(cut)
        .map(|((m, sm), cut)| {
            if cut {
                let marks = vec![true; m.indices.len()];
                Blas::build_with_opacity(&sm.name, &m.positions, &m.indices, &marks, options)
            } else {
                Blas::from_mesh(&sm.name, m, options)
            }
        })
        .collect()
}

/// [`AlphaInstance::texture`] bits 0..24 when the material has no base colour texture.
pub const ALPHA_NO_TEXTURE: u32 = 0x00ff_ffff;

/// The cut-out of one scene instance, indexed by the instance index hits report (16 bytes, one
/// vec4; `bvh_alpha_instances` of `hikari::bvh`, binding 4 of the set `bvh`).
///
/// | bytes | field | WGSL (`array<vec4<u32>>`, record `i` at `i`) |
/// |---|---|---|
/// | 0-3 | `cutoff: f32` | `bitcast<f32>(.x)`; 0: opaque material, every hit stands |
/// | 4-7 | `alpha: f32` | `bitcast<f32>(.y)`: the material's base colour alpha factor |
/// | 8-11 | `texture: u32` | `.z`: base colour layer in the sRGB texture array (bits 0..24, [`ALPHA_NO_TEXTURE`]: none) and its wrap bits (24..28, as `MaterialGpu::more_textures`) |
/// | 12-15 | `first_triangle: u32` | `.w`: the mesh's first [`AlphaTriangle`]; triangle `p` of the mesh is record `first_triangle + p` |
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct AlphaInstance {
    pub cutoff: f32,
    pub alpha: f32,
    pub texture: u32,
    pub first_triangle: u32,
}

/// What the alpha test needs of one triangle of a cut-out mesh (32 bytes, two vec4s;
/// `bvh_alpha_triangles`, binding 5, record `i` at `2 i`): the texture coordinates of its three
/// vertices (`[2i].xy`, `[2i].zw`, `[2i+1].xy`) and their vertex colour alphas as unorm16, as
/// the rasteriser reads them (`[2i+1].z` = a0 | a1 << 16, `[2i+1].w` = a2).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct AlphaTriangle {
    pub uv: [[f32; 2]; 3],
    pub alpha: [u32; 2],
}

/// The GPU filter's data: one [`AlphaInstance`] per scene instance and one [`AlphaTriangle`]
/// per triangle of each of the [`cutout_meshes`] (each mesh once, however many instances draw
/// it). With the scene's sRGB texture array (`SceneGpu::textures.color`, whose alpha is linear)
/// it is all the GPU's `bvh_accept_candidate` reads: 32 bytes per cut-out triangle, 16 per
/// instance, against 48 for the triangle's BVH record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BvhAlpha {
    pub instances: Vec<AlphaInstance>,
    pub triangles: Vec<AlphaTriangle>,
}

impl BvhAlpha {
    pub fn for_scene(scene: &Scene) -> Self {
        let layers = LayerMap::for_scene(scene);
        let cut = cutout_meshes(scene);
        let mut out = BvhAlpha::default();
        let mut first = vec![0u32; scene.meshes.len()];
        for (m, mesh) in scene.meshes.iter().enumerate() {
            if !cut[m] {
                continue;
            }
            first[m] = out.triangles.len() as u32;
            let color_alpha = |v: u32| {
                mesh.colors
                    .as_ref()
                    .and_then(|c| c.get(v as usize))
                    .map_or(1.0, |c| c.w)
            };
            let uv = |v: u32| mesh.uvs.get(v as usize).copied().unwrap_or_default();
            for t in mesh.indices.chunks_exact(3) {
                out.triangles.push(AlphaTriangle {
                    uv: [uv(t[0]).into(), uv(t[1]).into(), uv(t[2]).into()],
                    alpha: [
                        unorm16x2(color_alpha(t[0]), color_alpha(t[1])),
                        unorm16x2(color_alpha(t[2]), 0.0),
                    ],
                });
            }
        }
        for inst in &scene.instances {
            let mat = &scene.materials[inst.material];
            let texture = mat.base_color_texture.map_or(ALPHA_NO_TEXTURE, |r| {
                let layer = layers.color[r.texture].unwrap_or(NO_TEXTURE);
                let tex = &scene.textures[r.texture];
                let wrap = wrap_bits(tex.wrap_s) | (wrap_bits(tex.wrap_t) << 2);
                if layer >= ALPHA_NO_TEXTURE {
                    ALPHA_NO_TEXTURE
                } else {
                    layer | (wrap << 24)
                }
            });
            out.instances.push(AlphaInstance {
                cutoff: alpha_cutoff(mat),
                alpha: mat.alpha,
                texture,
                first_triangle: first[inst.mesh],
            });
        }
        out
    }

    /// Every one of `instances` opaque: every hit on a non-opaque triangle stands (what the
    /// traversal did before cut-outs, and a control for the tests).
    pub fn opaque(instances: usize) -> Self {
        Self {
            instances: vec![AlphaInstance::default(); instances],
            triangles: Vec::new(),
        }
    }
}

fn wrap_bits(w: hikari_scene::Wrap) -> u32 {
    match w {
        hikari_scene::Wrap::Repeat => 0,
        hikari_scene::Wrap::MirroredRepeat => 1,
        hikari_scene::Wrap::ClampToEdge => 2,
    }
}

/// The CPU twin of the GPU's `bvh_accept_candidate` for a scene: pass
/// `|i, p, u, v| filter.accept(i, p, u, v)` to hikari-bvh's `*_filtered` traversals over
/// [`blases`] and [`instances`] of the same scene.
///
/// It samples each texture from the scene's own image (bilinear, mip 0, the sampler's wrap
/// modes), which is what the GPU reads when every base colour texture already has the size of
/// the texture array's layers (a power of two up to `MAX_LAYER_SIZE`, the same for all; the
/// array resamples the others). Vertex colour alpha is quantised to 16 bits as uploaded.
pub struct SceneAlphaFilter<'a> {
    scene: &'a Scene,
}

impl<'a> SceneAlphaFilter<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        Self { scene }
    }

    /// The alpha at the point with weights `u` (of the triangle's second vertex) and `v` (of
    /// its third) on triangle `primitive` of instance `instance`, and the cut-off it is held
    /// to; `None` when the instance's material is opaque or the indices name nothing.
    pub fn alpha(&self, instance: u32, primitive: u32, u: f32, v: f32) -> Option<(f32, f32)> {
        let inst = self.scene.instances.get(instance as usize)?;
        let mat = &self.scene.materials[inst.material];
        let cutoff = alpha_cutoff(mat);
        if cutoff <= 0.0 {
            return None;
        }
        let mesh = &self.scene.meshes[inst.mesh];
        let first = primitive as usize * 3;
        let tri = mesh.indices.get(first..first + 3)?;
        let w = [1.0 - u - v, u, v];
        let unorm16 = |a: f32| (a.clamp(0.0, 1.0) * 65535.0).round() / 65535.0;
        let mut alpha = 0.0;
        let mut uv = Vec2::ZERO;
        for (k, &i) in tri.iter().enumerate() {
            let c = mesh
                .colors
                .as_ref()
                .and_then(|c| c.get(i as usize))
                .map_or(1.0, |c| c.w);
            alpha += unorm16(c) * mat.alpha * w[k];
            uv += mesh.uvs.get(i as usize).copied().unwrap_or_default() * w[k];
        }
        if let Some(r) = mat.base_color_texture {
            let texel = TwinTextures { scene: self.scene }.sample(r.texture, uv.as_dvec2(), false);
            alpha *= texel.w as f32;
        }
        Some((alpha, cutoff))
    }

    /// Whether a candidate hit counts (NaN alpha does not, as on the GPU).
    pub fn accept(&self, instance: u32, primitive: u32, u: f32, v: f32) -> bool {
        self.alpha(instance, primitive, u, v)
            .is_none_or(|(alpha, cutoff)| alpha >= cutoff)
    }
}
