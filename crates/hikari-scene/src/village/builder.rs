//! Collects meshes, materials and instances into a [`Scene`], with names, so that the parts
//! of the village can add themselves without juggling indices.

use glam::{Mat4, Quat, Vec3};

use crate::{Instance, Material, Mesh, Scene};

#[derive(Default)]
pub struct Builder {
    pub scene: Scene,
}

impl Builder {
    /// Adds `mesh` named `name`; returns its index.
    pub fn mesh(&mut self, name: &str, mut mesh: Mesh) -> usize {
        mesh.name = name.into();
        self.scene.meshes.push(mesh);
        self.scene.meshes.len() - 1
    }

    pub fn material(&mut self, material: Material) -> usize {
        self.scene.materials.push(material);
        self.scene.materials.len() - 1
    }

    pub fn instance(&mut self, mesh: usize, material: usize, transform: Mat4) {
        self.scene.instances.push(Instance {
            mesh,
            material,
            transform,
        });
    }
}

/// Rotation by `yaw` radians about +Y (counter-clockwise seen from above), then translation.
pub fn placed(position: Vec3, yaw: f32) -> Mat4 {
    Mat4::from_rotation_translation(Quat::from_rotation_y(yaw), position)
}
