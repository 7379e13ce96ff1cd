//! The scene as the ray tracer's input: one `hikari_bvh::Mesh` per scene mesh, one
//! `hikari_bvh::Instance` per scene instance (its BLAS index is the mesh index).

use glam::Affine3A;
use hikari_bvh::{Instance, Mesh};
use hikari_scene::Scene;

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
