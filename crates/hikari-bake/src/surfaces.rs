//! What a bounce ray sees where it lands: the surface's diffuse albedo and which of its sides
//! reflects.
//!
//! Diffuse albedo = material base colour factor x the **average** of its base-colour texture
//! (decoded from sRGB to linear, over all texels; the bake does not interpolate texture
//! coordinates, so a texture's detail is averaged away, its overall tint kept) x the vertex
//! colour interpolated at the hit (the village's terrain paints grass, earth and gravel this
//! way) x (1 - metalness) (metals reflect no diffuse light). Clamped to [0, 1].

use glam::Vec3;
use hikari_math::color::transfer::srgb_decode_f32;
use hikari_scene::Scene;

use crate::scene_rays::SurfaceHit;

/// Per scene instance: the constant part of its albedo, its mesh and whether both sides
/// reflect.
pub struct SurfaceAlbedo {
    /// Per scene material: base colour x texture average x (1 - metalness).
    pub(crate) material_albedo: Vec<Vec3>,
    pub(crate) material_double_sided: Vec<bool>,
    /// Per scene instance: (mesh, material).
    pub(crate) instance_parts: Vec<(usize, usize)>,
    /// Per scene mesh: triangle vertex indices and vertex colours (RGB), when it has colours.
    pub(crate) mesh_colors: Vec<Option<(Vec<u32>, Vec<Vec3>)>>,
}

/// Mean linear RGB of an sRGB-encoded RGBA8 texture; white for an empty or short one.
pub fn texture_average(data: &[u8], texels: usize) -> Vec3 {
    if texels == 0 || data.len() < texels * 4 {
        return Vec3::ONE;
    }
    // One decode table instead of a pow per channel and texel.
    let table: Vec<f64> = (0..256)
        .map(|e| f64::from(srgb_decode_f32(e as f32 / 255.0)))
        .collect();
    let mut sum = [0.0f64; 3];
    for px in data[..texels * 4].chunks_exact(4) {
        for c in 0..3 {
            sum[c] += table[px[c] as usize];
        }
    }
    let n = texels as f64;
    Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

impl SurfaceAlbedo {
    pub fn new(scene: &Scene) -> Self {
        let material_albedo = scene
            .materials
            .iter()
            .map(|m| {
                let tex = m
                    .base_color_texture
                    .and_then(|t| scene.textures.get(t.texture))
                    .map(|t| texture_average(&t.data, (t.width * t.height) as usize))
                    .unwrap_or(Vec3::ONE);
                let a = m.base_color * tex * (1.0 - m.metalness.clamp(0.0, 1.0));
                sanitize(a)
            })
            .collect();
        let mesh_colors = scene
            .meshes
            .iter()
            .map(|m| {
                m.colors
                    .as_ref()
                    .filter(|c| c.len() == m.positions.len())
                    .map(|c| (m.indices.clone(), c.iter().map(|v| v.truncate()).collect()))
            })
            .collect();
        Self {
            material_albedo,
            material_double_sided: scene.materials.iter().map(|m| m.double_sided).collect(),
            instance_parts: scene
                .instances
                .iter()
                .map(|i| (i.mesh, i.material))
                .collect(),
            mesh_colors,
        }
    }

    /// Diffuse albedo (linear RGB in [0, 1]) at `hit`.
    pub fn albedo(&self, hit: &SurfaceHit) -> Vec3 {
        let Some(&(mesh, material)) = self.instance_parts.get(hit.instance) else {
            return Vec3::ZERO;
        };
        let base = self
            .material_albedo
            .get(material)
            .copied()
            .unwrap_or(Vec3::ZERO);
        let vertex = self
            .mesh_colors
            .get(mesh)
            .and_then(|c| c.as_ref())
            .and_then(|(indices, colors)| {
                let t = indices.get(hit.primitive * 3..hit.primitive * 3 + 3)?;
                let [u, v] = hit.uv;
                let c = |k: usize| colors.get(t[k] as usize).copied();
                Some(c(0)? * (1.0 - u - v) + c(1)? * u + c(2)? * v)
            })
            .unwrap_or(Vec3::ONE);
        sanitize(base * vertex)
    }

    /// Whether the back of the surface hit reflects too (glTF `doubleSided`); a single-sided
    /// surface seen from behind is the inside of a solid and reflects nothing towards the probe.
    pub fn double_sided(&self, hit: &SurfaceHit) -> bool {
        self.instance_parts
            .get(hit.instance)
            .and_then(|&(_, m)| self.material_double_sided.get(m))
            .copied()
            .unwrap_or(false)
    }
}

fn sanitize(a: Vec3) -> Vec3 {
    if a.is_finite() {
        a.clamp(Vec3::ZERO, Vec3::ONE)
    } else {
        Vec3::ZERO
    }
}
