//! The scene's polygonal lights on the GPU, built once when it is loaded, and the instances
//! that cast their shadows.

use hikari_scene::Scene;

use super::polygon::PolygonLights;
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{Buf, FrameGraph};

/// What the pass needs of a scene, built once when it is loaded: its area lights. The shadow
/// rays trace the frame's scene BVH (`scene::rt::SceneRt`, its shadow TLAS), from which the
/// instances that are the glowing shell of a point or spot light ([`shadow_casters`]) are left
/// out: they stand for that light's own light passing through them (the village's lanterns).
pub struct AreaLightScene {
    pub lights: PolygonLights,
    light_buffer: wgpu::Buffer,
    triangle_buffer: wgpu::Buffer,
    uv_buffer: wgpu::Buffer,
}

/// The instances of `scene` that cast shadows: all but emissive shells around a point or spot
/// light (an emissive instance whose bounds hold a light's position).
pub fn shadow_casters(scene: &Scene) -> Vec<u32> {
    (0..scene.instances.len() as u32)
        .filter(|&i| {
            let inst = &scene.instances[i as usize];
            if scene.materials[inst.material].emissive_nits.max_element() <= 0.0 {
                return true;
            }
            let Some((lo, hi)) = scene.meshes[inst.mesh].bounds() else {
                return true;
            };
            let m = inst.transform;
            let corners = (0..8).map(|k| {
                m.transform_point3(glam::Vec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                ))
            });
            let (wlo, whi) = corners.fold(
                (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
                |(a, b), p| (a.min(p), b.max(p)),
            );
            !scene
                .lights
                .iter()
                .any(|l| l.position.cmpge(wlo).all() && l.position.cmple(whi).all())
        })
        .collect()
}

impl AreaLightScene {
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<Self> {
        let lights = PolygonLights::for_scene(scene);
        let buffer = |name: &str, bytes: &[u8]| ctx.storage_buffer(name, bytes);
        Ok(Self {
            light_buffer: buffer("area_lights.lights", bytemuck::cast_slice(&lights.lights))?,
            triangle_buffer: buffer(
                "area_lights.triangles",
                bytemuck::cast_slice(&lights.triangles),
            )?,
            uv_buffer: buffer(
                "area_lights.triangle_uvs",
                bytemuck::cast_slice(&lights.uvs),
            )?,
            lights,
        })
    }

    pub fn light_count(&self) -> u32 {
        self.lights.lights.len() as u32
    }

    /// The light and triangle tables in a frame (`area_lights.lights`, `.triangles`), also
    /// read by the lighting of GI hits.
    pub fn import(&self, g: &mut FrameGraph<'_>) -> (Buf, Buf) {
        (
            g.import_buffer("area_lights.lights", &self.light_buffer),
            g.import_buffer("area_lights.triangles", &self.triangle_buffer),
        )
    }

    /// The triangles' UVs in a frame (`area_lights.triangle_uvs`: [`PolygonLights::uvs`]).
    pub fn import_uvs(&self, g: &mut FrameGraph<'_>) -> Buf {
        g.import_buffer("area_lights.triangle_uvs", &self.uv_buffer)
    }
}
