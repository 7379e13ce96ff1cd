//! Built-in scenes, generated in code.

use glam::{Mat4, Quat, Vec3};

use crate::{shapes, Camera, Instance, Material, Scene, Sun};

/// Names of the built-in scenes, for the CLI.
pub const NAMES: &[&str] = &["boxes"];

pub fn by_name(name: &str) -> Option<Scene> {
    match name {
        "boxes" => Some(boxes()),
        _ => None,
    }
}

/// A few boxes on a plane under the sun: the engine skeleton's first lit scene.
pub fn boxes() -> Scene {
    let materials = vec![
        Material::diffuse("ground", Vec3::new(0.30, 0.28, 0.25)),
        Material::diffuse("red", Vec3::new(0.60, 0.08, 0.06)),
        Material::diffuse("green", Vec3::new(0.10, 0.45, 0.12)),
        Material::diffuse("white", Vec3::new(0.80, 0.80, 0.78)),
        Material::diffuse("gold leaves", Vec3::new(0.75, 0.55, 0.08)),
    ];
    let meshes = vec![shapes::plane(40.0), shapes::cube()];
    let mut instances = vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }];
    let boxes = [
        (Vec3::new(-3.0, 1.0, 0.0), Vec3::new(2.0, 2.0, 2.0), 20.0f32, 1),
        (Vec3::new(1.5, 0.75, -1.5), Vec3::new(1.5, 1.5, 1.5), -35.0, 2),
        (Vec3::new(2.5, 2.0, 2.5), Vec3::new(1.0, 4.0, 1.0), 10.0, 3),
        (Vec3::new(-0.5, 0.4, 3.0), Vec3::new(0.8, 0.8, 0.8), 45.0, 4),
    ];
    for (pos, size, yaw, material) in boxes {
        instances.push(Instance {
            mesh: 1,
            material,
            transform: Mat4::from_scale_rotation_translation(size, Quat::from_rotation_y(yaw.to_radians()), pos),
        });
    }
    Scene {
        meshes,
        materials,
        instances,
        cameras: vec![
            Camera {
                name: "main".into(),
                position: Vec3::new(7.0, 5.0, 11.0),
                target: Vec3::new(0.0, 1.0, 0.0),
                vfov_deg: 45.0,
                near: 0.1,
            },
            Camera {
                name: "top".into(),
                position: Vec3::new(0.5, 18.0, 0.6),
                target: Vec3::ZERO,
                vfov_deg: 50.0,
                near: 0.1,
            },
        ],
        sun: Some(Sun {
            direction: Vec3::new(-0.45, 0.75, 0.35).normalize(),
            illuminance_lux: 100_000.0,
            color: Vec3::ONE,
        }),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_builtin_scene_validates() {
        for name in super::NAMES {
            super::by_name(name).unwrap().validate().unwrap();
        }
    }
}
